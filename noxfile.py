"""Sessions CI and developers call: ``nox -s tests``, ``nox -s lint``, ``nox -s docs``, ``nox -s wheel``,
``nox -s bench``, ``nox -s learned``, ``nox -s reproduce``, ``nox -s results``, ``nox -s slurm``."""

import os
import shutil
import tempfile
import time
from pathlib import Path

import nox
from nox.command import CommandFailed

nox.options.default_venv_backend = "venv"
nox.options.reuse_existing_virtualenvs = True
HERE = Path(__file__).parent
DATA = os.environ.get("GRASPEXP_DATA", str((HERE / ".." / "shared" / "datasets").resolve()))
ENV = {"GRASPEXP_DATA": DATA, "OMP_NUM_THREADS": "1"}
PEERS = (Path(DATA) / ".." / "peers").resolve()
CHECKPOINTS = os.environ.get(
    "GRASPEXP_CHECKPOINTS", os.pathsep.join(str(p) for p in sorted(PEERS.glob("*")) if p.is_dir())
)
"""The folders of the published checkpoints the learned planners read: every folder of ``../shared/peers``
(one per planner, searched in turn; never copied)."""


@nox.session
def tests(session: nox.Session) -> None:
    """The test suite (real SAPIEN physics) with the shared meshes as data root, in two processes."""
    session.install("-e", ".[test]")
    session.run("pytest", "-n", "2", "--dist", "worksteal", *session.posargs, env=ENV)


def _install_learned(session: nox.Session) -> bool:
    """Install the optional extra ``learned`` (torch's CPU build, Open3D) and check that it imports; False
    (with one line saying why) where it cannot be installed or loaded here."""
    try:
        session.install("-e", ".[learned]", "-c", "constraints.txt", silent=True)
        session.run("python", "-c", "import torch, open3d", silent=True)
    except CommandFailed:
        session.log(
            "the optional extra learned cannot be installed or imported here (torch==2.13.0 CPU build, "
            "open3d-cpu==0.20.0, which needs the system's libusb-1.0: apt-get install libusb-1.0-0)"
        )
        return False
    return True


@nox.session
def learned(session: nox.Session) -> None:
    """The learned planners' tests (``-m learned``: e.g. planner=vgn loads its checkpoint, gives the same
    outputs every time, plans on a rendered scene) with the optional extra ``learned`` installed, then the
    fingerprints of the results pages that run a learned planner (``results --check --learned-planners``:
    skipped by the check without the extra); skipped with one line where the extra cannot be installed."""
    session.install("-e", ".[test]", "-c", "constraints.txt")
    if not _install_learned(session):
        session.skip("nox -s learned skipped: the optional extra learned is not available on this machine")
    env = {**ENV, "GRASPEXP_CHECKPOINTS": CHECKPOINTS}
    session.run("pytest", "-m", "learned", "-p", "no:cacheprovider", *session.posargs, env=env)
    session.run("python", "-m", "graspexp", "results", "--check", "--learned-planners", env=env)


@nox.session
def lint(session: nox.Session) -> None:
    """ruff lint and format check."""
    session.install("ruff")
    session.run("ruff", "check", ".")
    session.run("ruff", "format", "--check", ".")


@nox.session
def docs(session: nox.Session) -> None:
    """The documentation site, built strictly (any warning fails): ``build/site/``. The configuration
    reference is generated from the schemas during the build (``docs/hooks.py``). ``nox -s docs -- serve``
    serves it with live reload instead."""
    session.install("-e", ".[docs]")
    env = {**ENV, "NO_MKDOCS_2_WARNING": "1"}
    if session.posargs[:1] == ["serve"]:
        session.run("mkdocs", "serve", *session.posargs[1:], env=env)
        return
    start = time.perf_counter()
    session.run("mkdocs", "build", "--strict", *session.posargs, env=env)
    session.log(f"docs: built in {time.perf_counter() - start:.1f} s")


WHEEL_SOURCE_SKIPS = {"build", "outputs", "datasets", "docs", "tests", "examples"}
"""Top-level entries ``nox -s wheel`` leaves out of the copy it builds from (with every top-level dot entry:
.git, .venv, .nox, caches; and ``__pycache__`` and egg-info anywhere): build outputs, data, runs."""


