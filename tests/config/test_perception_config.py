"""The perception keys: the d435 preset composes, bad values are one line naming the key, and a job that
needs the camera without the camera extra is refused with the install command."""

import importlib.util
import re

import pytest
from helpers.config import compose_cfg

from graspexp.config import ConfigError, validate
from graspexp.config import perception as P


def test_the_d435_preset_and_truth_default():
    cfg = compose_cfg("perception/camera=d435")
    validate(cfg)
    assert cfg.perception.source == "truth" and cfg.perception.camera.name == "d435"
    assert (cfg.perception.camera.width_px, cfg.perception.camera.height_px) == (424, 240)


@pytest.mark.parametrize(
    ("override", "message"),
    [
        ("perception.source=stereo", "perception.source='stereo' is invalid: expected one of truth, depth"),
        ("perception.registration.prior=pvn3d", "perception.registration.prior='pvn3d' is invalid"),
        (
            "perception.camera.elevation_deg=0",
            "perception.camera.elevation_deg=0.0 is invalid: expected a number in (0, 90] deg",
        ),
        (
            "perception.camera.min_range_m=5",
            "perception.camera.min_range_m=5.0 is invalid: expected < perception.camera.max_range_m=3.0",
        ),
    ],
)
def test_bad_values_name_the_key(override, message):
    with pytest.raises(ConfigError, match="^" + re.escape(message)):
        validate(compose_cfg(override))


@pytest.mark.parametrize("override", ["perception.source=depth", "planner=antipodal_view"])
def test_a_missing_camera_extra_is_one_line_with_the_install_command(override, monkeypatch):
    real = importlib.util.find_spec
    monkeypatch.setattr(
        importlib.util, "find_spec", lambda name, *a: None if name == "open3d" else real(name, *a)
    )
    with pytest.raises(ConfigError) as err:
        validate(compose_cfg(override))
    assert str(err.value).endswith(f"needs open3d-cpu, not installed: {P.CAMERA_EXTRA}")
    assert "\n" not in str(err.value)
