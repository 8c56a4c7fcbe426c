"""The clutter table (``report`` on a ``mode=pile``/``packed`` run): GSR over executed attempts, DR over the
objects placed, both with Wilson intervals, the rounds' ends, the failure reasons and the planning latency."""

import dataclasses

import pytest

from graspexp.core.rounds import AttemptResult, RoundResult
from graspexp.report.round_tables import attempts_frame, clutter_markdown, clutter_table, rounds_frame
from graspexp.report.stats import wilson_interval


def _attempt(r, i, success, reason=None, executed=True, plan_cpu_s=0.004):
    return AttemptResult(
        round=r, attempt=i, target="can", slot=i, executed=executed, success=success, reason=reason,
        pick_order="lowest_cost", n_left=3 - i, n_planned=3 - i, plan_s=2 * plan_cpu_s, plan_cpu_s=plan_cpu_s,
    )  # fmt: skip


def _rounds():
    cleared = RoundResult(
        "ycb", "pile", "optimal", 0, 1, ["a", "b", "c"], ["object_0", "object_1", "object_2"],
        ["object_0", "object_1", "object_2"], "cleared",
        [_attempt(0, 0, True), _attempt(0, 1, False, "dropped"), _attempt(0, 2, True), _attempt(0, 3, True)],
    )  # fmt: skip
    stuck = RoundResult(
        "ycb", "pile", "optimal", 1, 2, ["a", "b", "c"], ["object_0", "object_1"], ["object_0"], "no_grasp",
        [_attempt(1, 0, True), _attempt(1, 1, False, "no_feasible_grasp", executed=False)],
    )  # fmt: skip
    return [cleared, stuck]


def test_gsr_counts_executed_attempts_and_dr_the_objects_placed():
    (row,) = clutter_table(_rounds()).to_dict("records")
    assert row["attempts"] == 5 and row["GSR_%"] == pytest.approx(80.0)
    assert (row["removed"], row["placed"]) == (4, 5) and row["DR_%"] == pytest.approx(80.0)
    lo, hi = wilson_interval(4, 5)
    assert (row["DR_lo"], row["DR_hi"]) == pytest.approx((100 * lo, 100 * hi))
    assert row["attempts/round"] == pytest.approx(2.5)
    assert (row["end_cleared"], row["end_no_grasp"], row["end_failure_limit"]) == (1, 1, 0)
    assert (row["fail_dropped"], row["fail_no_feasible_grasp"]) == (1, 1)
    assert row["plan_cpu_p50_ms"] == pytest.approx(4.0)


def test_the_tables_have_one_row_per_round_and_per_attempt():
    rounds = _rounds()
    assert len(rounds_frame(rounds)) == 2 and len(attempts_frame(rounds)) == 6
    text = clutter_markdown(rounds)
    assert "| optimal | pile | ycb | 2 | 80.0 [" in text and "dropped 1" in text


@pytest.mark.slow
def test_every_failed_attempt_of_a_logged_round_gets_a_picture_strip(tmp_path):
    """A logged pile round whose grasps close on air: each failed attempt is drawn from the round log (the
    one that found no grasp once), listed with its log; the report links the strips."""
    from helpers.config import compose_cfg

    from graspexp.record import read_round
    from graspexp.report.build import build_report, write_report
    from graspexp.report.clutter_strips import write_clutter_strips
    from graspexp.run.runner import run_in_dir

    cfg = compose_cfg(
        "mode=pile", "dataset=primitives", "objects=[can,box]", "mode.objects_per_round=2", "trials=1",
        "progress=false", "planner=random",
    )  # fmt: skip
    run_in_dir(cfg, tmp_path / "run")
    attempts = read_round(tmp_path / "run" / "trials" / "pile" / "000.mcap")["attempts"]
    failed = [a for a in attempts if not a["success"]]
    assert failed, "the random planner's round should fail at least once"
    text = write_clutter_strips(tmp_path / "run", tmp_path / "out")
    pngs = sorted((tmp_path / "out" / "clutter_failures").glob("*.png"))
    assert len(pngs) == len(failed) and text == (tmp_path / "out" / "clutter_failures.md").read_text()
    for a in failed:
        name = f"primitives_random_pile_r000_a{a['attempt']}_{a['reason']}"
        assert f"![{name}](clutter_failures/{name}.png)" in text
    assert "000.mcap`" in text
    report = write_report(build_report(tmp_path / "run", progress=False), tmp_path / "report")
    assert "[clutter_failures.md](clutter_failures.md)" in report
    assert write_clutter_strips(tmp_path / "empty", tmp_path / "none") == ""  # no round log: nothing drawn


def test_exact_and_registered_rounds_side_by_side_for_the_planners_both_ran():
    from graspexp.report.round_tables import side_by_side_markdown

    exact = _rounds()
    registered = [dataclasses.replace(r, attempts=r.attempts[:1]) for r in _rounds()[:1]]  # round 0 only
    other = [dataclasses.replace(r, planner="antipodal") for r in _rounds()]  # only with exact poses
    text = side_by_side_markdown(exact + other, registered)
    rows = [line for line in text.splitlines() if line.startswith("| optimal ")]
    assert len(rows) == 1 and "| 1 |" in rows[0] and "antipodal" not in text  # the rounds both ran
    gsr_exact = wilson_interval(3, 4)  # round 0 with exact poses: 3 of its 4 executed attempts held
    assert f"{100 * 3 / 4:.1f} [{100 * gsr_exact[0]:.1f}, {100 * gsr_exact[1]:.1f}]" in rows[0]
    assert side_by_side_markdown(exact, other).startswith("no planner and scene")
