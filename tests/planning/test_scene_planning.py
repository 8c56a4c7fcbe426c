"""The scene-level planner entry (:mod:`graspexp.planning.scene`): a per-object planner keeps working
through the adapter, a plugin's ``plan_scene`` is used when it has one, and the planner's name is filled
in either way."""

import dataclasses

import numpy as np
import pytest

from graspexp.config.planner.base import PlannerConfig
from graspexp.config.plugins import LoadedPlanner, PlannerPlugin
from graspexp.planning import registry
from graspexp.planning.grasp import Grasp, NoFeasibleGrasp
from graspexp.planning.request import PlanRequest, PlanResult
from graspexp.planning.scene import SceneRequest, SceneResult, TargetPlan, per_object


def _request(i: int, name: str = "optimal") -> PlanRequest:
    return PlanRequest(
        points=np.zeros((1, 3)) + i, normals=np.zeros((1, 3)), area_mask=np.ones(1, bool),
        object_pose=np.eye(4), table_z=0.1, mode="bin", gripper=None, planner=PlannerConfig(name=name),
        cost=None, seed=i,
    )  # fmt: skip


def _grasp_unless_odd(req: PlanRequest) -> PlanResult:
    """A grasp of cost = the target's index for even targets; none for odd ones."""
    i = int(req.points[0, 0])
    if i % 2:
        raise NoFeasibleGrasp(f"target {i}: none")
    return PlanResult(Grasp(pose=np.eye(4), width_m=0.05, cost=float(i)))


@pytest.mark.parametrize("first_found", [False, True])
def test_the_adapter_plans_each_target_in_order(first_found):
    req = SceneRequest(tuple(_request(i) for i in (1, 2, 3, 4)), (1, 2, 3, 4), first_found=first_found)
    res = per_object(_grasp_unless_odd)(req)
    expected = [1, 2] if first_found else [1, 2, 3, 4]  # up to the first grasp found
    assert [tp.index for tp in res.plans] == [i - 1 for i in expected]
    assert [tp.grasp is not None for tp in res.plans] == [i % 2 == 0 for i in expected]
    assert res.plans[0].reason == "target 1: none" and res.plans[1].reason == ""


def _fake_plugin(monkeypatch, **fields):
    plugin = PlannerPlugin(plan=_grasp_unless_odd, config=PlannerConfig, constraints={"name": []}, **fields)
    found = LoadedPlanner("fake", "fake 0.1", "fake:PLUGIN", plugin)
    monkeypatch.setattr(registry, "get_plugin", lambda name: found)
    registry.get_planner.cache_clear()
    registry.get_scene_planner.cache_clear()
    monkeypatch.setattr(registry, "plan", lambda req: _grasp_unless_odd(req))


def test_a_planner_without_plan_scene_is_planned_target_by_target(monkeypatch):
    _fake_plugin(monkeypatch)
    res = registry.plan_scene(SceneRequest(tuple(_request(i, "fake") for i in (2, 3)), (1, 2)))
    assert [tp.grasp is not None for tp in res.plans] == [True, False]
    assert res.plans[0].grasp.planner == "fake"  # the name filled in, as plan() does
    registry.get_scene_planner.cache_clear()


def test_a_plugins_plan_scene_is_called_once_for_the_scene(monkeypatch):
    calls = []

    def whole_scene(req: SceneRequest) -> SceneResult:
        calls.append(len(req.targets))
        grasp = Grasp(pose=np.eye(4), width_m=0.04, cost=0.5)
        return SceneResult(tuple(TargetPlan(i, PlanResult(grasp)) for i in range(len(req.targets))))

    _fake_plugin(monkeypatch, plan_scene=whole_scene)
    res = registry.plan_scene(SceneRequest(tuple(_request(i, "fake") for i in (1, 3, 5)), (1, 2, 3)))
    assert calls == [3] and all(tp.grasp.planner == "fake" for tp in res.plans)
    registry.get_scene_planner.cache_clear()


def test_a_scene_planner_that_returns_something_else_is_refused(monkeypatch):
    _fake_plugin(monkeypatch, plan_scene=lambda req: [])
    with pytest.raises(TypeError, match="expected a graspexp SceneResult"):
        registry.plan_scene(SceneRequest((_request(0, "fake"),), (1,)))
    registry.get_scene_planner.cache_clear()


def test_touching_a_neighbour_is_a_typed_field_of_the_grasp():
    grasp = Grasp(pose=np.eye(4), width_m=0.05)
    assert grasp.touches_neighbours is False and "touches_neighbours" not in grasp.extras
    assert dataclasses.replace(grasp, touches_neighbours=True).touches_neighbours
