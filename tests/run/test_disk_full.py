"""A run that cannot write its logs (a full disk; here a file-size limit, which fails the same writes):
one error line naming the fix, exit status 2, no partial file left; the same command then resumes."""

import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest
from helpers.cli import graspexp, run

pytestmark = pytest.mark.slow
REPO = Path(__file__).resolve().parents[2]
LIMITED = """
import resource, runpy, signal, sys
signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails with EFBIG instead
resource.setrlimit(resource.RLIMIT_FSIZE, (30_000, 30_000))
sys.argv = ["graspexp", *sys.argv[1:]]
runpy.run_module("graspexp", run_name="__main__")
"""
JOB = ["dataset=primitives", "objects=[can]", "trials=1", "progress=false"]  # conftest.FINISHED_RUN


def _run(*args: str, limited: bool = False) -> subprocess.CompletedProcess:
    """The job ``args``; with ``limited``, under a 30 kB file-size limit (a write past it fails: EFBIG)."""
    return run([sys.executable, "-c", LIMITED, *args]) if limited else graspexp(*args)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="RLIMIT_FSIZE and SIGXFSZ")
def test_a_full_disk_is_one_line_and_the_run_resumes(tmp_path, finished_run):
    run_dir = tmp_path / "run"
    full = _run(*JOB, f"hydra.run.dir={run_dir}", limited=True)
    assert full.returncode == 2, full.stderr[-2000:]
    lines = full.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in full.stderr
    assert lines[0].startswith("graspexp: error: cannot write the trial log ")
    assert "free space, then run the same command again" in lines[0]
    assert not list(run_dir.rglob("*.partial"))
    again = _run(*JOB, f"hydra.run.dir={run_dir}")
    assert again.returncode == 0, again.stderr[-2000:]
    keys = ["object", "trial", "seed", "success", "reason", "slip_m", "steps"]
    resumed, reference = (pd.read_csv(d / "results.csv")[keys] for d in (run_dir, finished_run))
    pd.testing.assert_frame_equal(resumed, reference)


def _tmpfs(path: Path, size: str) -> bool:
    """Mount a ``size`` tmpfs at ``path``; False where this process may not mount (not root, no CAP_SYS_ADMIN)."""
    path.mkdir(parents=True, exist_ok=True)
    return (
        subprocess.run(
            ["mount", "-t", "tmpfs", "-o", f"size={size}", "tmpfs", str(path)], capture_output=True
        ).returncode
        == 0
    )


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="a tmpfs mount")
@pytest.mark.parametrize(
    "job",
    [["dataset=primitives", "trials=20"], ["mode=pile", "dataset=primitives", "trials=6"]],
    ids=["trials", "rounds"],
)
def test_a_run_on_a_full_tmpfs_prints_no_traceback(tmp_path, job):
    """A real full disk (a 1 MiB tmpfs) fills while the logs are written: one error line, exit status 2, and
    no traceback anywhere in the output (Hydra's job log file, which cannot be written either, included)."""
    disk = tmp_path / "disk"
    if not _tmpfs(disk, "1m"):
        pytest.skip("cannot mount a tmpfs here (needs root)")
    try:
        full = graspexp(*job, "progress=false", f"hydra.run.dir={disk / 'run'}")
    finally:
        subprocess.run(["umount", str(disk)], capture_output=True)
    assert full.returncode == 2, (full.stdout[-1000:], full.stderr[-2000:])
    out = full.stdout + full.stderr
    assert "Traceback" not in out and "Logging error" not in out, full.stderr[-3000:]
    errors = [ln for ln in full.stderr.splitlines() if ln.startswith("graspexp: error:")]
    assert len(errors) == 1 and "free space" in errors[0], full.stderr[-2000:]
