"""The parallel gripper as a SAPIEN articulation built from ``conf/gripper/*``.

Chain: fixed root at the planned grasp frame -> prismatic x, y, z -> revolute roll, pitch, yaw (a driven,
floating 6-DoF base, expressed in the grasp frame) -> ``palm`` (the TCP frame: origin midway between the
pads, +Z approach, +Y closing axis) -> ``finger_left`` (+Y) and ``finger_right`` (-Y), prismatic,
force-limited drives coupled by a fixed tendon. A finger joint value q is the distance of that finger's
inner face from the TCP along +-Y, metres. Rooting the chain at the grasp frame keeps the rotational
joints near zero during a trial (no gimbal lock): the protocol holds them at 0 and moves the TCP by
translation offsets (pre-grasp, extend, pull back, lift), as the paper's end effector does. A box model's
palm and fingers carry its boxes; a URDF gripper's carry its convex collision pieces, the rest is the same.
"""

import math
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
import sapien

from graspexp.config.gripper import GripperConfig
from graspexp.core.bodies import FINGER_NAMES, PALM_NAME
from graspexp.core.geometry import matrix_to_quat_wxyz
from graspexp.grippers import LEFT, PALM, RIGHT, GripperGeometry, HandMeshes
from graspexp.sim.scene import GRIPPER_BIT, OBJECT_BIT, SUPPORT_BIT, set_groups

# wxyz quaternions that turn a joint's +x axis onto the named axis
_AXIS_Q = {
    "x": [1.0, 0.0, 0.0, 0.0],
    "y": [np.cos(np.pi / 4), 0.0, 0.0, np.sin(np.pi / 4)],
    "-y": [np.cos(np.pi / 4), 0.0, 0.0, -np.sin(np.pi / 4)],
    "z": [np.cos(np.pi / 4), 0.0, -np.sin(np.pi / 4), 0.0],
}
N_BASE = 6
"""Base joints before the two fingers: 3 prismatic then 3 revolute."""


@dataclass
class Gripper:
    articulation: sapien.physx.PhysxArticulation
    palm: sapien.physx.PhysxArticulationLinkComponent
    fingers: tuple[sapien.physx.PhysxArticulationLinkComponent, sapien.physx.PhysxArticulationLinkComponent]
    joints: list
    close_target_m: float
    """Finger joint target when closing (negative: past fully closed), m; see ``gripper.close_force_margin``."""
    arm_targets: list[float] = field(default_factory=lambda: [math.nan] * 3)
    """The x, y, z drive targets last set, m (NaN: none yet)."""

    def set_state(self, offset: np.ndarray, half_width_m: float) -> None:
        """Teleport to TCP offset (3,) in the grasp frame, fingers at ``half_width_m``; zero velocity."""
        q = np.array([*offset, 0.0, 0.0, 0.0, half_width_m, half_width_m], dtype=np.float32)
        self.articulation.set_qpos(q)
        self.articulation.set_qvel(np.zeros_like(q))
        self.drive_arm(offset)
        self.drive_fingers(half_width_m)

    def drive_arm(self, offset: np.ndarray) -> None:
        """Position targets of the x, y, z joints: TCP offset (3,) in the grasp frame, metres; a joint whose
        target is unchanged is left alone."""
        for set_target, value in self.arm_moves(np.reshape(offset, (1, 3)))[0]:
            set_target(value)

    def arm_moves(self, offsets: np.ndarray) -> list[list[tuple[Callable[[float], None], float]]]:
        """The x, y, z drive-target changes that move the TCP through ``offsets`` ((n, 3) in the grasp frame,
        m), one list per step of (setter, target): a joint whose target is unchanged since the step before (or
        since the last move) is left alone. Computed before stepping; :attr:`arm_targets` becomes the last row."""
        setters = [joint.set_drive_target for joint in self.joints[:3]]
        last = self.arm_targets
        moves = []
        for row in np.asarray(offsets, dtype=float).tolist():
            changed = []
            for i, value in enumerate(row):
                if value != last[i]:
                    changed.append((setters[i], value))
                    last[i] = value
            moves.append(changed)
        return moves

    def drive_fingers(self, half_width_m: float) -> None:
        for joint in self.joints[N_BASE:]:
            joint.set_drive_target(float(half_width_m))

    def close(self) -> None:
        """Drive the fingers past closed: each presses with the configured grip force."""
        self.drive_fingers(self.close_target_m)

    def tcp_pose(self) -> np.ndarray:
        """(4,4) world pose of the TCP (palm link frame)."""
        return self.palm.entity_pose.to_transformation_matrix()


def _attach_hulls(
    entities: list[sapien.Entity], hand: HandMeshes, material: sapien.physx.PhysxMaterial
) -> None:
    """Give the palm and finger links (entities not yet in a scene) the convex pieces of a URDF gripper, each
    in its link's frame (:mod:`graspexp.grippers.urdf`)."""
    links = {e.name: e.find_component_by_type(sapien.physx.PhysxArticulationLinkComponent) for e in entities}
    names = {PALM: PALM_NAME, LEFT: FINGER_NAMES[0], RIGHT: FINGER_NAMES[1]}
    one = np.ones(3, dtype=np.float32)
    for vertices, part in zip(hand.hulls, hand.hull_parts, strict=True):
        shape = sapien.physx.PhysxCollisionShapeConvexMesh(
            vertices=np.asarray(vertices, dtype=np.float32), scale=one, material=material
        )
        shape.set_density(1000.0)
        links[names[part]].attach(shape)
    counts = {name: len(link.collision_shapes) for name, link in links.items() if name in names.values()}
    expected = {names[p]: hand.hull_parts.count(p) for p in names}
    if counts != expected:  # PhysX drops a piece whose cooking failed
        raise RuntimeError(f"URDF gripper pieces attached {counts}, expected {expected}")


