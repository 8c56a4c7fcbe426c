"""Planners chosen by name: ``planner.name`` in the config is the key of :data:`PLANNERS`.

Every planner is a pure function ``PlanRequest -> PlanResult``. Add one with
``register_planner("name", fn)`` (or ``PLANNERS["name"] = fn``) from the module that defines it.
"""

from collections.abc import Callable

from graspexp.planning.optimal import LITERAL_NAME as OPTIMAL_LITERAL_NAME
from graspexp.planning.optimal import NAME as OPTIMAL_NAME
from graspexp.planning.optimal import plan_optimal
from graspexp.planning.request import PlanRequest, PlanResult

Planner = Callable[[PlanRequest], PlanResult]

PLANNERS: dict[str, Planner] = {OPTIMAL_NAME: plan_optimal, OPTIMAL_LITERAL_NAME: plan_optimal}


class UnknownPlanner(KeyError):
    """``planner.name`` names no registered planner."""

    def __str__(self) -> str:  # KeyError would quote the whole message
        return str(self.args[0])


def register_planner(name: str, fn: Planner) -> Planner:
    """Register ``fn`` under ``name`` (a name may be registered once); returns ``fn``."""
    if name in PLANNERS and PLANNERS[name] is not fn:
        raise ValueError(f"planner {name!r} is already registered")
    PLANNERS[name] = fn
    return fn


def get_planner(name: str) -> Planner:
    """The planner registered as ``name``; an unknown name raises :class:`UnknownPlanner` listing the valid ones."""
    try:
        return PLANNERS[name]
    except KeyError:
        valid = ", ".join(sorted(PLANNERS))
        raise UnknownPlanner(f"planner.name={name!r} is unknown: expected one of {valid}") from None


def plan(req: PlanRequest) -> PlanResult:
    """Dispatch on ``req.planner.name``."""
    return get_planner(req.planner.name)(req)


# Baselines and the improved planner (graspexp/planning/{antipodal,obb,random_grasp,optimal_plus}.py).
from graspexp.planning.antipodal import NAME as ANTIPODAL_NAME  # noqa: E402
from graspexp.planning.antipodal import plan_antipodal  # noqa: E402
from graspexp.planning.obb import NAME as OBB_NAME  # noqa: E402
from graspexp.planning.obb import plan_obb  # noqa: E402
from graspexp.planning.optimal_plus import NAME as OPTIMAL_PLUS_NAME  # noqa: E402
from graspexp.planning.optimal_plus import plan_optimal_plus  # noqa: E402
from graspexp.planning.random_grasp import NAME as RANDOM_NAME  # noqa: E402
from graspexp.planning.random_grasp import plan_random  # noqa: E402

for _name, _fn in (
    (ANTIPODAL_NAME, plan_antipodal),
    (OBB_NAME, plan_obb),
    (RANDOM_NAME, plan_random),
    (OPTIMAL_PLUS_NAME, plan_optimal_plus),
):
    register_planner(_name, _fn)
