"""Multiruns: the joblib and submitit_local launchers, and a sweep killed with SIGKILL then resumed.

Each test runs the real CLI (``python -m graspexp -m ...``) in a subprocess on the offline primitives
dataset with a few trials, so it needs no meshes and stays fast.
"""

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pandas as pd
import pytest
from helpers.cli import ok, run

from graspexp.report.collect import collect
from graspexp.run.jobs import job_dir_name
from graspexp.run.multirun import multirun_command

REPO = Path(__file__).resolve().parents[2]
SWEEP = ["mode=collab,bin", "rot=z", "dataset=primitives", "objects=[can,box]", "trials=3", "progress=false"]
N_TRIALS = 2 * 2 * 3  # settings x objects x trials
COLUMNS = ["dataset", "planner", "mode", "rot", "object", "trial", "seed", "success", "reason"]


def _cmd(sweep_dir: Path, *extra: str) -> list[str]:
    return multirun_command(sweep_dir, [*SWEEP, *extra], launcher=())


def _env() -> dict[str, str]:
    return {**os.environ, "OMP_NUM_THREADS": "1", "HYDRA_FULL_ERROR": "1"}


def _run(cmd: list[str], timeout: float = 120) -> subprocess.CompletedProcess:
    return ok(run(cmd, env={"HYDRA_FULL_ERROR": "1"}, timeout=timeout))


def _table(sweep_dir: Path) -> pd.DataFrame:
    """success / reason per trial, read from the logs."""
    col = collect(sweep_dir)
    assert col.unreadable == []
    return col.results[COLUMNS].sort_values(COLUMNS[:6]).reset_index(drop=True)


def _logs(sweep_dir: Path) -> list[Path]:
    return sorted(sweep_dir.glob("*/trials/*/*.mcap"))


