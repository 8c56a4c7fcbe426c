"""Schema of the ``gripper`` config group: a parallel-jaw gripper, all lengths in metres.

Gripper frame (paper Fig. 9): +Z approach, +Y closing axis, origin midway between the finger pads.
"""

from dataclasses import dataclass

from omegaconf import MISSING

from graspexp.config.constraints import TEXT, Interval, Vector


@dataclass
class GripperConfig:
    name: str = MISSING
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


def finger_z_range_m(g: GripperConfig) -> tuple[float, float]:
    """(z_min, z_max) of the fingers along the approach axis in the gripper frame, m: from the palm face
    (z_min, where the palm box starts and extends further back by palm_size_m[2]) to the tips (z_max)."""
    return g.tcp_from_tip_m - g.finger_length_m, g.tcp_from_tip_m


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
}
"""Allowed values of every key (see :mod:`graspexp.config.constraints`)."""
