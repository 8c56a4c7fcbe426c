"""Schema of the ``mode`` config group: collaborative hand-over or bin picking (paper IV-A, IV-C)."""

from dataclasses import dataclass

from omegaconf import MISSING

from graspexp.config.constraints import BOOL, Interval, Options, Vector


@dataclass
class ModeConfig:
    name: str = MISSING
    """``collab`` (Eq. 1; box removed after the grasp) or ``bin`` (Eq. 2-3; table, pull back)."""
    support_height_m: float = 0.10
    """Height of the support's top face above the ground plane, m (the plane z = h)."""
    support_half_size_m: list[float] = MISSING
    """Half extents [x, y] of the support top, m. The paper gives no size for its box; every one of its
    trials is a grasp of an object resting on it (IV-C), so the box must hold every dropped object. The
    collab box is 0.3 m wide, longer than the longest Table 1/2 object (LINEMOD iron 258 mm): a 0.2 m box
    let the driller (229 mm) fall off in 37 of 47 XYZ drops, 5 of its 10 trials even after 5 re-drops;
    0.3 m: 3 of 13 drops, no trial lost. The bin table is 0.8 m."""
    support_collides_with_gripper: bool = MISSING
    """False in collab mode (paper IV-A: the box is not used for gripper collisions)."""
    remove_support_after_grasp: bool = MISSING
    """True in collab mode: the box vanishes after the fingers close."""
    pull_back_m: float = 0.0
    """Bin mode: distance to retract along the approach direction after closing, m."""
    lift_m: float = 0.0
    """Bin mode: extra lift along world +Z after the pull back, m."""
    hold_s: float = 2.0
    """Time the grasp must hold at the end, s."""


CONSTRAINTS = {
    "name": [Options(("collab", "bin"))],
    "support_height_m": [Interval(0, 2, "right", "m")],
    "support_half_size_m": [Vector(2, Interval(0, 5, "right", "m"))],
    "support_collides_with_gripper": BOOL,
    "remove_support_after_grasp": BOOL,
    "pull_back_m": [Interval(0, 2, unit="m")],
    "lift_m": [Interval(0, 2, unit="m")],
    "hold_s": [Interval(0, 60, "right", "s")],
}
"""Allowed values of every key (see :mod:`graspexp.config.constraints`)."""
