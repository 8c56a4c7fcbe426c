"""Shared fixtures: composed configs, the real-mesh data root, an isolated convex-decomposition cache."""

import os
from pathlib import Path

import pytest
from omegaconf import DictConfig

from graspexp.cli import compose_config

REPO = Path(__file__).resolve().parent.parent


def shared_data_root() -> Path:
    """``GRASPEXP_DATA`` if set, else ``../shared/datasets`` beside the checkout."""
    return Path(os.environ.get("GRASPEXP_DATA", REPO.parent / "shared" / "datasets"))


def compose_cfg(*overrides: str) -> DictConfig:
    """The job config composed from ``conf/`` with Hydra overrides (no run directory, no logging)."""
    return compose_config(list(overrides))


@pytest.fixture(scope="session", autouse=True)
def _coacd_cache(tmp_path_factory: pytest.TempPathFactory) -> None:
    """Keep convex decompositions out of the user's cache unless CI names one (GRASPEXP_CACHE)."""
    if "GRASPEXP_CACHE" not in os.environ:
        os.environ["GRASPEXP_CACHE"] = str(tmp_path_factory.mktemp("coacd-cache"))


@pytest.fixture(scope="session")
def data_root() -> Path:
    root = shared_data_root()
    if not root.is_dir():
        pytest.skip(f"real meshes not found at {root}")
    return root
