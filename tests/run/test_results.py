"""``python -m graspexp results``: the page registry, the generated block, the fingerprint, and the
staleness check, which fails when a planner's code changes and passes otherwise."""

import dataclasses
import subprocess
import sys
import textwrap
from pathlib import Path

import pandas as pd
import pytest

from graspexp.config.compose import compose_validated
from graspexp.core.outcome import TrialResult
from graspexp.core.rounds import AttemptResult
from graspexp.datasets import select_objects
from graspexp.report.pages import (
    ATTEMPT_COLUMNS,
    ATTEMPT_KEYS,
    BEGIN,
    END,
    OUTCOME_COLUMNS,
    OUTCOME_KEYS,
    PageError,
    Stamp,
    add_stamp,
    outcome_fingerprint,
    read_stamp,
    read_stamps,
    replace_block,
    stamp,
)
from graspexp.run.provenance import cpu_class
from graspexp.run.result_pages import pages
from graspexp.run.results import check, commit_of, fingerprint_jobs, merged, regenerate
from graspexp.tools.results import main as results_main

ROOT = Path(__file__).resolve().parents[2]
PAGES = pages()
"""The results pages of the planners installed here."""

FAKE_PAGE = """
from graspexp.run.results import Page, Sweep
from graspexp.run.suites import Reading

PAGE = Page(
    "fake",
    "page.md",
    (),
    lambda page: "the tables\\n",
    (Sweep(Reading("mug", ("planner=optimal",), "the paper's planner on the mug")),),
    ("dataset=primitives", "objects=[mug]", "trials=1"),
)
"""
"""A page with no sweep and one fingerprint sweep (2 trials on a procedural mug, no data needed)."""


def _results(**changes) -> pd.DataFrame:
    row = {
        "dataset": "ycb",
        "object": "025_mug",
        "mode": "bin",
        "rot": "z",
        "planner": "optimal",
        "trial": "0",
    }
    row |= {"success": "True", "grasp_cost": "1.25", "timings_s": "{'plan': 0.1}"}
    return pd.DataFrame([row | changes])


def test_a_fingerprint_hashes_outcomes_not_timings_nor_new_columns():
    base = outcome_fingerprint([_results()])
    assert outcome_fingerprint([_results(timings_s="{'plan': 0.2}")]) == base
    assert outcome_fingerprint([_results(new_field="x")]) == base
    assert outcome_fingerprint([_results(grasp_cost="1.2500000001")]) != base
    assert outcome_fingerprint([_results(success="False")]) != base
    assert outcome_fingerprint([_results(registration_cpu_s="0.02")]) == base
    assert outcome_fingerprint([_results(pose_adds_mm="3.5")]) != base
    two = [_results(), _results(trial="1")]
    assert outcome_fingerprint(two) == outcome_fingerprint(two[::-1])


def test_every_fingerprinted_column_is_a_result_field():
    fields = set(TrialResult.__dataclass_fields__)
    assert set(OUTCOME_KEYS + OUTCOME_COLUMNS) <= fields


def test_the_block_is_replaced_and_its_stamp_read_back(tmp_path: Path):
    text = f"# Page\n\nBefore.\n\n{BEGIN}\nold\n{END}\n\nAfter.\n"
    s = Stamp("index", "0123abcd0123abcd", "abc1234")
    new = replace_block(text, stamp(s) + "\nnew table\n", "page.md")
    assert new.startswith("# Page\n\nBefore.\n\n") and new.endswith(f"{END}\n\nAfter.\n")
    assert "old" not in new and "new table" in new
    assert read_stamp(new) == s and read_stamp(text) is None
    with pytest.raises(PageError, match="page.md has no generated block"):
        replace_block("# no markers\n", "x", "page.md")


def test_overrides_merge_last_wins_and_pages_are_well_formed():
    assert merged(["trials=5", "record=false"], ["trials=1", "+x=2"]) == ("trials=1", "record=false", "+x=2")
    assert len({p.name for p in PAGES}) == len(PAGES)
    for page in PAGES:
        text = (ROOT / page.path).read_text()
        assert BEGIN in text and END in text, page.path
        jobs = fingerprint_jobs(page)
        assert jobs and all("record=false" in j for j in jobs), page.name
    names = {}
    for page in PAGES:
        for s in page.sweeps:
            assert names.setdefault(s.name, s) == s, f"two sweeps named {s.name}"


