"""A URDF gripper (boxes and a rounded fingertip mesh, written at test time) in real SAPIEN physics: its
convex pieces are the links' collision shapes, it presses with the configured grip force within 1 %, and it
grasps and holds in both modes."""

import numpy as np
import pytest
import sapien
from helpers.config import compose_cfg
from helpers.objects import write_urdf_gripper
from helpers.sim import THIN_M, steady_finger_forces
from omegaconf import OmegaConf

from graspexp.run.job_config import make_ready
from graspexp.run.objects import load_sim_object, trial_context
from graspexp.sim.gripper import build_gripper
from graspexp.sim.trial import plain_config, run_trial


@pytest.fixture
def urdf(tmp_path):
    return f"gripper.urdf={write_urdf_gripper(tmp_path)}"


def test_the_links_carry_the_urdf_pieces(urdf):
    cfg = compose_cfg("gripper=urdf", urdf)
    make_ready(cfg)
    gripper_cfg = OmegaConf.to_object(cfg).gripper
    scene = sapien.Scene([sapien.physx.PhysxCpuSystem()])
    grip = build_gripper(scene, gripper_cfg, np.eye(4), support_collides=False)
    shapes = [len(link.collision_shapes) for link in (grip.palm, *grip.fingers)]
    assert shapes == [1, 2, 2]  # palm box; each finger: a box and the rounded tip
    assert all(isinstance(s, sapien.physx.PhysxCollisionShapeConvexMesh) for s in grip.palm.collision_shapes)


@pytest.mark.parametrize("width_m", [THIN_M, 0.06], ids=["thin", "wide"])
def test_grip_force_is_the_configured_one_within_1_percent(urdf, width_m):
    forces, grip_force = steady_finger_forces(["gripper=urdf", urdf, "gripper.grip_force_n=40"], width_m)
    np.testing.assert_allclose(forces, grip_force, rtol=0.01)


@pytest.mark.parametrize(("mode", "rot", "trial"), [("collab", "z", 0), ("bin", "xyz", 3)])
def test_a_can_is_grasped_and_held(urdf, mode, rot, trial):
    cfg = compose_cfg("dataset=primitives", "gripper=urdf", urdf, f"mode={mode}", f"rot={rot}")
    make_ready(cfg)
    plain = plain_config(cfg)
    res = run_trial(trial_context(plain, load_sim_object(cfg, "can", plain), trial))
    assert res.success, res
    assert (
        min(res.finger_force_n) > 0.9 * plain.gripper.grip_force_n
    )  # as the box models' (tests/sim/test_sim.py)
