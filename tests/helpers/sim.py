"""The grip force a gripper really applies, measured in SAPIEN."""

from pathlib import Path

import numpy as np
import sapien
from omegaconf import OmegaConf

from graspexp.core.bodies import OBJECT_NAME
from graspexp.run.job_config import make_ready
from graspexp.sim.contacts import finger_forces
from graspexp.sim.gripper import build_gripper
from graspexp.sim.scene import GRIPPER_BIT, OBJECT_BIT, configure_physx, set_groups
from helpers.config import compose_cfg
from helpers.objects import write_urdf_gripper

THIN_M = 0.01
"""Width of the thin box, m (a pen, a screwdriver shaft)."""

WIDE_FRACTION = 0.8
"""Width of the wide box as a fraction of the stroke."""

MEASURE_S = 0.1
"""The force is averaged over the last 0.1 s of sim.close_s, s."""


def gripper_overrides(gripper: str, folder: Path) -> list[str]:
    """Overrides that choose gripper option ``gripper``; ``urdf`` gets the test URDF written into ``folder``."""
    extra = [f"gripper.urdf={write_urdf_gripper(folder)}"] if gripper == "urdf" else []
    return [f"gripper={gripper}", *extra]


def steady_finger_forces(overrides: list[str], width_m: float) -> tuple[np.ndarray, float]:
    """((2,) mean force of each finger on a static box of ``width_m`` along the closing axis, N; grip_force_n)
    for the gripper of ``overrides``."""
    composed = compose_cfg(*overrides)
    make_ready(composed)
    cfg = OmegaConf.to_object(composed)
    configure_physx(cfg.sim)
    scene = sapien.Scene([sapien.physx.PhysxCpuSystem()])
    scene.set_timestep(cfg.sim.timestep_s)
    builder = scene.create_actor_builder()
    builder.add_box_collision(half_size=[0.02, width_m / 2, 0.01])  # centred on the TCP, between the pads
    box = builder.build_static(OBJECT_NAME)
    set_groups(box.find_component_by_type(sapien.physx.PhysxRigidStaticComponent), OBJECT_BIT, GRIPPER_BIT)
    grip = build_gripper(scene, cfg.gripper, np.eye(4), support_collides=False)
    grip.set_state(np.zeros(3), cfg.gripper.max_width_m / 2)
    grip.close()
    dt = cfg.sim.timestep_s
    forces = []
    for _ in range(round(cfg.sim.close_s / dt)):
        scene.step()
        forces.append(list(finger_forces(scene.get_contacts(), dt, np.array([0.0, 1.0, 0.0])).values()))
    return np.mean(forces[-round(MEASURE_S / dt) :], axis=0), cfg.gripper.grip_force_n