@pytest.mark.slow
def test_every_fingerprint_job_composes_and_names_its_objects():
    """Validated (so only the pages whose planners can run here: :func:`available`)."""
    from graspexp.run.results import available

    jobs = {tuple(sorted(j)): j for page in available(PAGES) for j in fingerprint_jobs(page)}
    for job in jobs.values():
        cfg = compose_validated(list(job))
        assert select_objects(cfg.dataset, cfg.objects), job


def test_an_unknown_page_is_refused_with_one_line(capsys):
    with pytest.raises(SystemExit) as exc:
        results_main(["--check", "--pages", "nope"])
    assert exc.value.code == 2
    assert "unknown page(s) ['nope']; the pages are readme, index" in capsys.readouterr().err


@pytest.mark.slow
def test_check_passes_on_the_same_code_and_fails_when_a_planner_changes(tmp_path: Path):
    (tmp_path / "fake_page.py").write_text(FAKE_PAGE)
    sys.path.insert(0, str(tmp_path))
    try:
        from fake_page import PAGE as page
    finally:
        sys.path.remove(str(tmp_path))
    (tmp_path / "page.md").write_text(f"# Fake\n\n{BEGIN}\n{END}\n")
    assert regenerate([page], tmp_path, tmp_path / "out", [], "python -m graspexp results", 1) == []
    text = (tmp_path / "page.md").read_text()
    assert "the tables" in text and "2 fixed trials" in text and "2 jobs" in text
    assert read_stamp(text).cpu == cpu_class() and f"CPU class it was taken on, {cpu_class()}" in text
    assert check([page], tmp_path, 1) == []
    script = textwrap.dedent(
        f"""
        import sys
        from pathlib import Path

        import graspexp.planning.optimal as optimal
        from graspexp.run.results import check

        original = optimal.path_costs
        optimal.path_costs = lambda *a: original(*a) * 1.01  # a planner constant changed
        sys.path.insert(0, {str(tmp_path)!r})
        from fake_page import PAGE

        problems = check([PAGE], Path({str(tmp_path)!r}), 1)
        print("\\n".join(problems))
        sys.exit(1 if problems else 0)
        """
    )
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True)
    assert done.returncode == 1, done.stderr[-2000:]
    assert "page.md: made at commit" in done.stdout and "the current code gives" in done.stdout
    assert "python -m graspexp results --pages fake" in done.stdout


def test_a_sweep_marked_done_is_skipped_and_the_launcher_is_an_override(tmp_path: Path, capsys):
    from graspexp.run.results import DONE_NAME, Sweep, run_sweep
    from graspexp.run.suites import ALL, reading_sweep

    sweep = Sweep(ALL["default"], ("trials=3",))
    (tmp_path / sweep.name).mkdir()
    (tmp_path / sweep.name / DONE_NAME).write_text(
        '{"command": "c", "rc": 0, "wall_s": 90.0, "cpu_s": 170.0}'
    )
    done = run_sweep(sweep, tmp_path, [], "[1/1]")
    assert done.skipped and (done.wall_s, done.cpu_s) == (90.0, 170.0)
    assert f"[1/1] {sweep.name}: done before (90 s), skipped" in capsys.readouterr().err
    slurm = reading_sweep(
        ALL["default"], tmp_path, ["hydra/launcher=submitit_slurm", "hydra.launcher.partition=p"]
    )
    assert "hydra/launcher=joblib" not in slurm and "hydra/launcher=submitit_slurm" in slurm
    assert "hydra/launcher=joblib" in reading_sweep(ALL["default"], tmp_path)


def test_a_tuning_page_scores_the_best_trial_or_the_farthest_tie():
    import optuna

    from graspexp.report.tuning import scored_trial

    optuna.logging.set_verbosity(optuna.logging.WARNING)

    def study(values: list[tuple[float, float]]) -> optuna.Study:
        s = optuna.create_study(direction="maximize")
        dist = {"x": optuna.distributions.LogUniformDistribution(0.01, 100)}
        for x, v in values:
            s.add_trial(optuna.trial.create_trial(params={"x": x}, distributions=dist, value=v))
        return s

    assert scored_trial(study([(1.0, 0.9), (2.0, 0.95), (50.0, 0.9)])) is None  # trial 1 beat the baseline
    assert scored_trial(study([(1.0, 0.9), (2.0, 0.9), (0.05, 0.9), (30.0, 0.8)])) == 2  # 20x, tied
    assert scored_trial(study([(1.0, 0.9), (3.0, 0.8)])) is None  # no tie: the best is trial 0 itself


