"""Registers every schema in Hydra's ConfigStore (``base_<group>`` in each group)."""

from pathlib import Path

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

CONF_DIR = str(Path(__file__).resolve().parent.parent.parent / "conf")
"""The YAML config tree (``conf/<group>/<option>.yaml``)."""


def group_options(group: str) -> list[str]:
    """The option names of config group ``group`` (its YAML files), sorted."""
    return sorted(p.stem for p in (Path(CONF_DIR) / group).glob("*.yaml"))


def register_configs() -> None:
    """Store ``base_job`` and one ``base_<group>`` schema per group; safe to call twice."""
    from hydra.core.config_store import ConfigStore  # here, so that the schemas load without Hydra

    cs = ConfigStore.instance()
    cs.store(name="base_job", node=JobConfig)
    for group, schema in SCHEMAS.items():
        cs.store(group=group, name=f"base_{group}", node=schema)
