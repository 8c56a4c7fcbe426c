"""A trial with the depth camera in the loop (perception.source=depth) logs what the camera saw (depth and
id images, calibration, cloud, true / prior / estimated object frames, pose errors), passes the strict
validator, and ``replay --resim`` reproduces it, registration included."""

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from helpers.logs import strictly_valid

from graspexp.record import read_trial

pytestmark = pytest.mark.slow
REPO = Path(__file__).resolve().parents[2]
SMALL_CAMERA = (
    "perception.camera.width_px=160",
    "perception.camera.height_px=120",
    "perception.camera.fx_px=110",
    "perception.camera.fy_px=110",
    "perception.camera.cx_px=79.5",
    "perception.camera.cy_px=59.5",
)


@pytest.fixture(scope="module")
def camera_log(tmp_path_factory) -> Path:
    run = tmp_path_factory.mktemp("camera")
    cmd = [
        sys.executable, "-m", "graspexp", "progress=false", f"hydra.run.dir={run}", "objects=[can]",
        "trials=1", "perception.source=depth", "perception.noise.trans_mm=10", "perception.noise.rot_deg=10",
        *SMALL_CAMERA,
    ]  # fmt: skip
    proc = subprocess.run(cmd, cwd=REPO, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-2000:]
    return run / "trials" / "can" / "000.mcap"


def test_camera_trial_log_passes_the_strict_validator(camera_log):
    with open(camera_log, "rb") as f:
        counts = strictly_valid(f)
    for topic in ("/camera/depth", "/camera/ids", "/camera/calibration", "/camera/cloud", "/perception"):
        assert counts[topic] == 1, (topic, counts)
    log = read_trial(camera_log)
    assert {"view0", "object_true", "object_prior", "object_estimated"} <= set(log.transforms)
    p = log.perception
    assert p["source"] == "depth" and p["method"] == "icp" and p["n_target_points"] > 20
    np.testing.assert_allclose(
        log.transforms["object_estimated"][1][0], p["estimated_pose"][:3, 3], atol=1e-9
    )
    r = log.result
    assert r["pose_adds_mm"] == pytest.approx(p["adds_mm"]) and 0.0 <= r["registration_fitness"] <= 1.0
    assert r["pose_adds_mm"] < 10.0


def test_camera_trial_resimulates(camera_log):
    proc = subprocess.run(
        [sys.executable, "-m", "graspexp", "replay", str(camera_log), "--resim"],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "resim: agrees" in proc.stdout, proc.stdout