@pytest.fixture(scope="module")
def joblib_sweep(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """An uninterrupted sweep of two tiny settings with the joblib launcher (local processes)."""
    out = tmp_path_factory.mktemp("sweeps") / "joblib"
    _run(_cmd(out, "hydra/launcher=joblib", "hydra.launcher.n_jobs=2"))
    return out


@pytest.mark.slow
def test_joblib_multirun_runs_each_setting_into_its_own_dir(joblib_sweep: Path) -> None:
    subdirs = sorted(p.name for p in joblib_sweep.iterdir() if p.is_dir())
    assert subdirs == [
        "dataset=primitives,mode=bin,objects=[can,box],rot=z,trials=3",
        "dataset=primitives,mode=collab,objects=[can,box],rot=z,trials=3",
    ]
    assert len(_logs(joblib_sweep)) == N_TRIALS
    table = _table(joblib_sweep)
    assert sorted(set(table["mode"])) == ["bin", "collab"] and set(table["rot"]) == {"z"}
    assert table.groupby(["mode", "object"]).size().tolist() == [3, 3, 3, 3]
    for sub in subdirs:
        csv = pd.read_csv(joblib_sweep / sub / "results.csv")
        assert len(csv) == 6


@pytest.mark.slow
def test_sweep_killed_midway_and_resumed_equals_an_uninterrupted_one(
    joblib_sweep: Path, tmp_path: Path
) -> None:
    out = tmp_path / "killed"
    proc = subprocess.Popen(
        _cmd(out),
        cwd=REPO,
        env=_env(),
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    try:
        deadline = time.monotonic() + 90
        while len(_logs(out)) < 3 and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.02)
        os.killpg(proc.pid, signal.SIGKILL)
    finally:
        proc.wait(timeout=30)
    assert proc.returncode == -signal.SIGKILL, "the sweep finished before it could be killed"
    done = {p: p.stat().st_mtime_ns for p in _logs(out)}
    assert 3 <= len(done) < N_TRIALS

    _run(_cmd(out))  # resume into the same sweep dir (basic launcher this time)
    assert len(_logs(out)) == N_TRIALS
    assert not list(out.glob("*/trials/*/*.partial"))
    # finished trials were read back, not re-run
    assert {p: p.stat().st_mtime_ns for p in done} == done
    pd.testing.assert_frame_equal(_table(out), _table(joblib_sweep))


@pytest.mark.slow
def test_submitit_local_launcher(tmp_path: Path) -> None:
    out = tmp_path / "submitit"
    cmd = [
        sys.executable, "-m", "graspexp", "-m", "mode=collab", "dataset=primitives", "objects=[can]", "trials=1",
        "progress=false", "hydra/launcher=submitit_local", "hydra.launcher.timeout_min=5", f"hydra.sweep.dir={out}",
    ]  # fmt: skip
    _run(cmd, timeout=180)
    logs = _logs(out)
    assert [p.relative_to(out).parts[-2:] for p in logs] == [("can", "000.mcap")]
    assert list(out.glob(".submitit/*/*_log.out")), "no submitit job log"
    table = _table(out)
    assert table[["mode", "object", "trial"]].values.tolist() == [["collab", "can", 0]]


@pytest.mark.slow
@pytest.mark.parametrize("launcher", ["basic", "joblib"])
def test_a_job_that_cannot_run_does_not_stop_the_sweep(tmp_path: Path, launcher: str) -> None:
    out, empty = tmp_path / "sweep", tmp_path / "empty"
    empty.mkdir()
    cmd = [
        sys.executable, "-m", "graspexp", "-m", "dataset=linemod,primitives", "objects=[can]", "trials=1", "progress=false", f"hydra.sweep.dir={out}", f"hydra/launcher={launcher}",
    ]  # fmt: skip
    env = {**_env(), "GRASPEXP_DATA": str(empty)}
    proc = subprocess.run(cmd, cwd=REPO, env=env, capture_output=True, text=True, timeout=180)
    assert proc.returncode == 1, proc.stderr[-3000:]
    assert "Traceback" not in proc.stderr
    bad = "dataset=linemod,objects=[can],trials=1"
    summary = proc.stderr[proc.stderr.index("graspexp: 1 job(s) of the sweep failed:") :].splitlines()
    assert len(summary) == 2 and summary[1].startswith(
        f"  {bad}: mesh file for linemod object 'can' not found"
    )
    assert [p.relative_to(out).parts[0] for p in _logs(out)] == [bad.replace("linemod", "primitives")]
    assert not (out / bad / "trials").exists()


@pytest.mark.slow
def test_long_sweep_values_get_short_unique_dir_names_and_resume(tmp_path: Path) -> None:
    out = tmp_path / "sweep"
    roots = [f"/{c * 300}" for c in "ab"]  # the primitives ignore the data root: any value runs
    cmd = [
        sys.executable, "-m", "graspexp", "-m", f"dataset.root={roots[0]},{roots[1]}", "objects=[can]", "trials=1",
        "progress=false", f"hydra.sweep.dir={out}",
    ]  # fmt: skip
    _run(cmd)
    logs = _logs(out)
    names = sorted({p.relative_to(out).parts[0] for p in logs})
    assert len(logs) == 2 and len(names) == 2
    assert [n[:17] for n in names] == ["dataset.root=_aaa", "dataset.root=_bbb"]
    assert all(len(n) <= 120 for n in names)
    before = {p: p.stat().st_mtime_ns for p in logs}
    _run(cmd)
    assert {p: p.stat().st_mtime_ns for p in _logs(out)} == before


def test_job_dir_name_is_readable_short_and_unique() -> None:
    assert job_dir_name(["mode=bin", "rot=z", "progress=false"], ["progress"]) == "mode=bin,rot=z"
    long = [f"objects=[{','.join(f'obj_{i:03d}' for i in range(200))}]"]
    name = job_dir_name(long, [])
    assert name.startswith("objects=[obj_000,obj_001,obj_00~") and len(name) <= 120
    other = job_dir_name([long[0].replace("199", "200")], [])
    assert other != name and len(other) == len(name)
    many = [f"k{i}=v{i}" for i in range(60)]
    assert len(job_dir_name(many, [])) == 120 and "/" not in job_dir_name(["dataset.root=/a/b"], [])


@pytest.mark.slow
def test_a_second_sweep_into_a_running_sweeps_directory_is_refused_before_any_job(tmp_path: Path) -> None:
    from graspexp.core.run_layout import SWEEP_LOCK_NAME
    from graspexp.run.locks import DirectoryLock

    sweep = tmp_path / "sweep"
    with DirectoryLock(sweep, SWEEP_LOCK_NAME, "sweep"):  # the first sweep, still launching its jobs
        proc = subprocess.run(_cmd(sweep), cwd=REPO, env=_env(), capture_output=True, text=True, timeout=120)
    assert proc.returncode == 2, proc.stderr[-2000:]
    lines = [ln for ln in proc.stderr.splitlines() if ln.startswith("graspexp: error:")]
    assert len(lines) == 1 and f"{sweep} is in use by another sweep (pid {os.getpid()} on " in lines[0]
    assert "Traceback" not in proc.stderr
    assert not [p for p in sweep.iterdir() if not p.name.startswith(SWEEP_LOCK_NAME)]  # no job started
    _run(_cmd(sweep))  # once it is free, the sweep runs
    assert not (sweep / f"{SWEEP_LOCK_NAME}.holder").exists()