@pytest.mark.parametrize("name", ["camera", "learned"])
def test_the_camera_and_learned_pages_fingerprint_jobs_compose(name):
    """The fingerprint jobs of the pages made from camera trials compose (without validation: planner=vgn
    needs the optional extra ``learned``, which a page whose planners cannot run here is skipped for) and
    name Table 1 objects; each is a few single-trial jobs."""
    from graspexp.config.compose import compose_config
    from graspexp.report.paper import TABLE1

    page = next(p for p in PAGES if p.name == name)
    jobs = fingerprint_jobs(page)
    assert 0 < len(jobs) <= 12
    cfgs = {job: compose_config(list(job)) for job in jobs}
    for job, cfg in cfgs.items():
        assert cfg.record is False and int(cfg.trials) == 1, job
        assert set(cfg.objects) <= set(TABLE1.labels) and cfg.dataset.name == "ycb", job
    planners = {cfg.planner.name for cfg in cfgs.values()}
    assert "vgn" in planners and (name == "learned" or {"optimal", "antipodal_view"} <= planners)


def test_the_camera_clutter_pages_fingerprint_is_one_round_per_planner_and_scene_with_the_camera():
    """The camera clutter page's fingerprint: one round of each of its planners in pile and packed, every
    pose registered from the camera, vgn on the Panda it was trained for."""
    from graspexp.config.compose import compose_config
    from graspexp.config.plugins import learned_planners

    page = next(p for p in PAGES if p.name == "clutter_camera")
    jobs = [compose_config(list(job)) for job in fingerprint_jobs(page)]
    runs = {(cfg.planner.name, cfg.mode.name) for cfg in jobs}
    planners = {"optimal", "optimal_plus", "antipodal_view", *learned_planners()}
    assert len(jobs) == 2 * len(planners) and runs == {(p, m) for p in planners for m in ("pile", "packed")}
    for cfg in jobs:
        assert int(cfg.trials) == 1 and cfg.record is False and cfg.dataset.name == "ycb"
        assert cfg.perception.source == "depth" and cfg.perception.noise.trans_mm == 10
        trained = learned_planners().get(cfg.planner.name)
        assert cfg.gripper.name == (trained.gripper if trained else "rg2")


def test_a_page_whose_planner_cannot_run_here_is_skipped_with_one_line(monkeypatch, capsys):
    """Without the optional extra (planner=vgn unavailable) the camera and learned pages are skipped by
    ``results`` and ``results --check`` with one line naming the install command."""
    from graspexp.config.planner import vgn
    from graspexp.run.results import available

    monkeypatch.setattr(vgn, "find_spec", lambda module: None)  # neither torch nor open3d installed
    kept = available(PAGES)
    assert {p.name for p in PAGES} - {p.name for p in kept} == {"camera", "learned", "clutter_camera"}
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 3 and all(
        f"cannot run here: it needs torch and open3d, the optional extra 'learned': {vgn.INSTALL}" in line
        for line in err
    )
    assert err[0].startswith("graspexp results: page camera (docs/results/camera.md) skipped: planner=")


def test_every_results_page_is_generated_but_the_labelled_experiments():
    """Every page under docs/results/ is a :func:`pages` entry (``python -m graspexp results`` rewrites
    it), but the experiments page (before/after studies, each naming its commits)."""
    pages = {str(p.relative_to(ROOT)) for p in (ROOT / "docs" / "results").rglob("*.md")}
    assert pages - {p.path for p in PAGES} == {"docs/results/experiments.md"}


