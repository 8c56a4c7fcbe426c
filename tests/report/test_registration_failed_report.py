"""Issue 51, finding 1: the report counts ``registration_failed`` trials apart from grasp failures: a column of
its own in the failure breakdown (as ``not_at_rest``), a failure of the registered-pose column (never of the
exact pose's, though no pose error was recorded) and in no ADD-S bin; a log written before the reason existed
that planned on a fit to nothing (fitness 0) reads back as one."""

import math

import pandas as pd

from graspexp.core.outcome import FailureReason, TrialResult
from graspexp.report.camera import setting_table
from graspexp.report.collect import collect
from graspexp.report.pose_error import success_by_pose_error
from graspexp.report.tables import failure_breakdown

FAILED = FailureReason.REGISTRATION_FAILED.value


def _rows(n_failed: int) -> pd.DataFrame:
    """10 optimal trials of the mug (bin z) with the registered pose, no pose noise, ``n_failed`` of them
    ``registration_failed``, the others held at an ADD-S of 1 mm; and 10 with the exact pose, all held."""
    rows = []
    for trial in range(10):
        failed = trial < n_failed
        rows.append(
            {"dataset": "ycb", "mode": "bin", "rot": "z", "object": "025_mug", "planner": "optimal", "trial": trial,
             "success": not failed, "reason": FAILED if failed else None, "trans_mm": 0.0, "rot_deg": 0.0,
             "pose_adds_mm": math.nan if failed else 1.0, "pose_trans_err_mm": math.nan if failed else 1.0,
             "pose_rot_err_deg": math.nan if failed else 1.0}
        )  # fmt: skip
        rows.append(
            {**rows[-1], "trial": 10 + trial, "success": True, "reason": None, "pose_adds_mm": math.nan}
        )
    return pd.DataFrame(rows)


def test_registration_failed_is_a_column_of_its_own_and_fails_the_registered_column():
    df = _rows(3)
    counts = failure_breakdown(df).iloc[0]
    assert counts[FAILED] == 3 and counts["no_contact"] == 0 and counts["not_at_rest"] == 0
    table = setting_table(df, "bin", "z").set_index("object")
    assert (
        table.loc["Mug", "optimal, registered pose"] == "70"
        and table.loc["Mug", "optimal, exact pose"] == "100"
    )
    bins = success_by_pose_error(df)
    assert list(bins["trials"]) == [7] and list(bins["success %"]) == [
        100.0
    ]  # not "registered, ADD-S 0-2 mm"


def test_a_log_from_before_the_reason_that_fitted_nothing_reads_as_registration_failed(tmp_path):
    """A ``record=false`` table (results.csv) of a depth run from before ``registration_failed``: the trial
    whose registration had fitness 0 (the camera saw nothing: the prior planned on) counts as one."""
    run = tmp_path / "run"
    run.mkdir()
    base = TrialResult("ycb", "025_mug", "collab", "z", "optimal", 0, 1, True, None)
    old = [
        {**base.to_dict(), "registration_fitness": 0.0, "pose_adds_mm": 0.0},
        {**base.to_dict(), "trial": 1, "registration_fitness": 0.8, "pose_adds_mm": 1.5},
    ]
    for row in old:
        row.pop("detail")  # a table written before the field existed
    pd.DataFrame(old).to_csv(run / "results.csv", index=False)
    res = collect(run).results.set_index("trial")
    assert (
        res.loc[0, "reason"] == FAILED
        and not res.loc[0, "success"]
        and math.isnan(res.loc[0, "pose_adds_mm"])
    )
    assert res.loc[1, "success"] and res.loc[1, "pose_adds_mm"] == 1.5
