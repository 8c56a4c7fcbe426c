"""Optuna studies (``hydra/sweeper=study``) and ``python -m graspexp tune`` on the offline primitives
(the default dataset).

The real CLI runs in a subprocess: a 3-trial study whose returned objectives must equal the mean
success of each job's results.csv, its resume, a job that cannot run (a FAIL trial, the study goes on),
and the held-out scoring with its report.
"""

import subprocess
from pathlib import Path

import pandas as pd
import pytest
import yaml
from helpers.cli import graspexp

from graspexp.config.compose import expand_sweeps
from graspexp.config.job import OBJECTIVES
from graspexp.report.study import read_sweep_study
from graspexp.report.tuning import OBJECTIVE_WORDS

REPO = Path(__file__).resolve().parents[2]
STUDY = [
    "hydra/sweeper=study",
    "mode=bin",
    "objects=[can,box]",
    "trials=2",
    "record=false",
    "progress=false",
    "cost.angle_weight=tag(log, interval(0.01, 1))",
    "cost.table_offset=interval(0.01, 0.5)",
]


def _graspexp(*args: str, ok: bool = True) -> subprocess.CompletedProcess:
    proc = graspexp(*args, timeout=180)
    if ok:
        assert proc.returncode == 0, proc.stderr[-3000:]
    return proc


def _job_results(sweep_dir: Path) -> dict[tuple[float, float], pd.DataFrame]:
    """(angle_weight, table_offset) of each job directory -> its results.csv."""
    out = {}
    for job in sweep_dir.glob("*/.hydra/overrides.yaml"):
        values = dict(o.split("=", 1) for o in yaml.safe_load(job.read_text()))
        key = (float(values["cost.angle_weight"]), float(values["cost.table_offset"]))
        out[key] = pd.read_csv(job.parent.parent / "results.csv")
    return out


@pytest.fixture(scope="module")
def study_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("study") / "sweep"
    _graspexp("-m", *STUDY, "hydra.sweeper.n_trials=3", f"hydra.sweep.dir={out}")
    return out


@pytest.mark.slow
def test_study_objective_is_each_jobs_mean_success(study_dir: Path) -> None:
    study = read_sweep_study(study_dir).study
    trials = study.get_trials()
    assert [t.state.name for t in trials] == ["COMPLETE"] * 3
    assert trials[0].params == {"cost.angle_weight": 0.1, "cost.table_offset": 0.05}  # the paper's first
    jobs = _job_results(study_dir)
    for t in trials:
        df = jobs[(t.params["cost.angle_weight"], t.params["cost.table_offset"])]
        assert len(df) == 4
        assert t.value == pytest.approx(df["success"].mean())  # equal trials per object: = mean over objects
    history = pd.read_csv(study_dir / "optuna_trials.csv")
    assert list(history["number"]) == [0, 1, 2]
    assert (study_dir / "study_params.png").stat().st_size > 0
    assert (study_dir / "study_history.png").stat().st_size > 0


@pytest.mark.slow
def test_study_resumes_to_n_trials_in_all(study_dir: Path) -> None:
    before = {t.params["cost.angle_weight"] for t in read_sweep_study(study_dir).study.get_trials()}
    _graspexp("-m", *STUDY, "hydra.sweeper.n_trials=4", f"hydra.sweep.dir={study_dir}")
    trials = read_sweep_study(study_dir).study.get_trials()
    assert len(trials) == 4
    assert trials[3].params["cost.angle_weight"] not in before  # the sampler does not repeat the first run
    _graspexp("-m", *STUDY, "hydra.sweeper.n_trials=4", f"hydra.sweep.dir={study_dir}")  # done: runs none
    assert len(read_sweep_study(study_dir).study.get_trials()) == 4
    other = _graspexp("-m", *STUDY, "trials=3", f"hydra.sweep.dir={study_dir}", ok=False)  # another objective
    assert other.returncode == 2
    assert "holds a study of another command (trials: 2 in the study, 3 now)" in other.stderr


@pytest.mark.slow
def test_tune_scores_best_and_paper_on_the_test_split(study_dir: Path, tmp_path: Path) -> None:
    preset = tmp_path / "tuned.yaml"
    _graspexp("tune", str(study_dir), "--trials", "1", "--out", str(tmp_path), "--preset", str(preset))
    text = (tmp_path / "tuning.md").read_text()
    for obj in ("mug", "banana", "block"):  # the primitives' test split
        assert f"| {obj} |" in text
    assert "| **all objects** |" in text and "McNemar" in text
    assert set(yaml.safe_load(preset.read_text())) == {"defaults", "angle_weight", "table_offset"}
    assert len(pd.read_csv(tmp_path / "tuning_trials.csv")) >= 3


