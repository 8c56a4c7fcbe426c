"""gripper=urdf: the stroke and palm come from the file; a missing, broken or unsuitable URDF is refused in
one line naming the key and the file."""

import builtins
import io
import re

import pytest
from helpers.config import compose_cfg
from helpers.objects import write_urdf_gripper
from omegaconf import OmegaConf

from graspexp.config import ConfigError, validate
from graspexp.grippers import LEFT, GripperGeometry, fill_gripper
from graspexp.run.job_config import compose_job, make_ready


def test_the_stroke_comes_from_the_joint_limits(tmp_path):
    urdf = write_urdf_gripper(tmp_path, upper_m=0.04)
    cfg = compose_job(["gripper=urdf", f"gripper.urdf={urdf}"])
    assert cfg.gripper.max_width_m == pytest.approx(0.08)
    assert list(cfg.gripper.palm_size_m) == pytest.approx([0.045, 0.15, 0.06])


def _error(*overrides: str) -> str:
    with pytest.raises(ConfigError) as info:
        make_ready(compose_cfg(*overrides))
    message = str(info.value)
    assert "\n" not in message
    return message


def test_urdf_errors_are_one_line(tmp_path):
    urdf = write_urdf_gripper(tmp_path)
    assert _error("gripper=urdf") == "gripper.urdf has no value: set it with gripper.urdf=..."
    missing = tmp_path / "none.urdf"
    assert _error("gripper=urdf", f"gripper.urdf={missing}") == (
        f"gripper.urdf='{missing}' is invalid: {missing} not found"
    )
    broken = tmp_path / "broken.urdf"
    broken.write_text("<robot><link name='a'>")
    assert re.match(
        r"gripper.urdf='.*broken.urdf' is invalid: cannot read .*broken.urdf: ",
        _error("gripper=urdf", f"gripper.urdf={broken}"),
    )
    assert "has no joint 'nope'" in _error(
        "gripper=urdf", f"gripper.urdf={urdf}", "gripper.urdf_finger_joints=[left_joint,nope]"
    )
    assert "is not perpendicular to the closing axis" in _error(
        "gripper=urdf", f"gripper.urdf={urdf}", "gripper.urdf_approach_axis=[0,1,0]"
    )
    assert _error("gripper=urdf", f"gripper.urdf={urdf}", "gripper.max_width_m=0.2").startswith(
        "gripper.max_width_m=0.2 is invalid: expected <= 0.11 m, the stroke of the finger joints of "
    )
    (tmp_path / "tip.stl").unlink()
    assert re.search(r"mesh file .*tip.stl not found$", _error("gripper=urdf", f"gripper.urdf={urdf}"))


def test_finger_joints_must_be_prismatic_and_opposed(tmp_path):
    urdf = write_urdf_gripper(tmp_path)
    urdf.write_text(urdf.read_text().replace('<axis xyz="0 -1 0"/>', '<axis xyz="0 1 0"/>'))
    assert "do not open in opposite directions" in _error("gripper=urdf", f"gripper.urdf={urdf}")
    urdf.write_text(urdf.read_text().replace('type="prismatic"', 'type="revolute"'))
    assert "expected 2 prismatic finger joints" in _error("gripper=urdf", f"gripper.urdf={urdf}")


def test_the_tcp_is_behind_the_tips_or_where_the_config_puts_it(tmp_path):
    urdf = f"gripper.urdf={write_urdf_gripper(tmp_path, curved_tip=False)}"
    default = GripperGeometry.of(compose_job(["gripper=urdf", urdf]).gripper)
    assert (default.root_z_m, default.tip_z_m) == pytest.approx((-0.07, 0.01))  # as the RG2 box model
    deeper = compose_job(["gripper=urdf", urdf, "gripper.urdf_tcp_m=[0,0.003,0.065]"]).gripper
    geometry = GripperGeometry.of(deeper)  # fingers from z = 0 to 0.08 in the palm link: tips 15 mm ahead
    assert (geometry.root_z_m, geometry.tip_z_m) == pytest.approx((-0.065, 0.015))
    assert geometry.hand.part_vertices(LEFT)[:, 1].min() == pytest.approx(0.0)  # y ignored: pads centred


def test_validation_reads_no_file_and_writes_nothing_the_grippers_stage_fills_in(tmp_path, monkeypatch):
    cfg = compose_cfg("gripper=urdf", f"gripper.urdf={write_urdf_gripper(tmp_path, upper_m=0.04)}")
    before = OmegaConf.to_yaml(cfg)

    def no_file(*args, **kwargs):
        raise AssertionError(f"validate opened a file: {args[:1]}")

    with monkeypatch.context() as m:
        m.setattr(builtins, "open", no_file)
        m.setattr(io, "open", no_file)
        validate(cfg)
    assert OmegaConf.to_yaml(cfg) == before
    assert OmegaConf.is_missing(cfg.gripper, "max_width_m")
    fill_gripper(cfg)
    assert cfg.gripper.max_width_m == pytest.approx(0.08)
    assert list(cfg.gripper.palm_size_m) == pytest.approx([0.045, 0.15, 0.06])
