"""A sweep on a real SLURM cluster, one task cancelled mid-run and re-submitted, equals an uninterrupted sweep.

``python .ci/slurm_check.py [--cluster] [OUT]`` (OUT: default outputs/slurm_check, emptied first) needs a
running cluster with a partition ``debug``; ``--cluster`` starts one first with ``.ci/slurm_cluster.sh``
(root; installs Debian's packages if missing) and stops it at the end (``nox -s slurm`` does this).

1. ``OUT/ref``: the sweep with the joblib launcher (local processes), uninterrupted.
2. ``OUT/slurm``: the same sweep with ``hydra/launcher=submitit_slurm``; once the ``mode=bin`` task (array
   task 1) has written its first trial log, ``scancel`` ends it (submitit's job ignores the SIGTERM; the
   cluster's KillWait of 1 s brings the SIGKILL). The submitting process must end in one line naming the
   task and its state, exit status 2, no traceback, and every trial finished before stays.
3. The same command again into ``OUT/slurm`` (resume): exit 0, the trials finished before the cancel are
   read back, not re-run.
4. ``python -m graspexp bench.compare_runs OUT/ref OUT/slurm``: every trial identical.

Exit status 0 when all holds; 1 with the reason otherwise. Prints each step's wall time.
"""

import argparse
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

from graspexp.run.multirun import multirun_command

REPO = Path(__file__).resolve().parents[1]
NAME = "graspexp-slurm-check"
SWEEP = ["mode=collab,bin", "rot=z", "dataset=primitives", "objects=[can,box]", "trials=40", "progress=false"]
N_TRIALS_PER_JOB = 2 * 40  # objects x trials: enough that the task outlives the ~3 s scancel takes to kill it
SLURM = [
    "hydra/launcher=submitit_slurm",
    "hydra.launcher.partition=debug",
    f"hydra.launcher.name={NAME}",
    "hydra.launcher.timeout_min=10",
    "hydra.launcher.cpus_per_task=1",
]
CANCELLED_TASK = 1  # array task i runs Hydra job i: mode=collab is 0, mode=bin is 1
CANCELLED_DIR = "dataset=primitives,mode=bin,objects=[can,box],rot=z,trials=40"
# sbatch exports the submitting environment: the jobs run this checkout with the same interpreter and data
ENV = {
    **os.environ,
    "OMP_NUM_THREADS": "1",
    "PYTHONPATH": os.pathsep.join(p for p in (str(REPO), os.environ.get("PYTHONPATH")) if p),
}


def fail(message: str) -> None:
    print(f"slurm_check: FAILED: {message}", file=sys.stderr)
    raise SystemExit(1)


def sweep(out: Path, *launcher: str) -> list[str]:
    return multirun_command(out, SWEEP, launcher=launcher)


def run(cmd: list[str], timeout: float = 600) -> subprocess.CompletedProcess:
    start = time.perf_counter()
    proc = subprocess.run(cmd, cwd=REPO, env=ENV, capture_output=True, text=True, timeout=timeout)
    print(
        f"slurm_check: {' '.join(cmd[2:4])}... exit {proc.returncode} in {time.perf_counter() - start:.1f} s"
    )
    return proc


def logs(folder: Path) -> dict[Path, int]:
    """Finished trial logs of a job directory (one being written is ``*.mcap.partial``), with mtimes."""
    return {p: p.stat().st_mtime_ns for p in sorted(folder.glob("trials/*/*.mcap"))}


def array_task(job_name: str) -> str | None:
    """``<array job id>_<CANCELLED_TASK>`` once that task is running, else None."""
    out = subprocess.run(
        ["squeue", "-h", "-n", job_name, "-t", "RUNNING", "-o", "%i"], capture_output=True, text=True
    ).stdout
    wanted = [t for t in out.split() if t.endswith(f"_{CANCELLED_TASK}")]
    return wanted[0] if wanted else None


