"""A planner's entry for a whole scene: every object on the support at once (a clutter round's attempt).

VGN's shape (ethz-asl/vgn ``grasp_plan_fn(state)``): the scene's observation and objects in, grasps per
target out. A planner that fuses and infers once per scene (``vgn``) provides ``plan_scene`` in its plugin;
every other planner keeps its per-object ``plan`` and is planned target by target through
:func:`per_object` (what the round loop did before, request for request: the same grasps).
"""

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from graspexp.perception.observation import Observation
from graspexp.planning.grasp import Grasp, NoFeasibleGrasp
from graspexp.planning.request import PlanRequest, PlanResult


@dataclass(frozen=True)
class SceneRequest:
    """One planning call for a scene.

    targets : one request per object to plan for, in the order to plan them; each holds its target's cloud at
        its perceived pose, the other objects as :attr:`PlanRequest.neighbours` and (with a camera) the scene's
        observation with ``target_id`` naming it. The scene-wide fields (table, gripper, planner, cost,
        workspace) are the same in every target's request.
    ids : (len(targets),) the object id of each target in the observation's id images (its slot + 1).
    first_found : stop after the first target a grasp is found for (``mode.pick_order=top_most``); False:
        plan every target.
    observation : what the camera saw of the whole scene (``target_id`` 0), or None without a camera.
    """

    targets: tuple[PlanRequest, ...]
    ids: tuple[int, ...]
    first_found: bool = False
    observation: Observation | None = None

    @property
    def workspace_xy(self) -> np.ndarray | None:
        """(2, 2) the scene's workspace (:attr:`PlanRequest.workspace_xy`), world m."""
        return self.targets[0].workspace_xy if self.targets else None


@dataclass(frozen=True)
class TargetPlan:
    """The outcome of planning for one target of a :class:`SceneRequest`.

    index : the target's index in :attr:`SceneRequest.targets`. result : the plan, or None when no grasp was
    found for it (``reason`` says why, one line).
    """

    index: int
    result: PlanResult | None
    reason: str = ""

    @property
    def grasp(self) -> Grasp | None:
        return None if self.result is None else self.result.grasp


@dataclass(frozen=True)
class SceneResult:
    """Every target planned, in the order planned (with ``first_found``: up to the first grasp found)."""

    plans: tuple[TargetPlan, ...]


ScenePlanner = Callable[[SceneRequest], SceneResult]
"""A scene planner: grasps per target for a scene request."""


def per_object(plan: Callable[[PlanRequest], PlanResult]) -> ScenePlanner:
    """The scene planner that plans each target alone with ``plan`` (a per-object planner), in order; a
    :class:`NoFeasibleGrasp` is that target's reason."""

    def plan_scene(req: SceneRequest) -> SceneResult:
        plans = []
        for i, target in enumerate(req.targets):
            try:
                plans.append(TargetPlan(i, plan(target)))
            except NoFeasibleGrasp as exc:
                plans.append(TargetPlan(i, None, str(exc)))
                continue
            if req.first_found:
                break
        return SceneResult(tuple(plans))

    return plan_scene


def timed(plan_scene: ScenePlanner, req: SceneRequest) -> tuple[SceneResult, float, float]:
    """``plan_scene(req)`` with its wall time and the CPU time of the calling thread, s."""
    t0, c0 = time.perf_counter(), time.thread_time()
    result = plan_scene(req)
    return result, time.perf_counter() - t0, time.thread_time() - c0