def build_gripper(
    scene: sapien.Scene, cfg: GripperConfig, grasp_pose: np.ndarray, support_collides: bool
) -> Gripper:
    """Build the gripper with its root at ``grasp_pose`` ((4,4) world); fingers open to the stroke. A box
    model gets its finger and palm boxes, a URDF gripper its convex collision pieces; the links, joints,
    drives and tendon are the same."""
    ab = scene.create_articulation_builder()
    pad = sapien.physx.PhysxMaterial(cfg.pad_friction, cfg.pad_friction, 0.0)
    link = ab.create_link_builder()
    link.set_name("root")
    link.set_mass_and_inertia(0.1, sapien.Pose(), [1e-4] * 3)
    for axis in ("x", "y", "z"):
        link = ab.create_link_builder(link)
        link.set_name(f"slide_{axis}")
        link.set_joint_name(f"slide_{axis}")
        q = _AXIS_Q[axis]
        link.set_joint_properties("prismatic", [[-1.0, 1.0]], sapien.Pose(q=q), sapien.Pose(q=q))
        link.set_mass_and_inertia(0.1, sapien.Pose(), [1e-4] * 3)
    for axis, name in (("x", "roll"), ("y", "pitch"), ("z", "yaw")):
        link = ab.create_link_builder(link)
        link.set_name(name)
        link.set_joint_name(name)
        q = _AXIS_Q[axis]
        link.set_joint_properties("revolute", [[-np.pi, np.pi]], sapien.Pose(q=q), sapien.Pose(q=q))
        link.set_mass_and_inertia(0.1, sapien.Pose(), [1e-4] * 3)
    palm = link
    palm.set_name(PALM_NAME)
    geometry = GripperGeometry.of(cfg)
    hand = geometry.hand
    if hand is None:
        box = geometry.palm()
        palm.add_box_collision(
            sapien.Pose(list(box.center)), half_size=[s / 2 for s in box.size], material=pad
        )
    for name, axis, sign, part in (("finger_left", "y", 1.0, LEFT), ("finger_right", "-y", -1.0, RIGHT)):
        f = ab.create_link_builder(palm)
        f.set_name(name)
        f.set_joint_name(name)
        q = _AXIS_Q[axis]
        f.set_joint_properties(
            "prismatic", [[-cfg.close_past_m, cfg.max_width_m / 2]], sapien.Pose(q=q), sapien.Pose(q=q)
        )
        if hand is None:
            box = geometry.finger(sign)
            center = list(box.center)
            f.add_box_collision(
                sapien.Pose(center), half_size=[s / 2 for s in box.size], material=pad, density=1000.0
            )
        else:
            center = hand.part_vertices(part).mean(axis=0).tolist()
        f.set_mass_and_inertia(cfg.finger_mass_kg, sapien.Pose(center), [1e-5] * 3)
    entities = ab.build_entities(fix_root_link=True)
    if hand is not None:
        _attach_hulls(entities, hand, pad)
    for entity in entities:
        scene.add_entity(entity)
    art = entities[0].find_component_by_type(sapien.physx.PhysxArticulationLinkComponent).articulation
    art.name = "gripper"
    art.set_root_pose(sapien.Pose(grasp_pose[:3, 3], matrix_to_quat_wxyz(grasp_pose[:3, :3])))
    mask = OBJECT_BIT | (SUPPORT_BIT if support_collides else 0)
    for lk in art.links:
        lk.disable_gravity = True
        set_groups(lk, GRIPPER_BIT, mask)
    joints = list(art.active_joints)
    for j in joints[:3]:
        j.set_drive_properties(
            stiffness=cfg.arm_stiffness_n_per_m,
            damping=cfg.arm_damping_ns_per_m,
            force_limit=cfg.arm_force_limit_n,
        )
    for j in joints[3:N_BASE]:
        j.set_drive_properties(
            stiffness=cfg.wrist_stiffness_nm_per_rad,
            damping=cfg.wrist_damping_nms_per_rad,
            force_limit=cfg.wrist_torque_limit_nm,
        )
        j.set_drive_target(0.0)
    for j in joints[N_BASE:]:
        j.set_drive_properties(
            stiffness=cfg.finger_stiffness_n_per_m,
            damping=cfg.finger_damping_ns_per_m,
            force_limit=float(cfg.grip_force_n),
        )
    links = {lk.name: lk for lk in art.links}
    # couple the fingers like a real parallel gripper's linkage: q_left - q_right -> 0, stiffly
    art.create_fixed_tendon(
        [links[PALM_NAME], links[FINGER_NAMES[0]], links[FINGER_NAMES[1]]],
        [0.0, 1.0, -1.0],
        [0.0, 1.0, -1.0],
        stiffness=cfg.coupling_stiffness_n_per_m,
        damping=cfg.coupling_damping_ns_per_m,
    )
    return Gripper(
        articulation=art,
        palm=links[PALM_NAME],
        fingers=(links[FINGER_NAMES[0]], links[FINGER_NAMES[1]]),
        joints=joints,
        close_target_m=-max(
            cfg.close_past_m, cfg.close_force_margin * float(cfg.grip_force_n) / cfg.finger_stiffness_n_per_m
        ),
    )
