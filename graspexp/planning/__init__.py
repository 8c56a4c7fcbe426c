"""Grasp planning: pure numpy, no simulator import.

``plan(req)`` dispatches on ``req.planner.name`` through :data:`PLANNERS`; ``optimal`` is the paper's
strategy (section III, :mod:`graspexp.planning.optimal`).
"""

from graspexp.planning.grasp import Grasp, NoFeasibleGrasp
from graspexp.planning.optimal import plan_optimal
from graspexp.planning.registry import PLANNERS, UnknownPlanner, get_planner, plan, register_planner
from graspexp.planning.request import PlanRequest, PlanResult

__all__ = [
    "PLANNERS",
    "Grasp",
    "NoFeasibleGrasp",
    "PlanRequest",
    "PlanResult",
    "UnknownPlanner",
    "get_planner",
    "plan",
    "plan_optimal",
    "register_planner",
]
