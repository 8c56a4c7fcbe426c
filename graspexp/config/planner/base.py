"""The fields every planner's schema shares, and the base classes of the built-in planners' schemas.

A planner's schema is a dataclass deriving from :class:`PlannerConfig` (directly or through one of the
classes here); its constraints mapping (``CONSTRAINTS`` beside it) covers every field, inherited ones
included, so that ``{**BASE_CONSTRAINTS, ...}`` is the usual way to write it.
"""

from dataclasses import dataclass

from omegaconf import MISSING

from graspexp.config.constraints import TEXT, Interval


@dataclass
class PlannerConfig:
    """What every planner has: its registry name, the cloud it is given and the pre-grasp standoff."""

    name: str = MISSING
    """Planner registry key: an entry-point name of the ``graspexp.planners`` group (``optimal`` and
    ``optimal_literal`` are the paper's, read two ways)."""
    sphere_radius_m: float = 0.10
    """Radius of the Fibonacci sphere around each centre = pre-grasp standoff, m. The paper gives none;
    0.1 m clears the largest Table 1/2 object's half-extent from a cluster centre."""
    n_points: int = 2048
    """Size N of the object's surface point cloud (Eq. (1) sums over it). The paper gives none; 2048 points
    is about one per 5 mm^2 on the Table 1 objects, below the 10 mm scale of Eq. (1)'s distance term."""


BASE_CONSTRAINTS = {
    "name": TEXT,
    "sphere_radius_m": [Interval(0, 2, "right", "m")],
    "n_points": [Interval(16, 10_000_000, integer=True)],
}
"""Allowed values of the shared keys (see :mod:`graspexp.config.constraints`)."""


@dataclass
class CollisionConfig(PlannerConfig):
    """Planners that test the finger and palm boxes against the cloud and the support plane."""

    collision_margin_m: float = 0.002
    """Clearance the finger and palm boxes keep from cloud points and from the support plane, m."""


COLLISION_CONSTRAINTS = {**BASE_CONSTRAINTS, "collision_margin_m": [Interval(0, 0.1, unit="m")]}


@dataclass
class OpeningConfig(CollisionConfig):
    """Planners that open to the object's section between the pads plus a clearance."""

    width_clearance_m: float = 0.005
    """obb, antipodal, optimal_plus: opening = 2 * (largest |y| of the object between the pads) + 2 * this, m."""


OPENING_CONSTRAINTS = {**COLLISION_CONSTRAINTS, "width_clearance_m": [Interval(0, 0.1, unit="m")]}
