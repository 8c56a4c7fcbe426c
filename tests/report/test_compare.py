"""The comparison report on hand-made trial logs: success table, Wilson bounds, same-drops check, noise."""

import math

import pandas as pd
import pytest

from graspexp.core.outcome import TrialResult
from graspexp.record import TrialRecorder
from graspexp.report.compare import check_same_drops, collect_trials, write_comparison
from graspexp.report.stats import wilson_interval
from graspexp.tools.compare import main


def _log(run_dir, planner, obj, trial, seed, success, trans_mm=0.0, rot_deg=0.0, mode="bin") -> None:
    cfg = f"planner:\n  name: {planner}\nperception:\n  noise:\n    trans_mm: {trans_mm}\n    rot_deg: {rot_deg}\n"
    path = run_dir / "trials" / obj / f"{trial:03d}.mcap"
    path.parent.mkdir(parents=True, exist_ok=True)
    res = TrialResult(
        dataset="primitives",
        object=obj,
        mode=mode,
        rot="z",
        planner=planner,
        trial=trial,
        seed=seed,
        success=success,
        reason=None if success else "slipped",
    )
    with TrialRecorder(path, {"config_yaml": cfg, "object": obj, "trial": str(trial)}) as rec:
        rec.result(1.0, res.to_dict())


def _sweep(root, successes: dict, noise=((0.0, 0.0),), seeds=lambda obj, t: 100 * len(obj) + t) -> None:
    """successes: planner -> list of bools per trial (2 objects, same list each)."""
    for trans, rot in noise:
        for planner, ok in successes.items():
            run = root / f"{planner}_{trans}_{rot}"
            for obj in ("can", "mug"):
                for t, s in enumerate(ok):
                    _log(run, planner, obj, t, seeds(obj, t), s, trans, rot)


def test_table_counts_and_wilson_bounds(tmp_path) -> None:
    _sweep(tmp_path, {"optimal": [True, False, False, True, False], "antipodal": [True] * 5})
    md, table, drops = write_comparison(tmp_path, tmp_path / "out")
    assert drops == []
    row = table.set_index("planner").loc["optimal"]
    assert (row.n, row.successes, row.success_pct) == (10, 4, 40.0)
    lo, hi = wilson_interval(4, 10)
    assert row.ci_lo_pct == pytest.approx(100 * lo) and row.ci_hi_pct == pytest.approx(100 * hi)
    assert table.set_index("planner").loc["antipodal"].success_pct == 100.0
    assert "Same drops: every planner ran the same" in md
    assert f"40 [{100 * lo:.0f}, {100 * hi:.0f}] (10)" in md
    for name in ("compare.md", "compare.csv", "success_vs_noise.png"):
        assert (tmp_path / "out" / name).stat().st_size > 0
    assert len(pd.read_csv(tmp_path / "out" / "compare.csv")) == 2


def test_different_drops_are_reported(tmp_path) -> None:
    _sweep(tmp_path, {"optimal": [True, False]})
    _sweep(
        tmp_path,
        {"random": [True, False]},
        seeds=lambda obj, t: 7 if (obj, t) == ("mug", 1) else 100 * len(obj) + t,
    )
    df, _ = collect_trials(tmp_path)
    drops = check_same_drops(df)
    assert len(drops) == 1 and "object=mug" in drops[0]
    md, _, _ = write_comparison(tmp_path, tmp_path / "out")
    assert "did not all run on the same drops" in md


def test_noise_levels_come_from_the_config_and_split_the_table(tmp_path) -> None:
    _sweep(
        tmp_path, {"optimal": [True, True], "obb": [False, True]}, noise=((0.0, 0.0), (10.0, 0.0), (0.0, 5.0))
    )
    df, warnings = collect_trials(tmp_path)
    assert warnings == []
    assert sorted(set(zip(df.trans_mm, df.rot_deg, strict=True))) == [(0.0, 0.0), (0.0, 5.0), (10.0, 0.0)]
    _, table, _ = write_comparison(tmp_path, tmp_path / "out")
    assert len(table) == 6 and set(table.n) == {4}


def test_unreadable_and_duplicate_logs_are_warned_not_counted(tmp_path) -> None:
    _sweep(tmp_path, {"optimal": [True]})
    _log(tmp_path / "again", "optimal", "can", 0, 300, False)  # the same trial logged twice
    (tmp_path / "optimal_0.0_0.0" / "trials" / "can" / "001.mcap").write_bytes(b"not an mcap")
    df, warnings = collect_trials(tmp_path)
    assert len(df) == 2  # can #0 once (the first path in sorted order: again/...) and mug #0
    assert sorted(df.object) == ["can", "mug"]
    dup = [w for w in warnings if w.startswith("duplicate trial ignored")]
    assert len(dup) == 1 and "optimal_0.0_0.0/trials/can/000.mcap" in dup[0]
    assert any(w.startswith("unreadable log skipped") and "001.mcap" in w for w in warnings)


def test_cli_prints_markdown_and_fails_on_an_empty_dir(tmp_path, capsys) -> None:
    _sweep(tmp_path / "runs", {"optimal": [True, False]})
    assert main([str(tmp_path / "runs"), "--out", str(tmp_path / "o")]) == 0
    assert "| primitives | bin | z | 0 | 0 | 50 [" in capsys.readouterr().out
    (tmp_path / "empty").mkdir()
    assert main([str(tmp_path / "empty")]) == 2
    assert not math.isnan(wilson_interval(1, 2)[0])


def test_quality_table_splits_success_by_force_closure():
    import pandas as pd

    from graspexp.report.compare import quality_table

    base = {
        "dataset": "primitives",
        "mode": "bin",
        "rot": "z",
        "trans_mm": 0.0,
        "rot_deg": 0.0,
        "planner": "p",
    }
    rows = [
        {**base, "reason": None, "success": True, "fc_min_mu": 0.2},
        {**base, "reason": "slipped", "success": False, "fc_min_mu": 0.4},
        {**base, "reason": "dropped", "success": False, "fc_min_mu": float("nan")},
        {**base, "reason": "no_feasible_grasp", "success": False, "fc_min_mu": float("nan")},
    ]
    (q,) = quality_table(pd.DataFrame(rows)).to_dict("records")
    assert q["planned"] == 3
    assert q["fc_pct"] == pytest.approx(200 / 3)
    assert q["median_mu"] == pytest.approx(0.3)
    assert q["success_if_fc_pct"] == 50.0 and q["success_if_not_fc_pct"] == 0.0
