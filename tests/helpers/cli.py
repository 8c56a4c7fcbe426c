"""``python -m graspexp`` in a subprocess, as a user runs it (one thread per process, output captured)."""

import os
import subprocess
import sys
from pathlib import Path

from graspexp.run.multirun import JOBLIB, multirun_command
from helpers.config import REPO


def graspexp(
    *args: str, cwd: Path = REPO, env: dict[str, str] | None = None, timeout: float = 300
) -> subprocess.CompletedProcess:
    """Run ``python -m graspexp ARGS`` (``env``: variables added to this process's)."""
    return run([sys.executable, "-m", "graspexp", *args], cwd=cwd, env=env, timeout=timeout)


def multirun(
    sweep_dir: Path, *overrides: str, launcher=JOBLIB, env: dict[str, str] | None = None, timeout: float = 300
) -> subprocess.CompletedProcess:
    """Run the sweep ``python -m graspexp -m ...`` into ``sweep_dir`` (:func:`multirun_command`)."""
    return run(multirun_command(sweep_dir, overrides, launcher=launcher), env=env, timeout=timeout)


def run(
    cmd: list[str], cwd: Path = REPO, env: dict[str, str] | None = None, timeout: float = 300
) -> subprocess.CompletedProcess:
    """Run ``cmd`` with ``OMP_NUM_THREADS=1`` and ``env`` added to this process's environment."""
    full = {**os.environ, "OMP_NUM_THREADS": "1", **(env or {})}
    return subprocess.run(cmd, cwd=cwd, env=full, capture_output=True, text=True, timeout=timeout)


def ok(proc: subprocess.CompletedProcess) -> subprocess.CompletedProcess:
    """``proc`` after checking that it exited 0 (else the failure shows its output's tail)."""
    assert proc.returncode == 0, (proc.stdout[-2000:], proc.stderr[-3000:])
    return proc


def one_error_line(proc: subprocess.CompletedProcess, prefix: str = "graspexp: error:") -> str:
    """The single ``prefix`` line of a refused command (exit status 2, no traceback)."""
    assert proc.returncode == 2, proc.stderr[-3000:]
    assert "Traceback" not in proc.stderr, proc.stderr[-3000:]
    lines = [ln for ln in proc.stderr.splitlines() if ln.startswith(prefix)]
    assert len(lines) == 1, proc.stderr[-3000:]
    return lines[0]


def run_job(run_dir: Path, *overrides: str, env: dict[str, str] | None = None) -> subprocess.CompletedProcess:
    """The job of ``overrides`` into ``run_dir`` (``hydra.run.dir``), without a progress bar."""
    return graspexp("progress=false", f"hydra.run.dir={run_dir}", *overrides, env=env)
