"""The learned planners' tables (per setting with Wilson intervals beside the paper's printed averages, per
object, failures by reason) and the camera page's pooled table, on synthetic trials."""

import pandas as pd

from graspexp.report.camera import learned_columns, pooled_table
from graspexp.report.learned import failure_counts, object_rates, setting_rates


def _trials(planner: str, held: int, reason: str) -> pd.DataFrame:
    """10 trials of the mug per setting, the first ``held`` held, the rest failed with ``reason``; one
    LINEMOD trial (not Table 1: left out)."""
    rows = [
        {"dataset": "ycb", "object": "025_mug", "mode": mode, "rot": rot, "planner": planner, "trial": t,
         "success": t < held, "reason": "" if t < held else reason, "trans_mm": 0.0, "rot_deg": 0.0}
        for mode in ("collab", "bin") for rot in ("z", "xyz") for t in range(10)
    ]  # fmt: skip
    rows.append(rows[0] | {"dataset": "linemod", "object": "ape", "success": False, "reason": "dropped"})
    return pd.DataFrame(rows)


def test_setting_rates_pool_table1_trials_with_wilson_intervals():
    runs = {"vgn, gripper=panda": _trials("vgn", 7, "no_feasible_grasp"), "rg2": _trials("vgn", 10, "")}
    table = setting_rates(runs).set_index("setting")
    assert table.loc["Z Collaborative", "vgn, gripper=panda"] == "70.0 [39.7, 89.2]"
    assert table.loc["Z Collaborative", "rg2"] == "100.0 [72.2, 100.0]"
    assert table.loc["all settings", "vgn, gripper=panda"] == "70.0 [54.6, 81.9] (n=40)"
    assert table.loc["Z Collaborative", "paper: GPD [18]*"] == "64.44"
    assert table.loc["XYZ Bin picking", "paper: its planner"] == "95.56"
    objects = object_rates(runs["vgn, gripper=panda"]).set_index("object")
    assert (
        objects.loc["025_mug", "Z Bin picking"] == "70" and objects.loc["011_banana", "Z Bin picking"] == "-"
    )
    failures = failure_counts(runs).set_index("reason")
    assert failures.loc["no_feasible_grasp", "vgn, gripper=panda"] == 12 and "dropped" not in failures.index


def test_the_camera_pages_pooled_table_has_the_vgn_column():
    results = pd.concat(
        [_trials("optimal", 9, "dropped"), _trials("vgn", 5, "no_contact")], ignore_index=True
    )
    pooled = pooled_table(results, (("optimal", False, "optimal, exact pose"), *learned_columns()))
    pooled = pooled.set_index("column")
    assert pooled.loc["optimal, exact pose", "trials"] == 40
    assert pooled.loc["vgn, gripper=panda, camera views", "success %"] == "50.0 (35.2-64.8)"
