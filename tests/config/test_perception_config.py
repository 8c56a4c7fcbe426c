"""The perception keys: the d435 preset composes with its values unchanged, a camera preset carries its own
depth noise (a new camera is one YAML file), bad values are one line naming the key, and a job that needs
the camera without the camera extra is refused with the install command."""

import importlib.util
import re

import pytest
from helpers.config import compose_cfg
from omegaconf import OmegaConf

from graspexp.config import ConfigError, validate
from graspexp.config import perception as P


def test_the_d435_preset_and_truth_default():
    cfg = compose_cfg("perception/camera=d435")
    validate(cfg)
    assert cfg.perception.source == "truth" and cfg.perception.camera.name == "d435"
    assert (cfg.perception.camera.width_px, cfg.perception.camera.height_px) == (424, 240)


D435_CAMERA = {
    "name": "d435",
    "width_px": 424,
    "height_px": 240,
    "fx_px": 223.4,
    "fy_px": 223.4,
    "cx_px": 211.5,
    "cy_px": 119.5,
    "min_range_m": 0.1,
    "max_range_m": 3.0,
    "distance_m": 0.6,
    "elevation_deg": 45.0,
    "azimuths_deg": [0.0],
    "look_at_height_m": 0.05,
    "workspace_half_m": 0.15,
    "workspace_top_m": 0.35,
}
D435_NOISE = {
    "enabled": True,
    "model": "nguyen",
    "axial_a_m": 0.0012,
    "axial_b_m": 0.0019,
    "axial_z0_m": 0.4,
    "axial_c_m": 0.0001,
    "lateral_px": 0.8,
    "lateral_angle_px": 0.035,
    "max_incidence_deg": 80.0,
    "edge_jump_m": 0.02,
    "dex_gamma_shape": 1000.0,
    "dex_gamma_scale": 0.001,
    "dex_gp_sigma_m": 0.005,
    "dex_gp_downsample": 4.0,
    "dex_gp_probability": 0.5,
}
"""The default camera and its noise, as every run so far had them (the dex model's coefficients beside, unread
with ``model=nguyen``)."""


@pytest.mark.parametrize("overrides", [(), ("perception/camera=d435",)])
def test_the_d435_defaults_are_unchanged(overrides):
    cfg = compose_cfg(*overrides)
    assert OmegaConf.to_container(cfg.perception.camera) == D435_CAMERA
    assert OmegaConf.to_container(cfg.perception.depth_noise) == D435_NOISE


KINECT = """# @package perception
defaults:
  - /schema_camera@camera
  - /schema_depth_noise@depth_noise
camera:
  name: kinect
  width_px: 640
  height_px: 480
  fx_px: 580.0
  fy_px: 580.0
  cx_px: 319.5
  cy_px: 239.5
depth_noise:
  axial_a_m: 0.002
  lateral_px: 0.5
"""


def test_a_camera_preset_carries_its_own_depth_noise(tmp_path):
    """A new camera is one YAML file under ``perception/camera/`` (here in a config overlay): it sets the
    camera and its noise coefficients; the key overrides still win over it, and the other keys keep the
    schema's defaults."""
    (tmp_path / "perception" / "camera").mkdir(parents=True)
    (tmp_path / "perception" / "camera" / "kinect.yaml").write_text(KINECT)
    overlay = f"hydra.searchpath=[file://{tmp_path}]"
    cfg = compose_cfg(overlay, "perception/camera=kinect", "perception.camera.distance_m=0.8")
    validate(cfg)
    camera, noise = OmegaConf.to_container(cfg.perception.camera), cfg.perception.depth_noise
    intrinsics = {"fx_px": 580.0, "fy_px": 580.0, "cx_px": 319.5, "cy_px": 239.5}
    sizes = {"name": "kinect", "width_px": 640, "height_px": 480, "distance_m": 0.8}
    assert camera == {**D435_CAMERA, **intrinsics, **sizes}
    assert OmegaConf.to_container(noise) == {**D435_NOISE, "axial_a_m": 0.002, "lateral_px": 0.5}
    off = compose_cfg(overlay, "perception/camera=kinect", "perception.depth_noise.enabled=false")
    assert not off.perception.depth_noise.enabled and off.perception.depth_noise.axial_a_m == 0.002
    assert OmegaConf.to_container(compose_cfg(overlay).perception.depth_noise) == D435_NOISE


@pytest.mark.parametrize(
    ("override", "message"),
    [
        (
            "perception.depth_noise.model=kinect",
            "perception.depth_noise.model='kinect' is invalid: expected one of nguyen, dex",
        ),
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
