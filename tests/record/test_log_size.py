"""A camera whose images make logs of hundreds of MB a trial is said so, once, before the first trial
(issue 51, finding 10: a 4096 x 4096 four-view trial wrote a 322 MB log without a word)."""

import pytest

from graspexp.datasets import DatasetError
from graspexp.record.log_size import IMAGE_BYTES_PER_PX, LOG_WARN_BYTES, camera_log_bytes, log_size_warning
from graspexp.run.job_config import compose_job
from graspexp.run.runner import run_in_dir

BIG = [
    "perception.source=depth",
    "perception.camera.width_px=4096",
    "perception.camera.height_px=4096",
    "perception.camera.azimuths_deg=[0,90,180,270]",
]


def test_the_estimate_is_width_height_views_and_the_bytes_of_a_pixel():
    cfg = compose_job(BIG)
    assert IMAGE_BYTES_PER_PX == 4 + 2  # 32FC1 depth + 16UC1 ids, as TrialWriter.perception logs them
    assert camera_log_bytes(cfg) == 4096 * 4096 * 4 * 6 > LOG_WARN_BYTES
    assert log_size_warning(cfg) == (
        "perception.camera 4096 x 4096 px x 4 view(s) logs about 403 MB of depth and id images per trial (per "
        "attempt in a clutter round) before compression, above the 100 MB this warns at: lower "
        "perception.camera.width_px/height_px or the azimuths, or record=false to write no log"
    )


@pytest.mark.parametrize(
    "overrides",
    [
        ["perception.source=depth"],  # the D435 preset: 0.6 MB
        [*BIG, "record=false"],  # no log
        BIG[1:],  # perception.source=truth with a planner that reads no camera: nothing rendered
        [
            "perception.source=depth",
            "perception.camera.width_px=1280",
            "perception.camera.height_px=720",
            "perception.camera.azimuths_deg=[0,90,180,270]",
        ],  # the D435's largest mode, four views: 22 MB
    ],
    ids=["d435", "record-false", "no-camera", "d435-max-four-views"],
)
def test_no_warning_for_logs_of_a_real_sensors_size_or_no_log(overrides):
    assert log_size_warning(compose_job(overrides)) == ""


def test_the_job_warns_in_one_line_before_its_first_trial(capsys, tmp_path):
    """The warning comes before anything else the job does (here an unknown object ends it at once)."""
    with pytest.raises(DatasetError):
        run_in_dir(compose_job([*BIG, "dataset=primitives", "objects=[nope]"]), tmp_path / "run")
    err = capsys.readouterr().err.splitlines()
    assert [line for line in err if "warning" in line] == [
        f"graspexp: warning: {log_size_warning(compose_job(BIG))}"
    ]
