"""The report's success-against-pose-error table: trials binned by ADD-S, per planner, Wilson intervals."""

import math

import pandas as pd

from graspexp.report.pose_error import success_by_pose_error


def test_bins_and_rates():
    df = pd.DataFrame(
        {
            "planner": ["optimal"] * 4 + ["antipodal"],
            "success": [True, False, True, True, True],
            "pose_adds_mm": [1.0, 3.0, 4.0, 25.0, math.nan],
            "pose_trans_err_mm": [1.0, 2.0, 4.0, 30.0, math.nan],
            "pose_rot_err_deg": [1.0, 2.0, 3.0, 40.0, math.nan],
        }
    )
    table = success_by_pose_error(df)
    assert list(table["ADD-S mm"]) == ["0-2", "2-5", ">= 20"]  # no registered pose: not in the table
    assert list(table["trials"]) == [1, 2, 1] and list(table["success %"]) == [100.0, 50.0, 100.0]
    row = table.iloc[1]
    assert 0 < row["lo %"] < 50 < row["hi %"] < 100 and row["trans mm (median)"] == 3.0


def test_truth_runs_have_no_table():
    assert success_by_pose_error(pd.DataFrame({"planner": ["optimal"], "success": [True]})).empty


def test_camera_table_columns_split_by_registered_pose():
    from graspexp.report.camera import setting_table

    rows = []
    for planner, adds in (("optimal", math.nan), ("optimal", 2.0), ("antipodal_view", math.nan)):
        for trial in range(10):
            rows.append(
                {"mode": "bin", "rot": "z", "object": "025_mug", "planner": planner, "trial": trial,
                 "success": trial < (9 if math.isnan(adds) else 7), "pose_adds_mm": adds}
            )  # fmt: skip
    table = setting_table(pd.DataFrame(rows), "bin", "z").set_index("object")
    assert (
        table.loc["Mug", "optimal, exact pose"] == "90"
        and table.loc["Mug", "optimal, registered pose"] == "70"
    )
    assert (
        table.loc["Mug", "antipodal_view, camera cloud"] == "90" and table.loc["Mug", "paper: ours"] == "80"
    )
    assert table.loc["Average", "optimal, registered pose"].endswith("n=10")
    assert table.loc["Cleanser B.", "antipodal, full model"] == "-"