def cancelled_run(out: Path) -> dict[Path, int]:
    """The SLURM sweep with one task cancelled once it has a finished trial; the logs kept then."""
    start = time.perf_counter()
    proc = subprocess.Popen(
        sweep(out, *SLURM), cwd=REPO, env=ENV, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True
    )
    task, deadline = None, time.monotonic() + 300
    while proc.poll() is None and time.monotonic() < deadline:
        task = task or array_task(NAME)
        if task and logs(out / CANCELLED_DIR):
            subprocess.run(["scancel", task], check=True)
            break
        time.sleep(0.05)
    else:
        proc.kill()
        subprocess.run(["scancel", "-n", NAME])
        output = proc.communicate()[0]
        fail(
            f"the sweep ended or timed out before task {CANCELLED_TASK} had a trial log; it said:\n{output[-3000:]}"
        )
    output, _ = proc.communicate(timeout=600)
    print(
        f"slurm_check: SLURM sweep, {task} cancelled: exit {proc.returncode} in {time.perf_counter() - start:.1f} s"
    )
    kept = logs(out / CANCELLED_DIR)
    state = subprocess.run(
        ["sacct", "-n", "-X", "-P", "-j", task, "-o", "State"], capture_output=True, text=True
    ).stdout.strip()
    print(
        f"slurm_check: {task} {state}, {len(kept)} of {N_TRIALS_PER_JOB} trials finished; the submitter said:"
    )
    print("\n".join(output.splitlines()[-12:]))
    if not state.startswith("CANCELLED") or not 1 <= len(kept) < N_TRIALS_PER_JOB:
        fail(f"{task} was not cancelled mid-run (state {state!r}, {len(kept)} trials)")
    if proc.returncode != 2:
        fail(f"the sweep exited {proc.returncode}, not 2, although one of its tasks was cancelled")
    errors = [ln for ln in output.splitlines() if ln.startswith("graspexp: error:")]
    expected = f"graspexp: error: task {task} ended without a result (state CANCELLED)"
    if "Traceback" in output or len(errors) != 1 or not errors[0].startswith(expected):
        fail(f"the submitter did not end in one line starting {expected!r}:\n{output[-3000:]}")
    return kept


def check(out: Path) -> None:
    if subprocess.run(["sinfo", "-h", "-p", "debug"], capture_output=True).returncode != 0:
        fail("no SLURM cluster with a partition 'debug' answers (start one: .ci/slurm_cluster.sh)")
    subprocess.run(
        ["scancel", "-n", NAME], check=True
    )  # jobs of an earlier check, lest they be taken for ours
    shutil.rmtree(out, ignore_errors=True)
    start = time.perf_counter()
    if run(sweep(out / "ref", "hydra/launcher=joblib", "hydra.launcher.n_jobs=2")).returncode != 0:
        fail("the reference sweep failed")
    kept = cancelled_run(out / "slurm")
    resumed = run(sweep(out / "slurm", *SLURM))
    if resumed.returncode != 0:
        fail(f"the re-submitted sweep failed:\n{resumed.stderr[-3000:]}")
    changed = [p for p, mtime in kept.items() if not p.exists() or p.stat().st_mtime_ns != mtime]
    if changed:
        fail(f"trials finished before the cancel were run again: {changed}")
    compared = run(
        [sys.executable, "-m", "graspexp", "bench.compare_runs", str(out / "ref"), str(out / "slurm")]
    )
    print(compared.stdout, end="")
    if compared.returncode != 0 or "identical" not in compared.stdout:
        fail("the resumed SLURM sweep differs from the uninterrupted one")
    print(f"slurm_check: OK in {time.perf_counter() - start:.1f} s")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", nargs="?", type=Path, default=REPO / "outputs" / "slurm_check")
    parser.add_argument(
        "--cluster", action="store_true", help="start a one-node cluster first, stop it after"
    )
    args = parser.parse_args()
    if not args.cluster:
        return check(args.out.absolute())
    script = REPO / ".ci" / "slurm_cluster.sh"
    start = time.perf_counter()
    subprocess.run(["bash", str(script), "start"], check=True)
    print(f"slurm_check: cluster up in {time.perf_counter() - start:.1f} s")
    try:
        check(args.out.absolute())
    finally:
        subprocess.run(["bash", str(script), "stop"], check=True)


if __name__ == "__main__":
    main()
