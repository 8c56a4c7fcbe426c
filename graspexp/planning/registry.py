"""Planners chosen by name: ``planner.name`` is the entry-point name of an installed planner plugin.

Every planner is a pure function ``PlanRequest -> PlanResult``; a planner that sees a whole scene at once
may also provide ``plan_scene`` (``SceneRequest -> SceneResult``, :mod:`graspexp.planning.scene`), and every
other one is planned target by target through :func:`graspexp.planning.scene.per_object`. Planners (the
built-in ones too) are discovered through the ``graspexp.planners`` entry-point group
(:mod:`graspexp.config.plugins`); a function a plugin gives as ``"module:function"`` is imported here, on
first use.
"""

import dataclasses
import functools
import importlib
from collections.abc import Callable

from graspexp.config.plugins import PluginError, get_plugin
from graspexp.planning.request import PlanRequest, PlanResult
from graspexp.planning.scene import ScenePlanner, SceneRequest, SceneResult, TargetPlan, per_object

Planner = Callable[[PlanRequest], PlanResult]


class UnknownPlanner(PluginError, KeyError):
    """``planner.name`` names no installed planner, or one whose plugin cannot be loaded."""

    def __str__(self) -> str:  # KeyError would quote the whole message
        return str(self.args[0])


def _resolve(name: str, package: str, what: str, fn: Callable | str) -> Callable:
    """``fn``, or the function its ``"module:function"`` names, imported now."""
    if not isinstance(fn, str):
        return fn
    module, _, attr = fn.partition(":")
    try:
        return getattr(importlib.import_module(module), attr)
    except (ImportError, AttributeError) as exc:
        raise UnknownPlanner(
            f"planner {name!r} of {package}: its {what} function {fn} cannot be imported: "
            f"{type(exc).__name__}: {exc}"
        ) from None


def _plugin(name: str):
    try:
        return get_plugin(name)
    except PluginError as exc:
        raise UnknownPlanner(str(exc)) from None


@functools.cache
def get_planner(name: str) -> Planner:
    """The plan function of the planner called ``name``; :class:`UnknownPlanner` (one line naming the
    valid names, or the broken plugin's package) otherwise."""
    found = _plugin(name)
    return _resolve(name, found.package, "plan", found.plugin.plan)


@functools.cache
def get_scene_planner(name: str) -> ScenePlanner:
    """The scene planner of the planner called ``name``: its plugin's ``plan_scene``, else its ``plan``
    target by target (:func:`graspexp.planning.scene.per_object`)."""
    found = _plugin(name)
    if found.plugin.plan_scene is None:
        return per_object(plan)
    return _resolve(name, found.package, "plan_scene", found.plugin.plan_scene)


def plan(req: PlanRequest) -> PlanResult:
    """Dispatch on ``req.planner.name``; a grasp without a planner name gets ``req.planner.name``."""
    name = req.planner.name
    res = get_planner(name)(req)
    if not isinstance(res, PlanResult):
        raise TypeError(f"planner {name!r} returned a {type(res).__name__}: expected a graspexp PlanResult")
    if not res.grasp.planner:
        res = dataclasses.replace(res, grasp=dataclasses.replace(res.grasp, planner=name))
    return res


def plan_scene(req: SceneRequest) -> SceneResult:
    """Dispatch a scene on its planner's name (every target's request names the same planner); a grasp
    without a planner name gets it, as :func:`plan` does."""
    if not req.targets:
        return SceneResult(())
    name = req.targets[0].planner.name
    res = get_scene_planner(name)(req)
    if not isinstance(res, SceneResult):
        raise TypeError(f"planner {name!r} returned a {type(res).__name__}: expected a graspexp SceneResult")
    plans = []
    for tp in res.plans:
        if tp.result is not None and not tp.result.grasp.planner:
            grasp = dataclasses.replace(tp.result.grasp, planner=name)
            tp = TargetPlan(tp.index, dataclasses.replace(tp.result, grasp=grasp), tp.reason)
        plans.append(tp)
    return SceneResult(tuple(plans))
