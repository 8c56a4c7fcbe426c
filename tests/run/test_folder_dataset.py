"""A folder of your own objects end to end: both modes with two planners, the report and the benchmark;
an object that cannot be used fails alone, one whose mesh cannot be repaired falls back to a convex
decomposition (real SAPIEN physics)."""

import numpy as np
import pandas as pd
import pytest
import trimesh
from helpers.cli import graspexp
from helpers.config import REPO
from helpers.objects import make_object_folder

from graspexp.record.reader import read_metadata

NAMES = ["arc", "ball", "box", "bracket", "can", "cone"]


@pytest.mark.slow
def test_a_folder_runs_both_modes_with_two_planners_and_reports(tmp_path):
    objects = make_object_folder(tmp_path / "objects")
    out = tmp_path / "bench"
    bench = graspexp(
        "benchmark", "planner=optimal_plus", "dataset=folder", f"dataset.root={objects}", "trials=1", "rot=z",
        "--noise", "", "--compare", "antipodal", "--out", str(out), "progress=false", cwd=REPO, timeout=900,
    )  # fmt: skip
    assert bench.returncode == 0, bench.stderr[-3000:]
    summary = (out / "optimal_plus" / "summary.md").read_text()
    assert "## Ranking on `folder`" in summary
    ranking = pd.read_csv(out / "optimal_plus" / "ranking.csv")
    assert set(ranking["planner"]) == {"optimal_plus", "antipodal"}
    for planner in ("optimal_plus", "antipodal"):
        runs = sorted((out / planner / "runs" / "folder").iterdir())
        assert [r.name for r in runs] == ["bin_z_t0_r0", "collab_z_t0_r0"]
        for run in runs:
            assert sorted(p.name for p in (run / "trials").iterdir()) == NAMES
            assert "Objects:\n- arc: units: cm (arc.yaml)" in (run / "summary.md").read_text()

    report = graspexp("report", str(out), "--out", str(tmp_path / "report"), cwd=REPO)
    assert report.returncode == 0, report.stderr[-3000:]
    for planner in ("optimal_plus", "antipodal"):
        table = (tmp_path / "report" / f"table_folder_{planner}.md").read_text()
        assert "paper" not in table.lower()  # the paper has no numbers for these objects
        rows = [line.split("|")[1].strip() for line in table.splitlines()[2:] if line.startswith("|")]
        assert rows == [*NAMES, "Average"]


@pytest.mark.slow
def test_an_unusable_object_fails_alone_and_an_unrepairable_mesh_falls_back(tmp_path):
    objects = tmp_path / "objects"
    objects.mkdir()
    trimesh.creation.cylinder(radius=0.03, height=0.1, sections=32).export(objects / "can.obj")
    trimesh.creation.box(extents=(120.0, 40.0, 60.0)).export(objects / "part.stl")  # millimetres, no sidecar
    cross = np.array(
        [[-4, 0, 0], [4, 0, 0], [4, 0, 10], [-4, 0, 10], [0, -4, 0], [0, 4, 0], [0, 4, 10], [0, -4, 10]]
    )
    faces = np.array([[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]])  # two crossed sheets: no closed surface
    trimesh.Trimesh(cross / 100.0, faces).export(objects / "cross.obj")
    run = tmp_path / "run"
    job = graspexp(
        "dataset=folder",
        f"dataset.root={objects}",
        "trials=2",
        "progress=false",
        f"hydra.run.dir={run}",
        cwd=REPO,
    )
    assert job.returncode == 0, job.stderr[-3000:]
    results = pd.read_csv(run / "results.csv")
    assert results.groupby("object")["reason"].apply(lambda r: (r == "error").all()).to_dict() == {
        "can": False, "cross": False, "part": True,
    }  # fmt: skip
    error = results.loc[results["object"] == "part", "error"].iloc[0]
    assert "part.stl" in error and "units:" in error and "in mm (0.12 m)" in error
    summary = (run / "summary.md").read_text()
    assert "- part: NOT RUN, mesh " in summary
    assert (
        "- cross: " in summary and "collision: coacd (fallback: sim.collision_method=mesh failed" in summary
    )
    meta = read_metadata(run / "trials" / "cross" / "000.mcap")
    assert meta["collision_method"] == "coacd" and "mm p90" in meta["object_notes"]
    assert (run / "trials" / "part" / "000.mcap").is_file()  # the report counts the failed object's trials