@pytest.mark.slow
def test_a_job_that_cannot_run_is_a_failed_trial_and_the_study_goes_on(tmp_path: Path) -> None:
    # dataset=ycb has no object "can": that job prints one line and returns None (the seeded sampler
    # draws ycb for trial 2, after the default primitives of trial 0)
    out = tmp_path / "sweep"
    args = [*STUDY, "dataset=choice(primitives,ycb)", "hydra.sweeper.n_trials=4", f"hydra.sweep.dir={out}"]
    proc = _graspexp("-m", *args, ok=False)
    assert proc.returncode == 1, proc.stderr[-3000:]  # the sweep summary of failed jobs
    assert "unknown object" in proc.stderr
    states = [t.state.name for t in read_sweep_study(out).study.get_trials()]
    assert states == ["COMPLETE", "COMPLETE", "FAIL", "COMPLETE"]
    assert len(pd.read_csv(out / "optuna_trials.csv")) == 4


def test_every_objective_is_described_in_the_report() -> None:
    assert set(OBJECTIVE_WORDS) == set(OBJECTIVES)


def test_sweep_precheck_expands_optuna_ranges_to_their_ends() -> None:
    combos = expand_sweeps(
        ["cost.angle_weight=tag(log, interval(0.01, 1))", "trials=range(1,3)", "mode=choice(bin,collab)"]
    )
    assert len(combos) == 2 * 2 * 2
    assert {c[0] for c in combos} == {"cost.angle_weight=0.01", "cost.angle_weight=1.0"}


def test_a_search_range_without_an_optuna_sweeper_is_one_line() -> None:
    proc = _graspexp("-m", "cost.angle_weight=interval(0.01, 1)", ok=False)
    assert proc.returncode == 2
    assert proc.stderr.strip() == (
        "graspexp: error: cost.angle_weight=interval(0.01, 1) is a search range, which only an Optuna study "
        "draws from: add hydra/sweeper=study"
    )


def test_split_and_objects_together_are_refused() -> None:
    proc = _graspexp("dataset.split=train", "objects=[can]", ok=False)
    assert proc.returncode == 2
    assert proc.stderr.strip().endswith("both choose the objects; give one of them")


@pytest.mark.parametrize(
    "override, message",
    [
        (
            "cost.table_offset=interval(0.5, 0.01)",
            "the search range's lower end 0.5 is not below its upper end 0.01",
        ),
        ("hydra.sweeper.n_trials=0", "the number of trials of a study must be a positive integer"),
    ],
)
def test_a_study_that_cannot_start_is_one_line_and_leaves_nothing(tmp_path: Path, override, message) -> None:
    out = tmp_path / "sweep"
    proc = _graspexp("-m", *STUDY, override, f"hydra.sweep.dir={out}", ok=False)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    assert proc.stderr.strip() == f"graspexp: error: {override}: {message}"
    assert not out.exists()  # no optuna.db, no lock left behind


@pytest.mark.slow
def test_a_damaged_study_database_is_one_line(tmp_path: Path) -> None:
    out = tmp_path / "sweep"
    out.mkdir()
    (out / "optuna.db").write_bytes(b"not a database" * 100)
    proc = _graspexp("-m", *STUDY, "hydra.sweeper.n_trials=1", f"hydra.sweep.dir={out}", ok=False)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr, proc.stderr[-2000:]
    (line,) = [ln for ln in proc.stderr.splitlines() if ln.startswith("graspexp: error:")]
    assert "optuna.db cannot be opened (DatabaseError" in line and "move the damaged file aside" in line
    assert not list(out.glob("*/results.csv"))  # no trial ran


@pytest.mark.slow
def test_a_study_resumed_on_another_data_root_is_refused(tmp_path: Path) -> None:
    from graspexp.report.study import write_study_record

    out = tmp_path / "sweep"
    out.mkdir()
    overrides = [o for o in STUDY if not o.startswith("hydra")] + ["hydra.sweeper.n_trials=1"]
    task = [o for o in overrides if not o.startswith("hydra")]
    write_study_record(out, f"sqlite:///{out}/optuna.db", "graspexp", task, {"data_root": "/elsewhere"})
    proc = _graspexp("-m", "hydra/sweeper=study", *overrides, f"hydra.sweep.dir={out}", ok=False)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr, proc.stderr[-2000:]
    (line,) = [ln for ln in proc.stderr.splitlines() if ln.startswith("graspexp: error:")]
    assert "holds a study made on other inputs (data_root: /elsewhere in the study" in line
    assert not list(out.glob("*/results.csv"))


def test_an_unrun_object_is_not_a_failure_in_the_tuning_report() -> None:
    from graspexp.report.tuning import _rate, paired_test

    rows = [("ape", 0, False, "error"), ("can", 0, True, None), ("can", 1, False, "dropped")]
    df = pd.DataFrame(rows, columns=["object", "trial", "success", "reason"])
    assert _rate(df[df["object"] == "ape"]) == "not run"
    assert _rate(df).endswith("(1/2)")
    assert paired_test(df, df.assign(success=True)) == (0, 1, 1.0)
