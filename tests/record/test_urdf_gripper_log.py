"""A job with a URDF gripper logs its links as triangle meshes on /scene (foxglove.SceneUpdate), each
frame-locked to its link's /tf frame, and the log passes strict validation."""

from pathlib import Path

import pytest
from helpers.cli import run_job
from helpers.logs import strictly_valid
from helpers.objects import write_urdf_gripper

from graspexp.core.bodies import FINGER_NAMES, PALM_NAME
from graspexp.record import read_trial
from graspexp.record.reader import iter_trial_logs

pytestmark = pytest.mark.slow
REPO = Path(__file__).resolve().parents[2]


def test_the_log_shows_the_urdf_gripper_meshes(tmp_path):
    urdf = write_urdf_gripper(tmp_path)
    run = tmp_path / "run"
    proc = run_job(
        run,
        "dataset=primitives",
        "objects=[can]",
        "trials=1",
        "mode=bin",
        "gripper=urdf",
        f"gripper.urdf={urdf}",
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    (path,) = list(iter_trial_logs(run))
    with open(path, "rb") as f:
        assert strictly_valid(f)["/scene"] >= 2
    log = read_trial(path)
    entities = {e["id"]: e for _, ents in log.scenes for e in ents}
    for name in (PALM_NAME, *FINGER_NAMES):
        entity = entities[name]
        assert entity["frame_id"] == name and entity["frame_locked"] is True and not entity["cubes"]
        (tri,) = entity["triangles"]
        assert len(tri["indices"]) >= 36 and len(tri["indices"]) % 3 == 0  # at least a box's 12 triangles
    assert len(entities[FINGER_NAMES[0]]["triangles"][0]["points"]) > 8  # a box and the rounded tip