def _wheel_source_skips(folder: str, names: list[str]) -> set[str]:
    top = Path(folder) == HERE
    return {
        n
        for n in names
        if (top and (n in WHEEL_SOURCE_SKIPS or n.startswith(".")))
        or n == "__pycache__"
        or n.endswith(".egg-info")
    }


@nox.session(reuse_venv=False)
def wheel(session: nox.Session) -> None:
    """The installed app, not the checkout: build the wheel, install it (the tested dependency set,
    ``constraints.txt``, from the pip cache) into a fresh venv, then from an empty temporary folder run a
    job (the procedural objects, 1 trial each), ``report`` on it and ``plan``. Fails if ``graspexp`` or
    its YAML (``conf/``, shipped as ``graspexp.conf``) is found anywhere but in the venv."""
    start = time.perf_counter()
    tmp = Path(session.create_tmp())
    src, dist = tmp / "src", tmp / "dist"
    shutil.rmtree(src, ignore_errors=True)
    shutil.rmtree(dist, ignore_errors=True)
    # built from a copy without build outputs: setuptools would package a stale build/lib (a module
    # removed since the last build) and the checkout's egg-info
    shutil.copytree(HERE, src, ignore=_wheel_source_skips)
    session.run("python", "-m", "pip", "wheel", "-q", "--no-deps", "-w", str(dist), str(src))
    (built,) = dist.glob("graspexp-*.whl")
    # from the pip cache; not byte-compiled at install (the job compiles what it imports), which halves the
    # install's CPU time
    session.install("-q", "--no-compile", str(built), "-c", str(HERE / "constraints.txt"))
    installed_s = time.perf_counter() - start
    with tempfile.TemporaryDirectory(prefix="graspexp-wheel-") as work:
        session.chdir(work)
        env = {**ENV, "PYTHONPATH": ""}
        where = "import graspexp.config.registry as r; print(r.__file__); print(r.CONF_DIR)"
        found = session.run("python", "-c", where, silent=True, env=env).split()
        session.log(f"wheel: graspexp from {found[0]}, its YAML from {found[1]}")
        if any(not path.startswith(session.virtualenv.location) for path in found):
            session.error(f"wheel: graspexp or its conf/ found outside the venv: {found}")
        job = ["dataset=primitives", "trials=1", "progress=false", "hydra.run.dir=run"]
        session.run("graspexp", *job, env=env)
        session.run("graspexp", "report", "run", env=env)
        session.run("graspexp", "plan", "dataset=primitives", "objects=[can]", env=env)
    session.log(
        f"wheel: built and installed in {installed_s:.1f} s, total {time.perf_counter() - start:.1f} s wall"
    )


@nox.session
def bench(session: nox.Session) -> None:
    """Planner latency per Table 1 object, registration accuracy and depth + registration time per Table
    1/2 object (the camera extra), the per-phase trial benchmark, the clutter benchmark (a round's attempt
    beside a bin trial, planning latency per scene), then the 720-trial reproduction
    (logged, warm collision cache) with 1 and 2 workers; then, where the optional extra ``learned``
    installs, the learned planners' inference time (``bench.learned``)."""
    session.install("-e", ".[camera]")
    session.run("python", "-m", "graspexp", "bench.plan_latency", *session.posargs, env=ENV)
    session.run("python", "-m", "graspexp", "bench.registration", *session.posargs, env=ENV)
    session.run("python", "-m", "graspexp", "bench.trials", *session.posargs, env=ENV)
    session.run("python", "-m", "graspexp", "bench.clutter", "dataset=ycb", env=ENV)
    session.run("python", "-m", "graspexp", "bench.reproduce", *session.posargs, env=ENV)
    if _install_learned(session):  # the learned planners' inference time, where the extra installs
        env = {**ENV, "GRASPEXP_CHECKPOINTS": CHECKPOINTS}
        session.run("python", "-m", "graspexp", "bench.learned", env=env)


