"""Registers every schema in Hydra's ConfigStore (``base_<group>`` in each group)."""

from hydra.core.config_store import ConfigStore

from graspexp.config.dataset import DatasetConfig
from graspexp.config.gripper import GripperConfig
from graspexp.config.job import JobConfig
from graspexp.config.mode import ModeConfig
from graspexp.config.planner import CostConfig, PlannerConfig
from graspexp.config.rot import RotConfig
from graspexp.config.sim import SimConfig

SCHEMAS = {
    "dataset": DatasetConfig,
    "gripper": GripperConfig,
    "mode": ModeConfig,
    "planner": PlannerConfig,
    "cost": CostConfig,
    "rot": RotConfig,
    "sim": SimConfig,
}


def register_configs() -> None:
    """Store ``base_job`` and one ``base_<group>`` schema per group; safe to call twice."""
    cs = ConfigStore.instance()
    cs.store(name="base_job", node=JobConfig)
    for group, schema in SCHEMAS.items():
        cs.store(group=group, name=f"base_{group}", node=schema)
