"""Schema of the ``gripper`` config group: a parallel-jaw gripper, all lengths in metres.

Gripper frame (paper Fig. 9): +Z approach, +Y closing axis, origin midway between the finger pads.
A gripper is a box model (finger and palm boxes from the keys below) or, with ``urdf`` set, the collision
geometry of a URDF. This module holds the keys and their allowed values only; the gripper model they
describe (its geometry, a URDF's meshes) is built by the grippers stage (:mod:`graspexp.grippers`).
"""

from dataclasses import dataclass, field

from omegaconf import MISSING

from graspexp.config.constraints import TEXT, Interval, Names, Vector


@dataclass
class GripperConfig:
    name: str = MISSING
    """The gripper's name in logs and tables (the option's: ``rg2``, ``robotiq_2f85``, ``panda``, ``urdf``)."""
    max_width_m: float = MISSING
    """Largest opening between the finger pads (stroke), m."""
    min_width_m: float = 0.0
    """Smallest opening between the finger pads, m."""
    grip_force_n: float = MISSING
    """Force each finger presses with when closed on an object, N."""
    finger_length_m: float = 0.05
    """Finger length along the approach axis (+Z), m."""
    finger_width_m: float = 0.02
    """Finger width along the main axis (+X), m."""
    finger_thickness_m: float = 0.01
    """Finger thickness along the closing axis (+Y), m."""
    palm_size_m: list[float] = MISSING
    """Palm box full size [x, y, z] in the gripper frame, m; its front face touches the finger roots."""
    pad_friction: float = 1.0
    """Coulomb friction of the finger pads (PhysX averages with the object's)."""
    finger_mass_kg: float = 0.05
    """Mass of each finger, kg."""
    tcp_from_tip_m: float = 0.01
    """Distance from the fingertips back to the TCP (the grasp point, the pads' centre) along -Z, m."""
    arm_stiffness_n_per_m: float = 2.0e4
    """Drive stiffness of the simulated arm's three translation joints, N/m."""
    arm_damping_ns_per_m: float = 4.0e2
    """Drive damping of the arm's translation joints, N s/m."""
    arm_force_limit_n: float = 400.0
    """Force limit of the arm's translation drives, N."""
    wrist_stiffness_nm_per_rad: float = 2.0e3
    """Drive stiffness of the three wrist rotation joints (held at their start), N m/rad."""
    wrist_damping_nms_per_rad: float = 5.0e1
    """Drive damping of the wrist joints, N m s/rad."""
    wrist_torque_limit_nm: float = 200.0
    """Torque limit of the wrist drives, N m."""
    finger_stiffness_n_per_m: float = 2.0e3
    """Drive stiffness of each finger joint, N/m (its force limit is ``grip_force_n``)."""
    finger_damping_ns_per_m: float = 1.0e2
    """Drive damping of each finger joint, N s/m."""
    coupling_stiffness_n_per_m: float = 1.0e5
    """Stiffness of the fixed tendon that keeps both fingers at the same opening, N/m."""
    coupling_damping_ns_per_m: float = 1.0e3
    """Damping of that tendon, N s/m."""
    close_past_m: float = 0.02
    """How far past fully closed (q = 0) a finger may travel, m: its joint's lower limit is -this, so the
    limit never takes part of the squeeze on a thin object (with the limit at 0, a 10 mm box got 88 of
    100 N even with the target far past it)."""
    urdf: str | None = None
    """URDF file of the hand (a path; ``~`` expanded): its palm and finger collision geometry replaces the
    finger and palm boxes (``finger_length_m``, ``finger_width_m``, ``finger_thickness_m`` and
    ``palm_size_m`` are then unused; an unset ``palm_size_m`` is set to the palm's bounding box), and with
    ``max_width_m`` unset the joints' limits give the stroke (both filled in by
    :func:`graspexp.grippers.fill_gripper` when a job starts). None: the box model of those keys."""
    urdf_palm_link: str | None = None
    """URDF link of the palm (with the links fixed to it); None: the finger joints' parent link."""
    urdf_finger_joints: list[str] | None = None
    """The two prismatic finger joints [left, right] of the URDF; the left finger opens towards +Y. None:
    the two prismatic joints with collision geometry below them."""
    urdf_approach_axis: list[float] = field(default_factory=lambda: [0.0, 0.0, 1.0])
    """Approach direction (+Z of the gripper frame) in the URDF palm link's frame, unitless (normalised);
    it must be perpendicular to the finger joints' axes."""
    urdf_tcp_m: list[float] | None = None
    """TCP (grasp point) in the URDF palm link's frame, m; its component along the closing axis is set to
    the pads' middle. None: centred on the fingers' width, ``tcp_from_tip_m`` behind the fingertips."""
    close_force_margin: float = 2.0
    """The finger target lies this many times ``grip_force_n / finger_stiffness_n_per_m`` past closed (at
    least ``close_past_m``), so the drive's spring force at any contact is >= this x ``grip_force_n`` and the
    force limit alone sets the squeeze. PhysX's implicit drive delivers less than its limit when the spring
    barely exceeds it (measured on a 10 mm box, Robotiq 100 N: margin 1.1 -> 94 N, 1.5 -> 99.5 N, 2 ->
    100 N)."""


CONSTRAINTS = {
    "name": TEXT,
    "max_width_m": [Interval(0, 0.5, "right", "m")],
    "min_width_m": [Interval(0, 0.5, "left", "m")],
    "grip_force_n": [Interval(0, 1000, "right", "N")],
    "finger_length_m": [Interval(0, 0.5, "right", "m")],
    "finger_width_m": [Interval(0, 0.2, "right", "m")],
    "finger_thickness_m": [Interval(0, 0.1, "right", "m")],
    "palm_size_m": [Vector(3, Interval(0, 1, "right", "m"))],
    "pad_friction": [Interval(0, 5)],
    "finger_mass_kg": [Interval(0, 10, "right", "kg")],
    "tcp_from_tip_m": [Interval(0, 0.5, unit="m")],
    "arm_stiffness_n_per_m": [Interval(0, 1e9, "right", "N/m")],
    "arm_damping_ns_per_m": [Interval(0, 1e9, unit="N s/m")],
    "arm_force_limit_n": [Interval(0, 1e6, "right", "N")],
    "wrist_stiffness_nm_per_rad": [Interval(0, 1e9, "right", "N m/rad")],
    "wrist_damping_nms_per_rad": [Interval(0, 1e9, unit="N m s/rad")],
    "wrist_torque_limit_nm": [Interval(0, 1e6, "right", "N m")],
    "finger_stiffness_n_per_m": [Interval(0, 1e9, "right", "N/m")],
    "finger_damping_ns_per_m": [Interval(0, 1e9, unit="N s/m")],
    "coupling_stiffness_n_per_m": [Interval(0, 1e9, "right", "N/m")],
    "coupling_damping_ns_per_m": [Interval(0, 1e9, unit="N s/m")],
    "close_past_m": [Interval(0, 0.5, unit="m")],
    "close_force_margin": [Interval(1, 100)],
    "urdf": [None, *TEXT],
    "urdf_palm_link": [None, *TEXT],
    "urdf_finger_joints": [None, Names()],
    "urdf_approach_axis": [Vector(3, Interval(-1, 1))],
    "urdf_tcp_m": [None, Vector(3, Interval(-1, 1, unit="m"))],
}
"""Allowed values of every key (see :mod:`graspexp.config.constraints`)."""
