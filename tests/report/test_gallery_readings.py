"""The failure gallery and the readings table, from real trial logs of two small runs (one per reading)."""

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from helpers.cli import ok, run_job

from graspexp.record import read_trial
from graspexp.report.collect import collect
from graspexp.report.gallery import _entities_at, key_times, pick_examples, write_gallery
from graspexp.report.readings import MixedConfigError, readings_report
from graspexp.run.suites import ALL, READINGS, reading_sweep
from graspexp.tools.readings import main as readings_main

pytestmark = pytest.mark.slow
REPO = Path(__file__).resolve().parents[2]
OBJECTS = "objects=[box,block,mug]"


def _run(run_dir: Path, *overrides: str) -> None:
    ok(run_job(run_dir, "trials=2", OBJECTS, *overrides))


@pytest.fixture(scope="module")
def readings_dir(tmp_path_factory) -> Path:
    root = tmp_path_factory.mktemp("readings")
    _run(root / "default" / "run", "planner=optimal")
    _run(root / "literal" / "run", "planner=optimal_literal")
    return root


def test_literal_reading_fails_where_the_default_holds(readings_dir: Path) -> None:
    ours = collect(readings_dir / "default").results
    literal = collect(readings_dir / "literal").results
    assert len(ours) == len(literal) == 6
    assert set(literal["planner"]) == {"optimal_literal"} and set(ours["planner"]) == {"optimal"}
    assert literal["success"].sum() < ours["success"].sum()


def test_gallery_draws_each_failure_at_close_and_end(readings_dir: Path, tmp_path: Path) -> None:
    df = collect(readings_dir / "literal").results
    failed = df[~df["success"]]
    md = write_gallery(df, tmp_path, per_reason=1)
    pngs = sorted(p.name for p in (tmp_path / "gallery").glob("*.png"))
    expected = {
        f"primitives_optimal_literal_collab_z_{r.reason}_{r.object}_{r.trial:03d}.png"
        for r in pick_examples(df, 1).itertuples()
    }
    assert set(pngs) == expected and len(pngs) == failed["reason"].nunique()
    assert all((tmp_path / "gallery" / p).stat().st_size > 10_000 for p in pngs)
    assert all(str(p) in md for p in pick_examples(df, 1)["path"])
    log = read_trial(failed["path"].iloc[0])
    t = key_times(log)
    assert 0 < t["close"] <= t["end"]


def test_entities_at_follows_additions_and_deletions(readings_dir: Path) -> None:
    path = collect(readings_dir / "default").results["path"].iloc[0]
    log = read_trial(path)
    first = log.scenes[0][0]
    assert "support" in _entities_at(log, first)
    log.scene_deletions.append((first + 0.5, "support"))
    assert "support" not in _entities_at(log, first + 0.6)
    assert "support" in _entities_at(log, first + 0.4)


def test_pick_examples_prefers_distinct_objects() -> None:
    rows = [("a", 0), ("a", 1), ("b", 5), ("c", 2)]
    df = pd.DataFrame(
        [
            {"dataset": "d", "planner": "p", "mode": "bin", "rot": "z", "object": o, "trial": t}
            | {"success": False, "reason": "dropped"}
            for o, t in rows
        ]
    )
    picked = pick_examples(df, 3)
    assert list(zip(picked["object"], picked["trial"], strict=True)) == [("a", 0), ("c", 2), ("b", 5)]


def test_readings_table_rows_and_ceiling(readings_dir: Path, tmp_path: Path) -> None:
    entries = {n: (readings_dir / n, ALL[n].what) for n in ("default", "literal")}
    md = readings_report(entries, tmp_path)
    table = pd.read_csv(tmp_path / "readings.csv")
    assert set(table["reading"]) == {"default", "literal"} and (table["n"] == 6).all()
    for name in ("default", "literal"):
        df = collect(readings_dir / name).results
        row = table[table["reading"] == name].iloc[0]
        assert row["ours_pct"] == pytest.approx(100 * df["success"].mean())
    ceiling = pd.read_csv(tmp_path / "ceiling.csv")
    assert len(ceiling) == 3
    best = pd.concat([collect(readings_dir / n).results.assign(r=n) for n in entries])
    per = best.groupby(["object", "r"])["success"].mean().groupby("object").max() * 100
    np.testing.assert_allclose(ceiling.set_index("object")["best_pct"].sort_index(), per.sort_index())
    assert "default" in md and "literal" in md
    # The second criterion beside each rate, and the grasp frame's X per object of the default reading.
    assert table["in_area_pct"].between(0, 100).all()
    assert (table["in_area_pct"] <= table["ours_pct"] + 1e-9).all()
    axes = pd.read_csv(tmp_path / "area_axes.csv")
    assert sorted(axes["object"]) == ["block", "box", "mug"]
    assert (axes["elongation"] >= 1).all() and set(axes["pose_axis"]) <= {"object", "area"}
    assert "The grasp frame's X per object" in md


def test_a_reading_directory_with_two_configs_is_refused(readings_dir: Path, tmp_path: Path) -> None:
    with pytest.raises(MixedConfigError, match="holds planners"):
        readings_report({"both": (readings_dir, "")}, tmp_path)


def test_readings_command_shape_and_bad_names(tmp_path: Path, capsys) -> None:
    assert [r.name for r in READINGS[:3]] == ["default", "in_area", "literal"]
    cmd = reading_sweep(ALL["r_rms"], tmp_path)
    assert cmd[-2:] == ["planner=optimal", "planner.cluster_radius=rms"]
    assert "mode=collab,bin" in cmd and "rot=z,xyz" in cmd and f"hydra.sweep.dir={tmp_path / 'r_rms'}" in cmd
    assert "dataset=ycb,linemod" in cmd and "trials=10" in cmd
    assert reading_sweep(ALL["r_rms"], tmp_path, ["trials=3", "gripper=panda"])[-4:] == [
        "planner=optimal",
        "planner.cluster_radius=rms",
        "trials=3",
        "gripper=panda",
    ]
    assert "trials=10" not in reading_sweep(ALL["r_rms"], tmp_path, ["trials=3"])
    assert readings_main(["--out", str(tmp_path), "--only", "nope", "--report-only"]) == 2
    assert "unknown ['nope']" in capsys.readouterr().err
