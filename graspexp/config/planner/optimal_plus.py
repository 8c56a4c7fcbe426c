"""Schema of ``optimal_plus`` (graspexp/planning/optimal_plus.py): the paper's paths, a swept collision
check, a geometric opening and a centre-of-mass preference."""

from dataclasses import dataclass

from graspexp.config.constraints import Interval
from graspexp.config.planner.base import OPENING_CONSTRAINTS, OpeningConfig
from graspexp.config.planner.optimal import PAPER_PATHS_CONSTRAINTS, PaperPathsConfig
from graspexp.config.plugins import PlannerPlugin


@dataclass
class OptimalPlusConfig(PaperPathsConfig, OpeningConfig):
    com_weight: float = 1.0
    """optimal_plus: cost factor (1 + com_weight * |c_k - centroid| / object size); 0 switches it off."""


CONSTRAINTS = {**PAPER_PATHS_CONSTRAINTS, **OPENING_CONSTRAINTS, "com_weight": [Interval(0, 100)]}
"""Allowed values of every key of :class:`OptimalPlusConfig` (see :mod:`graspexp.config.constraints`)."""

PLUGIN = PlannerPlugin(
    plan="graspexp.planning.optimal_plus:plan_optimal_plus", config=OptimalPlusConfig, constraints=CONSTRAINTS
)
"""Entry point of the built-in planner (graspexp's ``pyproject.toml``)."""
