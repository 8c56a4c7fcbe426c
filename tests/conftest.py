"""Shared fixtures: an isolated convex-decomposition cache, the real-mesh data root and one finished run
that the end-to-end checks share (helpers to import live in ``tests/helpers/``)."""

import os
import shutil
from pathlib import Path

import pytest
from helpers.cli import graspexp, ok
from helpers.config import shared_data_root


@pytest.fixture(scope="session", autouse=True)
def _coacd_cache(tmp_path_factory: pytest.TempPathFactory) -> None:
    """Keep convex decompositions out of the user's cache unless CI names one (GRASPEXP_CACHE)."""
    if "GRASPEXP_CACHE" not in os.environ:
        os.environ["GRASPEXP_CACHE"] = str(tmp_path_factory.mktemp("coacd-cache"))


@pytest.fixture(scope="session")
def data_root() -> Path:
    """The shared real meshes (``ycb/`` and ``linemod/``); tests that need them skip when they are absent."""
    root = shared_data_root()
    if not (root / "ycb").is_dir() or not (root / "linemod").is_dir():
        pytest.skip(f"real meshes (ycb/, linemod/) not found at {root}: set GRASPEXP_DATA")
    return root


FINISHED_RUN = ("dataset=primitives", "objects=[can]", "trials=1", "progress=false")
"""The job of :func:`finished_run`: one logged trial of the primitive can (default mode and rotation)."""


@pytest.fixture(scope="session")
def finished_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """One finished run of :data:`FINISHED_RUN` for the end-to-end checks of the session (a test that writes
    into it works on a copy: :func:`finished_run_copy`)."""
    run = tmp_path_factory.mktemp("finished") / "run"
    ok(graspexp(*FINISHED_RUN, f"hydra.run.dir={run}"))
    return run


@pytest.fixture
def finished_run_copy(finished_run: Path, tmp_path: Path) -> Path:
    """A private copy of :func:`finished_run`, to resume, refuse or damage."""
    out = tmp_path / "run"
    shutil.copytree(finished_run, out)
    return out
