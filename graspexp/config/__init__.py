"""Structured Hydra configs: one schema dataclass per config group, registered in the ConfigStore.

Every YAML option under ``conf/<group>/`` lists its schema (``base_<group>``) first in its defaults,
so Hydra type-checks every option and rejects unknown keys.
"""

from graspexp.config.dataset import DatasetConfig
from graspexp.config.gripper import GripperConfig
from graspexp.config.job import JobConfig, PerceptionConfig, PoseNoiseConfig
from graspexp.config.mode import ModeConfig
from graspexp.config.planner import CostConfig, PlannerConfig
from graspexp.config.registry import register_configs
from graspexp.config.rot import RotConfig
from graspexp.config.sim import SimConfig
from graspexp.config.validate import ConfigError, validate

__all__ = [
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
