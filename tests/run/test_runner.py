"""The runner's trust rules: resume reuses only logs of the same config, input errors stop a job before any
trial is recorded, error trials are redone, one writer per directory, one line for an unusable output folder,
the config frozen once validated.

Each end-to-end test runs the real CLI on the offline primitives dataset with one trial of ``can``.
"""

import os
from pathlib import Path

import pandas as pd
import pytest
from helpers.cli import one_error_line, run_job
from helpers.config import compose_cfg
from helpers.logs import foreign_log
from omegaconf import OmegaConf
from omegaconf.errors import ReadonlyConfigError

from graspexp.config.differences import config_differences
from graspexp.core.outcome import FailureReason, TrialResult
from graspexp.datasets import DatasetError
from graspexp.record import TrialRecorder, read_result
from graspexp.run.provenance import job_metadata
from graspexp.run.resume import job_lock
from graspexp.run.runner import run_in_dir
from graspexp.run.summary import summarize

REPO = Path(__file__).resolve().parents[2]
BASE = ("objects=[can]", "trials=1")


@pytest.fixture
def run_copy(finished_run_copy: Path) -> Path:
    """A copy of the session's finished run (conftest.FINISHED_RUN: the job of BASE, one trial)."""
    return finished_run_copy


@pytest.mark.slow
def _snapshot(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


@pytest.mark.slow
def test_resume_refuses_logs_made_with_another_config(run_copy: Path) -> None:
    log = run_copy / "trials" / "can" / "000.mcap"
    before = log.read_bytes()
    assert (run_copy / ".hydra" / "config.yaml").is_file()  # written once the run was accepted
    snapshot = _snapshot(run_copy)
    line = one_error_line(run_job(run_copy, "mode=bin", "gripper=panda", "seed=7", *BASE))
    assert _snapshot(run_copy) == snapshot  # nothing written, Hydra's .hydra/ included
    assert line.startswith(f"graspexp: error: {run_copy} holds trial logs made with a different config; ")
    assert "differing keys: gripper.name, mode.name, seed, " in line
    assert "mode.name: 'collab' in the log, 'bin' now" in line
    assert log.read_bytes() == before
    assert not (run_copy / "trials" / "can" / "001.mcap").exists()


@pytest.mark.slow
def test_resume_ignores_keys_that_do_not_change_a_result(run_copy: Path) -> None:
    log = run_copy / "trials" / "can" / "000.mcap"
    before = log.stat().st_mtime_ns
    proc = run_job(run_copy, "objects=[can]", "trials=2", "progress=true", "sim.cache_dir=null")
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert log.stat().st_mtime_ns == before
    assert (run_copy / "trials" / "can" / "001.mcap").is_file()


def test_config_differences_name_every_result_key_and_skip_neutral_ones() -> None:
    cfg = compose_cfg(*BASE)
    recorded = job_metadata(cfg)["config_yaml"]
    assert config_differences(recorded, compose_cfg("objects=[box]", "trials=5", "progress=false")) == {}
    diff = config_differences(recorded, compose_cfg(*BASE, "sim.close_s=0.8", "gripper=panda"))
    assert diff["sim.close_s"] == (0.6, 0.8) and diff["gripper.name"] == ("rg2", "panda")


def test_a_key_added_since_the_log_counts_as_equal_only_at_its_default() -> None:
    recorded = OmegaConf.create(job_metadata(compose_cfg(*BASE))["config_yaml"])
    del recorded.sim["min_finger_force_n"]  # a log written before the key existed
    old_log = OmegaConf.to_yaml(recorded)
    assert config_differences(old_log, compose_cfg(*BASE)) == {}
    assert config_differences(old_log, compose_cfg(*BASE, "sim.min_finger_force_n=2")) == {
        "sim.min_finger_force_n": ("<absent>", 2.0)
    }


def test_a_key_added_with_a_new_behaviour_counts_as_its_value_before() -> None:
    """``sim.settle_hold_s`` came with a longer settle (0.1 s); logs without it settled in one step (0)."""
    recorded = OmegaConf.create(job_metadata(compose_cfg(*BASE))["config_yaml"])
    del recorded.sim["settle_hold_s"]
    old_log = OmegaConf.to_yaml(recorded)
    assert config_differences(old_log, compose_cfg(*BASE)) == {"sim.settle_hold_s": ("<absent>", 0.1)}
    assert config_differences(old_log, compose_cfg(*BASE, "sim.settle_hold_s=0")) == {}


def test_a_list_key_added_since_the_log_counts_as_equal_at_its_default() -> None:
    cfg = compose_cfg(*BASE, "planner=antipodal")
    recorded = OmegaConf.create(job_metadata(cfg)["config_yaml"])
    del recorded.planner["fallback_modes"]  # a list default (default_factory)
    assert config_differences(OmegaConf.to_yaml(recorded), cfg) == {}
    changed = compose_cfg(*BASE, "planner=antipodal", "planner.fallback_modes=[collab]")
    assert config_differences(OmegaConf.to_yaml(recorded), changed) == {
        "planner.fallback_modes": ("<absent>", ["collab"])
    }


@pytest.mark.parametrize(
    ("overrides", "message"),
    [
        (
            ("dataset=ycb", "dataset.root={empty}", "objects=[025_mug]"),
            "mesh file for ycb object '025_mug' not found",
        ),
        (("dataset.regions=nope.yaml", "objects=[can]"), "nope.yaml"),
    ],
)
@pytest.mark.slow
def test_missing_input_stops_the_job_before_any_trial_is_recorded(
    tmp_path: Path, overrides: tuple[str, ...], message: str
) -> None:
    (tmp_path / "empty").mkdir()
    run = tmp_path / "run"
    args = [o.format(empty=tmp_path / "empty") for o in overrides]
    line = one_error_line(run_job(run, *args, "trials=1"))
    assert message in line
    assert not (run / "trials").exists() and not (run / "results.csv").exists()


@pytest.mark.slow
def test_error_trial_is_redone_on_resume(run_copy: Path) -> None:
    cfg = compose_cfg(*BASE)
    path = run_copy / "trials" / "can" / "000.mcap"
    old = TrialResult.from_dict(read_result(path))
    error = TrialResult(
        **{**old.to_dict(), "success": False, "reason": FailureReason.ERROR.value, "error": "RuntimeError: x"}
    )
    path.unlink()
    meta = {**job_metadata(cfg), "object": "can", "trial": "0", "trial_seed": str(old.seed)}
    with TrialRecorder(path, meta) as rec:
        rec.result(0.0, error.to_dict())
    assert read_result(path)["reason"] == "error"
    proc = run_job(run_copy, *BASE)
    assert proc.returncode == 0, proc.stderr[-2000:]
    redone = read_result(path)
    assert (redone["reason"], redone["success"]) == (old.reason, old.success)
    assert pd.read_csv(run_copy / "results.csv")["success"].tolist() == [old.success]
    (kept,) = (run_copy / "trials" / ".quarantine" / "can").iterdir()  # the error log is kept, not deleted
    assert kept.name.startswith("000.mcap.") and read_result(kept)["reason"] == "error"


@pytest.mark.slow
def test_foreign_and_damaged_files_in_trials_are_moved_aside_never_reused_or_deleted(run_copy: Path) -> None:
    good = read_result(run_copy / "trials" / "can" / "000.mcap")
    foreign = run_copy / "trials" / "can" / "001.mcap"
    foreign_log(foreign, {**good, "trial": 1, "success": True, "reason": None})
    forged = run_copy / "trials" / "box" / "000.mcap"
    forged.parent.mkdir()
    forged.write_bytes(b"\x89MCAP0\r\n not a log")
    proc = run_job(run_copy, "objects=[can]", "trials=2")
    assert proc.returncode == 0, proc.stderr[-2000:]
    quarantined = sorted(
        p.relative_to(run_copy / "trials" / ".quarantine")
        for p in (run_copy / "trials" / ".quarantine").rglob("*.mcap.*")
    )
    assert [(q.parent.name, q.name.split(".")[0]) for q in quarantined] == [("box", "000"), ("can", "001")]
    assert read_result(run_copy / "trials" / "can" / "001.mcap")["trial"] == 1  # trial 1 was run for real
    results = pd.read_csv(run_copy / "results.csv")
    assert sorted(zip(results["object"], results["trial"], strict=True)) == [("can", 0), ("can", 1)]


@pytest.mark.slow
def test_a_rerun_with_fewer_trials_keeps_every_trial_in_the_table(run_copy: Path) -> None:
    assert run_job(run_copy, "objects=[can]", "trials=2").returncode == 0
    assert run_job(run_copy, "objects=[can]", "trials=1").returncode == 0
    assert pd.read_csv(run_copy / "results.csv")["trial"].tolist() == [0, 1]
    assert "|        2 |" in (run_copy / "summary.md").read_text()


@pytest.mark.slow
def test_second_writer_into_a_locked_directory_is_one_line_naming_the_holder(tmp_path: Path) -> None:
    run = tmp_path / "run"
    with job_lock(run):
        line = one_error_line(run_job(run, *BASE))
    assert line.startswith(f"graspexp: error: {run} is in use by another run (pid {os.getpid()} on ")
    assert not (run / "trials").exists()


@pytest.mark.slow
def test_unwritable_output_folder_is_one_line(tmp_path: Path) -> None:
    blocker = tmp_path / "file"
    blocker.write_text("")
    line = one_error_line(run_job(blocker / "run", *BASE))
    assert (
        line
        == f"graspexp: error: cannot write the output directory {blocker / 'run'}: {blocker} is not a directory"
    )
    run = tmp_path / "run"
    run.mkdir()
    (run / "trials").write_text("")  # the trials folder cannot be made
    line = one_error_line(run_job(run, *BASE))
    assert (
        line
        == f"graspexp: error: cannot write the trial log {run / 'trials' / 'can' / '000.mcap'}: Not a directory"
    )


def test_summary_average_counts_objects_without_failures_as_zero() -> None:
    rows = [("mug", i, False, "slipped") for i in range(3)] + [
        (obj, i, True, "") for obj in ("can", "banana") for i in range(3)
    ]
    df = pd.DataFrame(rows, columns=["object", "trial", "success", "reason"])
    table = summarize(df)
    assert table.loc["mug", "slipped"] == 3 and table.loc["can", "slipped"] == 0
    assert table.loc["Average", "slipped"] == pytest.approx(1.0)
    assert table.loc["Average", "success_%"] == pytest.approx(200 / 3)


def test_the_job_config_is_frozen_once_validated(tmp_path: Path) -> None:
    cfg = compose_cfg("dataset=ycb", f"dataset.root={tmp_path / 'no-data'}")
    with pytest.raises(DatasetError):  # stops at the first object, after validation
        run_in_dir(cfg, tmp_path / "run")
    with pytest.raises(ReadonlyConfigError):
        cfg.trials = 3
