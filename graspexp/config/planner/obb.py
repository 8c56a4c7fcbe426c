"""Schema of the bounding-box baseline (top-down across the narrower side), graspexp/planning/obb.py."""

from dataclasses import dataclass

from graspexp.config.planner.base import OPENING_CONSTRAINTS, OpeningConfig
from graspexp.config.plugins import PlannerPlugin


@dataclass
class ObbConfig(OpeningConfig):
    """No keys beyond the opening clearance and the collision margin."""


CONSTRAINTS = dict(OPENING_CONSTRAINTS)
"""Allowed values of every key of :class:`ObbConfig` (see :mod:`graspexp.config.constraints`)."""

PLUGIN = PlannerPlugin(plan="graspexp.planning.obb:plan_obb", config=ObbConfig, constraints=CONSTRAINTS)
"""Entry point of the built-in planner (graspexp's ``pyproject.toml``)."""
