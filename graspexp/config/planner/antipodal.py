"""Schema of the antipodal sampling baseline (GPD / PointNetGPD style), graspexp/planning/antipodal.py."""

from dataclasses import dataclass

from graspexp.config.constraints import BOOL, Interval
from graspexp.config.planner.base import AREA_CONTACT_CONSTRAINTS, AreaContactConfig
from graspexp.config.plugins import PlannerPlugin


@dataclass
class AntipodalConfig(AreaContactConfig):
    n_candidates: int = 256
    """First-contact points sampled."""
    n_approach: int = 12
    """Approach directions tried about each contact pair's line (evenly spaced)."""
    friction_coef: float = 0.5
    """Friction coefficient mu of the sampling cone, half-angle atan(mu) (dimensionless)."""
    sample_area_only: bool = False
    """Both contacts from the grasping area (preset ``antipodal_area``); False: from the whole cloud, as
    GPD. The pads may still close on another part first; preset ``antipodal_area_pads`` adds
    ``min_contacts_in_area`` 1.0, the area rule ``optimal_plus`` follows."""
    fallback_contacts_in_area: float = 0.0
    """As :class:`AreaContactConfig`. Declared here without a value before it: runs made before the key
    existed checked no pad contacts (``min_contacts_in_area`` 0), where the fallback changes nothing."""
    approach_tilt_weight: float = 0.1
    """Cost per degree between the approach and straight down, added to the contacts' worst
    friction-cone angle (degrees), so top-down approaches win among equally antipodal pairs."""


CONSTRAINTS = {
    **AREA_CONTACT_CONSTRAINTS,
    "n_candidates": [Interval(1, 1_000_000, integer=True)],
    "n_approach": [Interval(1, 3600, integer=True)],
    "friction_coef": [Interval(0, 10)],
    "sample_area_only": BOOL,
    "approach_tilt_weight": [Interval(0, 100)],
}
"""Allowed values of every key of :class:`AntipodalConfig` (see :mod:`graspexp.config.constraints`)."""

PLUGIN = PlannerPlugin(
    plan="graspexp.planning.antipodal:plan_antipodal", config=AntipodalConfig, constraints=CONSTRAINTS
)
"""Entry point of ``antipodal``, ``antipodal_area`` and ``antipodal_area_pads`` (one function, three presets)."""
