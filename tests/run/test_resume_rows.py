"""Issue 51, findings 5 and 6 (single-object modes): nothing finished is overwritten or dropped. An object
that cannot be used on a re-run keeps its finished logs and rows; a ``record=false`` re-run merges with the
finished rows of the same config or is refused as a logged run is (one rule: docs/guide/running.md,
"Resume, and what a run refuses")."""

import logging
from pathlib import Path

import pandas as pd
import pytest
import trimesh
from helpers.config import compose_cfg

from graspexp.record import read_result
from graspexp.run.locks import RunError
from graspexp.run.runner import run_in_dir

pytestmark = pytest.mark.slow


def _can(*overrides: str):
    return compose_cfg("dataset=primitives", "objects=[can]", "progress=false", *overrides)


def _rows(run: Path) -> list[tuple]:
    df = pd.read_csv(run / "results.csv", keep_default_na=False)
    return sorted(zip(df["object"], df["trial"], df["planner"], df["reason"].replace("", "ok"), strict=True))


def _snapshot(folder: Path) -> dict[str, bytes]:
    return {
        str(p.relative_to(folder)): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file() and ".graspexp.lock" not in p.name
    }


def test_finding_6_a_record_false_rerun_with_another_planner_is_refused(tmp_path):
    """record=false trials=3, then record=false trials=1 planner=antipodal: it left one antipodal row."""
    run_in_dir(_can("record=false", "trials=3"), tmp_path)
    before = _snapshot(tmp_path)
    with pytest.raises(RunError) as err:
        run_in_dir(_can("record=false", "trials=1", "planner=antipodal"), tmp_path)
    line = str(err.value)
    assert "\n" not in line and line.startswith(f"{tmp_path} holds results made with a different config; ")
    assert (
        "differing keys: planner.name, " in line
        and "(run.json: planner.name: 'optimal' in its record" in line
    )
    assert _snapshot(tmp_path) == before
    assert [r[:3] for r in _rows(tmp_path)] == [("can", t, "optimal") for t in range(3)]


def test_finding_6_a_logged_rerun_keeps_the_record_false_rows(tmp_path):
    """record=false trials=4, then record=true trials=2: it kept trials 0-1 only."""
    run_in_dir(_can("record=false", "trials=4"), tmp_path)
    first = pd.read_csv(tmp_path / "results.csv")
    run_in_dir(_can("record=true", "trials=2"), tmp_path)
    assert sorted(p.name for p in (tmp_path / "trials" / "can").glob("*.mcap")) == ["000.mcap", "001.mcap"]
    df = pd.read_csv(tmp_path / "results.csv").sort_values("trial").reset_index(drop=True)
    cols = ["object", "trial", "seed", "success", "reason", "grasp_cost"]
    pd.testing.assert_frame_equal(df[cols], first[cols])  # the same four trials, the same results
    assert "|        4 |" in (tmp_path / "summary.md").read_text()
    from graspexp.report.collect import collect

    assert sorted(collect(tmp_path).results["trial"]) == [0, 1, 2, 3]  # the report reads all four
    run_in_dir(
        _can("record=false", "trials=1", "objects=[box]"), tmp_path
    )  # another object extends the table
    assert [r[:2] for r in _rows(tmp_path)] == [("box", 0)] + [("can", t) for t in range(4)]


def test_rows_no_log_backs_without_a_record_are_refused_not_overwritten(tmp_path):
    """A results.csv written before graspexp kept the run record: its rows are of an unknown config."""
    run_in_dir(_can("record=false", "trials=3"), tmp_path)
    (tmp_path / "run.json").unlink()
    before = _snapshot(tmp_path)
    with pytest.raises(
        RunError, match=r"results.csv holds 3 rows that no log backs \(can trial 0, can trial 1"
    ):
        run_in_dir(_can("record=false", "trials=1"), tmp_path)
    assert _snapshot(tmp_path) == before


def _folder(root: Path, x_m: float = 0.05) -> Path:
    root.mkdir(exist_ok=True)
    trimesh.creation.box(extents=(x_m, 0.04, 0.06)).export(root / "brick.stl")
    trimesh.creation.cylinder(radius=0.025, height=0.08, sections=24).export(root / "tin.stl")
    return root


def _folder_cfg(root: Path, *overrides: str):
    return compose_cfg(
        "dataset=folder", f"dataset.root={root}", "objects=[brick,tin]", "progress=false", *overrides
    )


def test_a_record_false_row_of_another_mesh_is_refused_with_both_hashes(tmp_path):
    from graspexp.datasets import job_object

    meshes, run = _folder(tmp_path / "meshes"), tmp_path / "run"
    run_in_dir(_folder_cfg(meshes, "record=false", "trials=1"), run)
    old = job_object(_folder_cfg(meshes), "brick").mesh_sha256
    _folder(meshes, 0.055)
    new = job_object(_folder_cfg(meshes), "brick").mesh_sha256
    with pytest.raises(RunError) as err:
        run_in_dir(_folder_cfg(meshes, "record=false", "trials=2"), run)
    line = str(err.value)
    assert "holds trials of brick made on another mesh (run.json: " in line, line
    assert f"sha256 {old[:12]}" in line and f"sha256 {new[:12]}" in line, line


@pytest.mark.parametrize("record", ["true", "false"])
def test_finding_5_an_object_that_became_unusable_keeps_its_finished_trials(tmp_path, caplog, record):
    """A finished log was overwritten by an error log when its object became unusable on a re-run."""
    meshes, run = _folder(tmp_path / "meshes"), tmp_path / "run"
    run_in_dir(_folder_cfg(meshes, f"record={record}", "trials=2"), run)
    logs = {p.name: p.read_bytes() for p in (run / "trials" / "brick").glob("*.mcap")}
    (meshes / "brick.yaml").write_text("mass_kg: -1\n")  # brick cannot be used any more
    with caplog.at_level(logging.WARNING):
        run_in_dir(_folder_cfg(meshes, f"record={record}", "trials=3"), run)
    after = {p.name: p.read_bytes() for p in (run / "trials" / "brick").glob("*.mcap")}
    assert {k: after[k] for k in logs} == logs  # the finished logs, untouched
    if record == "true":
        assert sorted(after) == ["000.mcap", "001.mcap", "002.mcap"]
        assert read_result(run / "trials" / "brick" / "002.mcap")["reason"] == "error"
    assert [r for r in _rows(run) if r[0] == "brick"] == [
        ("brick", 0, "optimal", "ok"),
        ("brick", 1, "optimal", "ok"),
        ("brick", 2, "optimal", "error"),
    ]
    kept = [r.getMessage() for r in caplog.records if "finished trials are kept" in r.getMessage()]
    assert len(kept) == 1 and kept[0].startswith("brick cannot be used now; "), kept
    assert "the other 1 are not run" in kept[0]
    summary = (run / "summary.md").read_text()
    assert (
        "- brick: NOT RUN, " in summary
        and "(its 2 finished trial(s) from an earlier run are kept)" in summary
    )


def test_a_record_that_speaks_for_no_row_refuses_nothing(tmp_path):
    """A run killed before it wrote its tables leaves run.json alone: another config may use the folder."""
    run_in_dir(_can("record=false", "trials=1"), tmp_path)
    (tmp_path / "results.csv").unlink()
    run_in_dir(_can("record=false", "trials=1", "planner=antipodal"), tmp_path)
    assert _rows(tmp_path) == [("can", 0, "antipodal", "ok")]
