"""optimal_plus's choice among its shortlisted grasps, and the study that simulates each of them."""

import numpy as np
import pandas as pd
import pytest

from graspexp.planning.optimal_plus import pick_shortlisted
from graspexp.tools.bench.shortlist import main as shortlist_main


def test_pick_shortlisted_prefers_room_by_the_finger_edges_then_cost() -> None:
    costs = np.array([1.0, 0.5, 2.0, 3.0])
    robust = np.array([True, False, True, True])
    excess = np.array([0.001, -0.004, -0.0005, -0.002])  # m; the second is not robust
    assert pick_shortlisted("cost", costs, robust, excess) == 0  # the cheapest robust path
    assert pick_shortlisted("edge_clearance", costs, robust, excess) == 2  # clear of the edges, then cheapest
    clear = np.array([-0.001, 0.0, -0.003, 0.002])
    assert pick_shortlisted("edge_clearance", costs, robust, clear) == 0  # ties at 0: the cost decides


@pytest.mark.slow
def test_shortlist_study_simulates_every_shortlisted_grasp(tmp_path, capsys) -> None:
    out = tmp_path / "shortlist.csv"
    argv = ["--out", str(out), "trials=1", "dataset=primitives", "objects=[can]"]
    assert shortlist_main([*argv, "mode=collab", "rot=z", "--n-jobs", "1"]) == 0
    df = pd.read_csv(out)
    assert len(df) == df["candidate"].max() + 1 > 1  # every shortlisted grasp of the one drop, once
    assert df["pick_edge_clearance"].sum() == 1
    assert df["pick_cost"].sum() == 1
    assert set(df["held"]) <= {True, False}
    assert "Drops whose pick is held" in capsys.readouterr().out
