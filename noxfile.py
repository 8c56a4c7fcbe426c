"""Sessions CI and developers call: ``nox -s tests``, ``nox -s lint``, ``nox -s bench``, ``nox -s reproduce``."""

import os
from pathlib import Path

import nox

nox.options.default_venv_backend = "venv"
nox.options.reuse_existing_virtualenvs = True
HERE = Path(__file__).parent
DATA = os.environ.get("GRASPEXP_DATA", str((HERE / ".." / "shared" / "datasets").resolve()))
ENV = {"GRASPEXP_DATA": DATA, "OMP_NUM_THREADS": "1"}


@nox.session
def tests(session: nox.Session) -> None:
    """The test suite (real SAPIEN physics) with the shared meshes as data root."""
    session.install("-e", ".[test]")
    session.run("pytest", *session.posargs, env=ENV)


@nox.session
def lint(session: nox.Session) -> None:
    """ruff lint and format check."""
    session.install("ruff")
    session.run("ruff", "check", ".")
    session.run("ruff", "format", "--check", ".")


@nox.session
def bench(session: nox.Session) -> None:
    """Planner latency per Table 1 object, then the per-phase trial benchmark."""
    session.install("-e", ".")
    session.run("python", "-m", "graspexp.bench.plan_latency", *session.posargs, env=ENV)
    session.run("python", "-m", "graspexp.bench.trials", *session.posargs, env=ENV)