def test_a_changed_page_is_not_a_code_change_but_a_changed_module_is(tmp_path: Path):
    def git(*args: str) -> None:
        subprocess.run(["git", "-c", "user.name=t", "-c", "user.email=t@t", *args], cwd=tmp_path, check=True)

    (tmp_path / "docs").mkdir()
    for name in ("README.md", "docs/page.md", "module.py"):
        (tmp_path / name).write_text("a\n")
    git("init", "-q")
    git("add", ".")
    git("commit", "-q", "-m", "first")
    (tmp_path / "README.md").write_text("b\n")
    (tmp_path / "docs" / "page.md").write_text("b\n")
    assert not commit_of(tmp_path)[0].endswith("+changes")
    (tmp_path / "module.py").write_text("b\n")
    assert commit_of(tmp_path)[0].endswith("+changes")


def test_a_clutter_fingerprint_hashes_attempt_outcomes_not_their_times():
    def attempts(**changes: str) -> pd.DataFrame:
        row = {k: "0" for k in (*ATTEMPT_KEYS, *ATTEMPT_COLUMNS)} | {"success": "True", "plan_s": "0.1"}
        return pd.DataFrame([row | changes])

    base = outcome_fingerprint([attempts()])
    assert outcome_fingerprint([attempts(plan_s="0.2", plan_cpu_s="0.3", execute_s="1")]) == base
    assert outcome_fingerprint([attempts(success="False")]) != base
    assert outcome_fingerprint([attempts(moved_neighbours="object_1")]) != base
    with pytest.raises(ValueError, match="not both"):
        outcome_fingerprint([attempts(), _results()])
    assert set(ATTEMPT_KEYS + ATTEMPT_COLUMNS) <= set(AttemptResult.__dataclass_fields__) | {
        "dataset",
        "mode",
        "planner",
    }


def test_a_fingerprint_is_checked_on_its_own_cpu_class_and_stamped_for_another(tmp_path, monkeypatch, capsys):
    """The last digits of a trial depend on the CPU's instruction set: a page stamped on another class only
    is skipped by ``--check`` with a line, ``--stamp-cpu`` adds this class's fingerprint (replacing an older
    one of the class), and a stamp without a class (made before classes were recorded) is checked anywhere."""
    from graspexp.run import results

    page = dataclasses.replace(next(p for p in PAGES if p.name == "index"), path="page.md")
    gives = {"fp": "1111"}
    monkeypatch.setattr(results, "run_fingerprints", lambda pages, *a: {p.name: gives["fp"] for p in pages})
    monkeypatch.setattr(results, "cpu_class", lambda: "x86_64-v4")
    path = tmp_path / "page.md"
    made = Stamp("index", "0000", "abc1234", "x86_64-v3")
    path.write_text(f"# P\n\n{BEGIN}\n{stamp(made)}\n\ntables\n{END}\n")
    assert results.check([page], tmp_path, 1) == []
    assert (
        "fingerprints of x86_64-v3 only, not checkable on this machine (x86_64-v4)" in capsys.readouterr().err
    )
    assert results.stamp_cpu([page], tmp_path, 1) == []
    assert [(s.cpu, s.fingerprint) for s in read_stamps(path.read_text())] == [
        ("x86_64-v3", "0000"),
        ("x86_64-v4", "1111"),
    ]
    assert results.check([page], tmp_path, 1) == []
    gives["fp"] = "2222"  # the code changed
    (problem,) = results.check([page], tmp_path, 1)
    assert "fingerprint 1111, x86_64-v4" in problem and "gives 2222" in problem
    assert results.stamp_cpu([page], tmp_path, 1) == []
    assert [s.fingerprint for s in read_stamps(path.read_text())] == ["0000", "2222"]
    path.write_text(f"# P\n\n{BEGIN}\n{stamp(Stamp('index', '0000', 'abc1234'))}\n\ntables\n{END}\n")
    assert "fingerprint 0000)" in results.check([page], tmp_path, 1)[0]  # unclassed: checked here
    path.write_text(f"# P\n\n{BEGIN}\n{stamp(Stamp('index', '2222', 'abc1234', 'x86_64-v4'))}\n{END}\n")
    assert results.stamp_cpu([page], tmp_path, 1) == [] and len(read_stamps(path.read_text())) == 1
    with pytest.raises(PageError, match="made on x86_64-v4; regenerate it instead"):
        add_stamp(path.read_text(), Stamp("index", "3333", "def", "x86_64-v4"), "page.md")