@nox.session(venv_backend="none")
def reproduce(session: nox.Session) -> None:
    """Paper Tables 1 and 2: YCB and LINEMOD x {collab, bin} x {z, xyz} x 10 trials with the paper's
    planner (``optimal``) and beside it ``optimal_in_area`` (every pad contact in the area), then the report.

    Runs in the environment nox is started from (activate the project venv first), so the wall time
    printed is the experiment's, not an install's. The multirun is resumable: running the session
    again skips finished trials. ``nox -s reproduce -- DIR`` writes into DIR (default
    outputs/reproduce); further posargs are extra overrides (e.g. ``trials=30`` for more power,
    ``hydra.launcher.n_jobs=4``).
    """
    out = session.posargs[0] if session.posargs else "outputs/reproduce"
    extra = list(session.posargs[1:])
    suite = session.run("python", "-m", "graspexp.run.suites", silent=True, env=ENV, external=True)
    given = {e.split("=")[0] for e in extra}
    suite_overrides = [o for o in suite.split() if o.split("=")[0] not in given]
    start = time.perf_counter()
    session.run(
        "python", "-m", "graspexp.run.multirun", out, *suite_overrides, *extra, env=ENV, external=True
    )
    sweep_s = time.perf_counter() - start
    session.run("python", "-m", "graspexp", "report", out, env=ENV, external=True)
    total_s = time.perf_counter() - start
    session.log(
        f"reproduce: sweep {sweep_s:.1f} s, report {total_s - sweep_s:.1f} s, wall time {total_s:.1f} s"
    )


@nox.session(venv_backend="none")
def compare(session: nox.Session) -> None:
    """Six planners x pose noise on a small setting (primitives can/mug/banana, bin, rot z, 3 trials:
    ``graspexp.run.suites.COMPARE_SUITE``), then ``python -m graspexp compare``. ``nox -s compare -- DIR [overrides...]`` (default outputs/compare);
    resumable."""
    out = session.posargs[0] if session.posargs else "outputs/compare"
    extra = list(session.posargs[1:])
    start = time.perf_counter()
    suite = session.run("python", "-m", "graspexp.run.suites", "compare", silent=True, env=ENV, external=True)
    session.run("python", "-m", "graspexp.run.multirun", out, *suite.split(), *extra, env=ENV, external=True)
    session.run("python", "-m", "graspexp", "compare", out, "--out", f"{out}/compare", env=ENV, external=True)
    session.log(f"compare: {time.perf_counter() - start:.0f} s wall")


@nox.session(venv_backend="none")
def readings(session: nox.Session) -> None:
    """Every reading of the paper and every other planner on Tables 1 and 2 (``python -m graspexp readings``),
    then the readings table. ``nox -s readings -- [--out OUT] [--only a,b] [trials=N]``; resumable."""
    start = time.perf_counter()
    session.run("python", "-m", "graspexp", "readings", *session.posargs, env=ENV, external=True)
    session.log(f"readings: {time.perf_counter() - start:.0f} s wall")


@nox.session(venv_backend="none")
def results(session: nox.Session) -> None:
    """Every results page (``docs/results/``) and the README's results table from runs of this code
    (``python -m graspexp results``): resumable (run it again after an interruption), progress on stderr.
    ``nox -s results -- --check`` checks the pages' fingerprints instead; further posargs go to the tool
    (``--pages index,readme``, ``hydra/launcher=submitit_slurm hydra.launcher.partition=P``)."""
    start = time.perf_counter()
    session.run("python", "-m", "graspexp", "results", *session.posargs, env=ENV, external=True)
    session.log(f"results: {time.perf_counter() - start:.0f} s wall")


@nox.session(venv_backend="none")
def slurm(session: nox.Session) -> None:
    """A sweep on a real one-node SLURM cluster: ``.ci/slurm_cluster.sh`` installs (Debian 12, as root)
    and starts munged, MariaDB, slurmdbd, slurmctld and slurmd; a small sweep runs with
    ``hydra/launcher=submitit_slurm``, one array task is cancelled mid-run with ``scancel``, the same command
    is re-submitted into the same sweep dir, and ``bench.compare_runs`` must find every trial identical to
    an uninterrupted joblib sweep; then the cluster is stopped. Non-zero exit on any difference.

    Runs in the environment nox is started from (activate the project venv first). ``nox -s slurm -- DIR``
    writes into DIR (default outputs/slurm_check, emptied first). The logic is ``.ci/slurm_check.py``
    (``python .ci/slurm_check.py --cluster [DIR]`` without nox; without ``--cluster`` on a running cluster).
    """
    start = time.perf_counter()
    session.run("python", ".ci/slurm_check.py", "--cluster", *session.posargs, env=ENV, external=True)
    session.log(f"slurm: {time.perf_counter() - start:.0f} s wall")
