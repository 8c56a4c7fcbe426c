"""Schema of the random baseline (a lower bound), graspexp/planning/random_grasp.py."""

from dataclasses import dataclass

from graspexp.config.constraints import Interval
from graspexp.config.planner.base import COLLISION_CONSTRAINTS, CollisionConfig
from graspexp.config.plugins import PlannerPlugin


@dataclass
class RandomConfig(CollisionConfig):
    n_candidates: int = 256
    """Draws before giving up."""


CONSTRAINTS = {**COLLISION_CONSTRAINTS, "n_candidates": [Interval(1, 1_000_000, integer=True)]}
"""Allowed values of every key of :class:`RandomConfig` (see :mod:`graspexp.config.constraints`)."""

PLUGIN = PlannerPlugin(
    plan="graspexp.planning.random_grasp:plan_random", config=RandomConfig, constraints=CONSTRAINTS
)
"""Entry point of the built-in planner (graspexp's ``pyproject.toml``)."""
