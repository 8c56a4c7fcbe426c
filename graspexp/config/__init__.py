"""Structured Hydra configs: one schema dataclass per config group, registered in the ConfigStore.

Every YAML option under ``conf/<group>/`` lists its schema (``/schema_<group>@_here_``; for a planner
``/schema_planner_<planner name>@_here_``, from its plugin) first in its defaults, so Hydra type-checks
every option and rejects unknown keys. The schemas are stored outside the groups, so none is an option. Nothing here imports Hydra (only :func:`register_configs` does, when called).
"""

from graspexp.config.constraints import BEFORE, added
from graspexp.config.cost import CostConfig
from graspexp.config.dataset import DatasetConfig
from graspexp.config.gripper import GripperConfig
from graspexp.config.job import JobConfig
from graspexp.config.mode import ModeConfig
from graspexp.config.perception import CameraConfig, PerceptionConfig, PoseNoiseConfig
from graspexp.config.planner import (
    BASE_CONSTRAINTS,
    AntipodalConfig,
    ObbConfig,
    OptimalConfig,
    OptimalPlusConfig,
    PlannerConfig,
    RandomConfig,
)
from graspexp.config.plugins import Learned, PlannerPlugin, PluginError
from graspexp.config.registry import register_configs
from graspexp.config.rot import RotConfig
from graspexp.config.sim import SimConfig
from graspexp.config.validate import ConfigError, validate

__all__ = [
    "BEFORE",
    "added",
    "BASE_CONSTRAINTS",
    "AntipodalConfig",
    "CameraConfig",
    "Learned",
    "ObbConfig",
    "OptimalConfig",
    "OptimalPlusConfig",
    "PlannerPlugin",
    "PluginError",
    "RandomConfig",
    "ConfigError",
    "CostConfig",
    "DatasetConfig",
    "GripperConfig",
    "JobConfig",
    "ModeConfig",
    "PerceptionConfig",
    "PlannerConfig",
    "PoseNoiseConfig",
    "RotConfig",
    "SimConfig",
    "register_configs",
    "validate",
]
