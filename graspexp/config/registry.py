"""Registers every schema in Hydra's ConfigStore, outside the config groups (``schema_<group>``, one
``schema_planner_<name>`` per planner), so that no schema is offered as an option (``--help``, completion)."""

from pathlib import Path

from omegaconf import DictConfig, OmegaConf

from graspexp.config.cost import CostConfig
from graspexp.config.dataset import DatasetConfig
from graspexp.config.errors import ConfigError
from graspexp.config.gripper import GripperConfig
from graspexp.config.job import JobConfig
from graspexp.config.mode import CLUTTER_KEYS, LEGACY_SCENES, ClutterModeConfig, ModeConfig
from graspexp.config.perception import CameraConfig, DepthNoiseConfig
from graspexp.config.plugins import LoadedPlanner, PluginError, get_plugin, load_planners
from graspexp.config.rot import RotConfig
from graspexp.config.sim import SimConfig

SCHEMAS = {
    "dataset": DatasetConfig,
    "gripper": GripperConfig,
    "mode": ModeConfig,
    "cost": CostConfig,
    "rot": RotConfig,
    "sim": SimConfig,
}
"""The schema of each group with one schema; the ``planner`` group has one per planner (its plugin's)."""
SUBSCHEMAS = {"clutter_mode": ("mode", ClutterModeConfig)}
"""Schemas of a group's options that extend the group's schema with keys of their own, stored as
``schema_<name>`` (name -> (group, schema)): the clutter modes' (``conf/mode/pile.yaml`` lists
``/schema_clutter_mode@_here_``)."""
NESTED_SCHEMAS = {"camera": CameraConfig, "depth_noise": DepthNoiseConfig}
"""Schemas of the keys a nested group's options set, stored as ``schema_<key>``: a ``perception/camera``
option (``# @package perception``) sets ``perception.camera`` and, for a sensor with its own noise model,
``perception.depth_noise``; its defaults list names both schemas (``/schema_camera@camera``,
``/schema_depth_noise@depth_noise``)."""


def _conf_dir() -> Path:
    """The YAML tree: ``graspexp/conf`` in an installed wheel (the package ``graspexp.conf``), else the
    checkout's top-level ``conf/`` (a source tree or an editable install)."""
    package = Path(__file__).resolve().parent.parent
    installed = package / "conf"
    return installed if (installed / "config.yaml").is_file() else package.parent / "conf"


CONF_DIR = str(_conf_dir())
"""The YAML config tree, ``conf/<group>/<option>.yaml``: the repository's top-level ``conf/``, which the
wheel ships as ``graspexp/conf`` (``setup.py``)."""


def _yaml_options(group: str) -> set[str]:
    return {p.stem for p in (Path(CONF_DIR) / group).glob("*.yaml")}


def group_options(group: str) -> list[str]:
    """The option names of config group ``group``, sorted: its YAML files, and for ``planner`` also every
    installed planner (a plugin without a preset file is an option with its schema's defaults)."""
    names = _yaml_options(group)
    if group == "planner":
        names |= set(load_planners())
    return sorted(names)


def schema_name(group: str, planner: str | None = None) -> str:
    """The ConfigStore name of a group's schema (of the planner ``planner`` for ``group="planner"``): a
    top-level entry, not an option of the group; an option's YAML lists it as ``/<name>@_here_``."""
    return f"schema_planner_{planner}" if group == "planner" else f"schema_{group}"


def register_configs() -> None:
    """Store the job schema (``schema_job``), one schema per group and per installed planner
    (:func:`schema_name`), and per planner without a preset ``conf/planner/<name>.yaml`` the option
    ``planner/<name>`` (the schema's defaults); safe to call twice. Broken plugins are skipped here (their
    error is raised when one is selected, see :func:`graspexp.config.plugins.get_plugin`)."""
    from hydra.core.config_store import ConfigStore  # here, so that the schemas load without Hydra

    cs = ConfigStore.instance()
    cs.store(name=schema_name("job"), node=JobConfig)
    for group, schema in SCHEMAS.items():
        cs.store(name=schema_name(group), node=schema)
    for name, schema in NESTED_SCHEMAS.items():
        cs.store(name=schema_name(name), node=schema)
    for name, (_, schema) in SUBSCHEMAS.items():
        cs.store(name=schema_name(name), node=schema)
    presets = _yaml_options("planner")
    for name, found in load_planners().items():
        if isinstance(found, LoadedPlanner):
            schema = found.plugin.config
            cs.store(name=schema_name("planner", name), node=schema)
            if name not in presets:
                cs.store(group="planner", name=name, node=schema(name=name))


def _recorded_mode(mode: DictConfig) -> DictConfig:
    """A recorded ``mode`` node typed by its schema: :class:`ClutterModeConfig` when it names a scene type (a
    log written before ``mode.scene`` existed: a ``pile`` or ``packed`` mode, its scene type of that name),
    else :class:`ModeConfig` (such an older log recorded the clutter keys for every mode: dropped)."""
    if "scene" not in mode and mode.get("name") in LEGACY_SCENES:
        mode.scene = mode.name
    if "scene" in mode:
        return OmegaConf.merge(OmegaConf.structured(ClutterModeConfig), mode)
    return OmegaConf.merge(
        OmegaConf.structured(ModeConfig), {k: v for k, v in mode.items() if k not in CLUTTER_KEYS}
    )


def job_config_from_yaml(text: str) -> DictConfig:
    """A job config recorded as YAML (e.g. a trial log's ``config_yaml``) typed again by its schemas, the
    ``planner`` node by the schema of the planner it names (:class:`PluginError` if none is installed), a
    clutter mode's by :class:`ClutterModeConfig` (a log written before ``mode.scene`` existed: the scene type
    its mode was named for)."""
    try:
        data = OmegaConf.create(text)
        planner = OmegaConf.structured(get_plugin(data.planner.name).plugin.config)
        data.mode = _recorded_mode(data.mode)
        cfg = OmegaConf.merge(OmegaConf.structured(JobConfig), data)
        cfg.planner = OmegaConf.merge(planner, data.planner)
    except PluginError:
        raise
    except Exception as exc:  # YAML, a list, unknown keys, wrong types: OmegaConf raises many kinds
        first = str(exc).strip().splitlines()[0] if str(exc).strip() else ""
        raise ConfigError(
            f"the recorded config is not a graspexp job config ({type(exc).__name__}: {first})"
        ) from None
    return cfg
