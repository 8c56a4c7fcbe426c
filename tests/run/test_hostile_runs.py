"""Issue 39: runs into shared directories and objects from other people's folders. No run file is written
through a planted link or outside the run, an unrun object is never a 0 % in an average or an objective, a
job in which nothing ran is refused, and resume never mixes collision shapes or grasping areas."""

import re
from pathlib import Path
from types import SimpleNamespace

import pandas as pd
import pytest
import trimesh
from helpers.config import compose_cfg

from graspexp.core.outcome import TrialResult
from graspexp.core.run_layout import trial_log_path
from graspexp.core.userinput import UserInputError
from graspexp.record import TrialRecorder
from graspexp.run.locks import RunError
from graspexp.run.resume import check_same_meshes
from graspexp.run.runner import run_in_dir
from graspexp.run.summary import objective_value, summarize, summary_markdown


def test_an_unrun_object_is_in_no_average_and_no_objective():
    rows = [("ape", 0, False, "error"), ("ape", 1, False, "error")]
    rows += [("can", i, i < 2, None if i < 2 else "dropped") for i in range(3)]
    df = pd.DataFrame(rows, columns=["object", "trial", "success", "reason"])
    table = summarize(df)
    assert table.loc["Average", "success_%"] == pytest.approx(200 / 3)  # can alone: ape is not 0 %
    assert table.loc["ape", "trials"] == 0 and table.loc["ape", "not_run"] == 2
    assert re.search(r"\| ape +\| +0 \| not run +\|", summary_markdown(table))
    assert objective_value(df, "worst_object") == pytest.approx(2 / 3)


def test_a_job_in_which_nothing_ran_is_refused_in_one_line(tmp_path):
    objects = tmp_path / "objects"
    objects.mkdir()
    trimesh.creation.box(extents=(0.05, 0.05, 0.05)).export(objects / "cube.stl")
    (objects / "cube.yaml").write_text("mass_kg: -1\n")  # the only object cannot be used
    cfg = compose_cfg("dataset=folder", f"dataset.root={objects}", "trials=1", "progress=false")
    with pytest.raises(
        RunError, match=r"no trial ran: every one of the 1 trials ended in an error \(first: cube"
    ) as err:
        run_in_dir(cfg, tmp_path / "run")
    assert "\n" not in str(err.value)
    assert re.search(r"\| cube +\| +0 \| not run +\|", (tmp_path / "run" / "summary.md").read_text())


@pytest.mark.parametrize("planted", ["results.csv", "trials/can"])
def test_no_run_file_is_written_through_a_planted_link(tmp_path, planted):
    victim = tmp_path / "victim"
    victim.mkdir()
    (victim / "data.txt").write_text("keep me")
    run = tmp_path / "run"
    (run / "trials").mkdir(parents=True)
    (run / planted).symlink_to(victim if planted == "trials/can" else victim / "data.txt")
    cfg = compose_cfg("dataset=primitives", "objects=[can]", "trials=1", "progress=false")
    with pytest.raises(
        RunError, match=rf"{planted} is a symbolic link; graspexp writes no run file through a link"
    ):
        run_in_dir(cfg, run)
    assert [p.name for p in victim.iterdir()] == ["data.txt"] and (
        victim / "data.txt"
    ).read_text() == "keep me"


@pytest.mark.parametrize("name", ["..", ".", ".quarantine", "a/b", "a\nb"])
def test_no_log_path_leaves_trials_for_a_name_that_is_no_object(tmp_path, name):
    with pytest.raises(UserInputError, match="is not a valid object name"):
        trial_log_path(tmp_path, name, 0)


def _log(run: Path, **meta: str) -> None:
    path = trial_log_path(run, "can", 0)
    with TrialRecorder(path, {"object": "can", "mesh_sha256": "m" * 64, **meta}) as rec:
        rec.result(0.0, TrialResult("primitives", "can", "collab", "z", "optimal", 0, 1, True, None))


@pytest.mark.parametrize(
    "logged, match",
    [
        (
            {"collision_sha256": "c" * 64},
            r"another collision shape \(a changed cache entry\?\).*collision_sha256 cccc",
        ),
        ({"area_sha256": "a" * 64}, r"another grasping area \(an edited area spec\?\).*area_sha256 aaaa"),
    ],
)
def test_resume_refuses_logs_of_another_collision_shape_or_area(tmp_path, logged, match):
    _log(tmp_path, **logged)
    model = SimpleNamespace(name="can", mesh_sha256="m" * 64, area_sha256="b" * 64, source="", mesh_facts={})
    now = {"can": SimpleNamespace(model=model, hulls=SimpleNamespace(sha256="d" * 64))}
    with pytest.raises(RunError, match=match):
        check_same_meshes(tmp_path, now)
    _log(tmp_path)  # a log that records neither (older graspexp) is not compared
    check_same_meshes(tmp_path, now)


def test_a_log_whose_recorded_config_is_an_alias_bomb_is_moved_aside_not_expanded(tmp_path):
    from graspexp.run.resume import check_resumable

    bomb = "a: &a [x, x, x, x, x, x, x, x, x]\n" + "".join(
        f"{c}: &{c} [*{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}]\n"
        for p, c in zip("abcdefgh", "bcdefghi", strict=True)
    )
    _log(tmp_path, config_yaml=bomb)
    check_resumable(compose_cfg("dataset=primitives"), tmp_path)  # quarantined, never expanded
    assert [p.name for p in (tmp_path / "trials" / ".quarantine" / "can").iterdir()][0].startswith(
        "000.mcap."
    )
