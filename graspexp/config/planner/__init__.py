"""One schema per planner (``planner`` config group), each with its constraints beside it.

:class:`PlannerConfig` holds what every planner has; each built-in planner's module derives its schema
from it and exposes a ``PLUGIN`` (:class:`graspexp.config.plugins.PlannerPlugin`) that graspexp's
``pyproject.toml`` registers under the ``graspexp.planners`` entry-point group, as a third-party planner
package does.
"""

from graspexp.config.planner.antipodal import AntipodalConfig
from graspexp.config.planner.base import BASE_CONSTRAINTS, PlannerConfig
from graspexp.config.planner.obb import ObbConfig
from graspexp.config.planner.optimal import OptimalConfig
from graspexp.config.planner.optimal_plus import OptimalPlusConfig
from graspexp.config.planner.random_grasp import RandomConfig

__all__ = [
    "BASE_CONSTRAINTS",
    "AntipodalConfig",
    "ObbConfig",
    "OptimalConfig",
    "OptimalPlusConfig",
    "PlannerConfig",
    "RandomConfig",
]
