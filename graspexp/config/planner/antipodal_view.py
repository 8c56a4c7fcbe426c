"""Schema of the view-based antipodal planner (GPD's class of method), graspexp/planning/antipodal_view.py."""

from dataclasses import dataclass

from graspexp.config.constraints import Interval
from graspexp.config.planner.base import OPENING_CONSTRAINTS, OpeningConfig
from graspexp.config.plugins import PlannerPlugin


@dataclass
class AntipodalViewConfig(OpeningConfig):
    n_candidates: int = 256
    """Observed target points sampled as the first contact."""
    n_approach: int = 8
    """Approach directions tried about each seed's closing axis (evenly spaced)."""
    friction_coef: float = 0.5
    """Friction coefficient mu of the contacts' cone, half-angle atan(mu) (dimensionless; antipodal's)."""
    unseen_side_deg: float = 30.0
    """Cost of a far contact the camera did not see, degrees (on the scale of the contact angles): above
    any observed antipodal contact inside the cone (26.6 deg at mu = 0.5), so a grasp whose both contacts
    were seen wins, yet a grasp of a one-sided view is still made, as GPD makes it."""
    approach_tilt_weight: float = 0.1
    """Cost per degree between the approach and straight down, added to the contact angle (degrees)."""
    contact_band_m: float = 0.004
    """Observed points within this of a side's extreme between the pads count as that pad's contact, m
    (about the cloud's spacing: 2.7 mm per pixel at 0.6 m with the d435 preset)."""
    min_points: int = 20
    """Fewest observed target points to plan on; fewer: no feasible grasp."""


CONSTRAINTS = {
    **OPENING_CONSTRAINTS,
    "n_candidates": [Interval(1, 1_000_000, integer=True)],
    "n_approach": [Interval(1, 3600, integer=True)],
    "friction_coef": [Interval(0, 10, "right")],
    "unseen_side_deg": [Interval(0, 180, unit="deg")],
    "approach_tilt_weight": [Interval(0, 100)],
    "contact_band_m": [Interval(0, 0.05, "right", "m")],
    "min_points": [Interval(1, 1_000_000, integer=True)],
}
"""Allowed values of every key of :class:`AntipodalViewConfig` (see :mod:`graspexp.config.constraints`)."""

PLUGIN = PlannerPlugin(
    plan="graspexp.planning.antipodal_view:plan_antipodal_view",
    config=AntipodalViewConfig,
    constraints=CONSTRAINTS,
    needs_observation=True,
)
"""Entry point of ``antipodal_view``: it reads the camera's cloud (``needs_observation``)."""
