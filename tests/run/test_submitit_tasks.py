"""A submitit task that ends without a result (killed, cancelled, out of time) ends the sweep in one line
naming the task and the fix, exit status 2, and the trials it finished stay for the resume. Real processes
(``hydra/launcher=submitit_local``); the SLURM variant with ``scancel`` is ``.ci/slurm_check.py``."""

import os
import signal
import subprocess
import time
from pathlib import Path

import pytest

from graspexp.run.launchers import task_failure
from graspexp.run.multirun import multirun_command

pytestmark = pytest.mark.slow
REPO = Path(__file__).resolve().parents[2]


def test_submitit_messages_become_one_line() -> None:
    cancelled = "Job 41_1 (task: 0) with path /s/.submitit/41_1/41_1_0_result.pkl\nhas not produced any output (state: CANCELLED by 0)\nError stream produced:\n----\nslurmstepd: *** JOB 41 CANCELLED ***"
    line = task_failure(cancelled, failed=False)
    assert line.startswith("task 41_1 ended without a result (state CANCELLED). The sweep stopped waiting")
    assert "\n" not in line and line.endswith("finished trials are not run again)")
    raised = "Job 41_0 (task: 0) with path /s/r.pkl\nhas failed with:\nTraceback (most recent call last):\n  ...\nMemoryError: out of memory"
    assert task_failure(raised, failed=True).startswith("task 41_0 failed (MemoryError: out of memory)")


def test_a_killed_local_task_ends_the_sweep_in_one_line(tmp_path: Path) -> None:
    out = tmp_path / "sweep"
    job = ["mode=bin", "rot=z", "dataset=primitives", "objects=[can]", "trials=40", "progress=false"]
    cmd = multirun_command(out, job, launcher=["hydra/launcher=submitit_local"])
    proc = subprocess.Popen(cmd, cwd=REPO, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    job_dir = out / "dataset=primitives,mode=bin,objects=[can],rot=z,trials=40"
    deadline = time.monotonic() + 240
    while not list(job_dir.glob("trials/can/*.mcap")) and time.monotonic() < deadline:
        time.sleep(0.1)
    task = subprocess.run(["pgrep", "-f", f"submitit.core._submit {out}"], capture_output=True, text=True)
    assert task.stdout.split(), "no running submitit task found"
    for pid in task.stdout.split():
        os.kill(int(pid), signal.SIGKILL)
    kept = sorted(job_dir.glob("trials/can/*.mcap"))
    _, stderr = proc.communicate(timeout=240)
    assert proc.returncode == 2, stderr[-3000:]
    assert "Traceback" not in stderr
    errors = [ln for ln in stderr.splitlines() if ln.startswith("graspexp: error:")]
    assert len(errors) == 1 and "ended without a result" in errors[0], stderr[-3000:]
    assert "run the same command again to resume" in errors[0]
    assert 1 <= len(kept) < 40 and all(p.is_file() for p in kept)  # what it finished is kept
    assert not (out / ".graspexp-sweep.lock.holder").exists()  # the sweep released its directory
