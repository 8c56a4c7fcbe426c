"""The fields every planner's schema shares, and the base classes of the built-in planners' schemas.

A planner's schema is a dataclass deriving from :class:`PlannerConfig` (directly or through one of the
classes here); its constraints mapping (``CONSTRAINTS`` beside it) covers every field, inherited ones
included, so that ``{**BASE_CONSTRAINTS, ...}`` is the usual way to write it.
"""

from dataclasses import dataclass, field

from omegaconf import MISSING

from graspexp.config.constraints import TEXT, Interval, Options, Vector, added


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


@dataclass
class AreaRuleConfig(PlannerConfig):
    """Planners that check where their pads touch: each pad's contact points (the cloud points within
    ``contact_band_m`` of the section's extreme between the pads) must be grasping-area points
    (:func:`graspexp.planning.stability.pad_contacts`, :mod:`graspexp.planning.area_rule`)."""

    min_contacts_in_area: float = 0.0
    """Share of each pad's contact points that must be grasping-area points (III-A: the robot grasps the
    area, not the part a person holds); 0: not checked. Fingers 8 cm long can close on another part
    first (the iron's handle above its body), so aiming at area points is not enough."""
    fallback_contacts_in_area: float = added(0.0, before=1.0)
    """In the modes of ``fallback_modes``, when no grasp passes with ``min_contacts_in_area``, the search
    is repeated requiring the largest share any otherwise passing try reached, if at least this (1.0:
    no fallback; the grasp's ``extras["in_area_required"]`` records the share required). Some poses
    leave no grasp inside the area: the cat on its side closes on its legs or head whatever the path
    (the best try's share is 0-0.14), the iron on its side on the soleplate or the handle. 0: the grasp
    touching the area most, rather than none; the in-area metric reports every such trial."""
    fallback_modes: list[str] = field(default_factory=lambda: ["bin"])
    """Modes in which the fallback applies. ``bin``: nobody holds the object, the area is the task's
    preference (III-A), and a pick outside it beats no pick. Not ``collab``: there a person holds the
    rest of the object (IV-C, hand-over), so a grasp outside the area would take their hand; none is
    planned."""
    contact_band_m: float = 0.004
    """Points within this of a side's extreme y count as that pad's contacts, m: about the cloud's point
    spacing (2048 points on a Table 1 object)."""


AREA_RULE_CONSTRAINTS = {
    **BASE_CONSTRAINTS,
    "min_contacts_in_area": [Interval(0, 1)],
    "fallback_contacts_in_area": [Interval(0, 1)],
    "fallback_modes": [Vector(None, Options(("collab", "bin")))],
    "contact_band_m": [Interval(0, 0.05, "right", "m")],
}
"""Allowed values of the keys of :class:`AreaRuleConfig`."""


@dataclass
class AreaContactConfig(AreaRuleConfig, OpeningConfig):
    """Planners that open to the section, check collisions and apply the area rule of
    :class:`AreaRuleConfig` (antipodal, optimal_plus)."""


AREA_CONTACT_CONSTRAINTS = {**OPENING_CONSTRAINTS, **AREA_RULE_CONSTRAINTS}
