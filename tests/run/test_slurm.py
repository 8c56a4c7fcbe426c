"""The SLURM check (``.ci/slurm_check.py``): a sweep with one task cancelled and re-submitted equals an
uninterrupted one. Runs only where a SLURM cluster answers (``.ci/slurm_cluster.sh`` starts one)."""

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]


def _cluster_answers() -> bool:
    if not shutil.which("sbatch") or not shutil.which("sinfo"):
        return False
    try:
        proc = subprocess.run(["sinfo", "-h", "-p", "debug"], capture_output=True, timeout=15)
    except subprocess.TimeoutExpired:
        return False
    return proc.returncode == 0


@pytest.mark.slow
def test_cancelled_and_resubmitted_slurm_sweep_equals_an_uninterrupted_one(tmp_path: Path) -> None:
    if not _cluster_answers():  # asked here, not at collection: sinfo waits for a controller that is down
        pytest.skip("no SLURM cluster with a partition 'debug'")
    proc = subprocess.run(
        [sys.executable, str(REPO / ".ci" / "slurm_check.py"), str(tmp_path / "check")],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    assert "identical" in proc.stdout
