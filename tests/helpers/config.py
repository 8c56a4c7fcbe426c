"""The repository, the real-mesh data root and composed job configs."""

import os
from pathlib import Path

from omegaconf import DictConfig

from graspexp.config.compose import compose_config

REPO = Path(__file__).resolve().parent.parent


def shared_data_root() -> Path:
    """``GRASPEXP_DATA`` if set, else ``../shared/datasets`` beside the checkout."""
    return Path(os.environ.get("GRASPEXP_DATA", REPO.parent / "shared" / "datasets"))


def compose_cfg(*overrides: str) -> DictConfig:
    """The job config composed from ``conf/`` with Hydra overrides (no run directory, no logging)."""
    return compose_config(list(overrides))
