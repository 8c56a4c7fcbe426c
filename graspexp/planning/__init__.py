"""Grasp planning: pure numpy, no simulator import.

``plan(req)`` dispatches on ``req.planner.name`` to the installed planner plugin of that name
(:mod:`graspexp.planning.registry`); ``optimal`` is the paper's strategy (section III,
:mod:`graspexp.planning.optimal`).
"""

from graspexp.planning.grasp import Grasp, NoFeasibleGrasp
from graspexp.planning.optimal import plan_optimal
from graspexp.planning.registry import (
    Planner,
    UnknownPlanner,
    get_planner,
    get_scene_planner,
    plan,
    plan_scene,
)
from graspexp.planning.request import PlanRequest, PlanResult
from graspexp.planning.scene import SceneRequest, SceneResult, TargetPlan

__all__ = [
    "Grasp",
    "NoFeasibleGrasp",
    "PlanRequest",
    "PlanResult",
    "Planner",
    "SceneRequest",
    "SceneResult",
    "TargetPlan",
    "UnknownPlanner",
    "get_planner",
    "get_scene_planner",
    "plan",
    "plan_optimal",
    "plan_scene",
]
