"""Planners chosen by name: ``planner.name`` is the entry-point name of an installed planner plugin.

Every planner is a pure function ``PlanRequest -> PlanResult``. Planners (the built-in ones too) are
discovered through the ``graspexp.planners`` entry-point group (:mod:`graspexp.config.plugins`); the
function of a plugin that gives it as ``"module:function"`` is imported here, on first use.
"""

import dataclasses
import functools
import importlib
from collections.abc import Callable

from graspexp.config.plugins import PluginError, get_plugin
from graspexp.planning.request import PlanRequest, PlanResult

Planner = Callable[[PlanRequest], PlanResult]


class UnknownPlanner(PluginError, KeyError):
    """``planner.name`` names no installed planner, or one whose plugin cannot be loaded."""

    def __str__(self) -> str:  # KeyError would quote the whole message
        return str(self.args[0])


@functools.cache
def get_planner(name: str) -> Planner:
    """The plan function of the planner called ``name``; :class:`UnknownPlanner` (one line naming the
    valid names, or the broken plugin's package) otherwise."""
    try:
        found = get_plugin(name)
    except PluginError as exc:
        raise UnknownPlanner(str(exc)) from None
    fn = found.plugin.plan
    if isinstance(fn, str):
        module, _, attr = fn.partition(":")
        try:
            fn = getattr(importlib.import_module(module), attr)
        except (ImportError, AttributeError) as exc:
            raise UnknownPlanner(
                f"planner {name!r} of {found.package}: its plan function {found.plugin.plan} cannot be "
                f"imported: {type(exc).__name__}: {exc}"
            ) from None
    return fn


def plan(req: PlanRequest) -> PlanResult:
    """Dispatch on ``req.planner.name``; a grasp without a planner name gets ``req.planner.name``."""
    name = req.planner.name
    res = get_planner(name)(req)
    if not isinstance(res, PlanResult):
        raise TypeError(f"planner {name!r} returned a {type(res).__name__}: expected a graspexp PlanResult")
    if not res.grasp.planner:
        res = dataclasses.replace(res, grasp=dataclasses.replace(res.grasp, planner=name))
    return res
