"""Checks on a composed job config that the type system cannot express.

Every key's allowed values are declared as data next to its schema (``CONSTRAINTS`` in each schema
module, see :mod:`graspexp.config.constraints`); this module walks the composed config against the
schemas: unknown keys (``+foo=1``), keys left without a value (``???``), values out of range,
and the few relations between keys. Every message is one line naming the dotted key, the value and the
allowed range. Only values are checked: nothing here reads a file or writes into the config (a URDF
gripper's file is read, and the values it gives are filled in, by :func:`graspexp.grippers.fill_gripper`).
"""

import dataclasses
from typing import Any

from omegaconf import DictConfig, OmegaConf

from graspexp.config import cost, dataset, gripper, job, mode, perception, rot, sim
from graspexp.config.constraints import accepts, describe
from graspexp.config.errors import ConfigError
from graspexp.config.plugins import PluginError, get_plugin
from graspexp.config.registry import SCHEMAS, group_options

SCHEMA_CONSTRAINTS: dict[type, dict[str, list]] = {
    job.JobConfig: job.JOB_CONSTRAINTS,
    perception.PoseNoiseConfig: perception.POSE_NOISE_CONSTRAINTS,
    perception.PerceptionConfig: perception.PERCEPTION_CONSTRAINTS,
    perception.CameraConfig: perception.CAMERA_CONSTRAINTS,
    perception.DepthNoiseConfig: perception.DEPTH_NOISE_CONSTRAINTS,
    perception.RegistrationConfig: perception.REGISTRATION_CONSTRAINTS,
    dataset.DatasetConfig: dataset.CONSTRAINTS,
    gripper.GripperConfig: gripper.CONSTRAINTS,
    mode.ModeConfig: mode.CONSTRAINTS,
    mode.ClutterModeConfig: mode.CLUTTER_CONSTRAINTS,
    cost.CostConfig: cost.CONSTRAINTS,
    rot.RotConfig: rot.CONSTRAINTS,
    sim.SimConfig: sim.CONSTRAINTS,
}
"""Each schema's constraints mapping (field name -> allowed alternatives); a planner's schema and
constraints come from its plugin (:func:`graspexp.config.plugins.get_plugin`)."""
NOT_CONFIG = frozenset({"defaults"})
"""JobConfig fields that are Hydra's composition machinery, not settings."""
RELATIONS = (
    ("gripper.min_width_m", "<", "gripper.max_width_m"),
    ("sim.rest_offset_m", "<", "sim.contact_offset_m"),
    ("sim.settle_min_s", "<=", "sim.settle_max_s"),
    ("perception.camera.min_range_m", "<", "perception.camera.max_range_m"),
)
"""Pairs of keys whose values must keep this order."""
RANGES = ("mode.object_scale",)
"""Keys whose value is a range [min, max]: min must not exceed max."""
URDF_OPTION = "urdf"
"""The gripper option that reads ``gripper.urdf`` (conf/gripper/urdf.yaml): without a file it has no
geometry (a ``???`` in its YAML would not override the schema's None)."""
FROM_URDF = frozenset({"max_width_m", "palm_size_m"})
"""Gripper keys a URDF gripper may leave unset: its file gives them (:func:`graspexp.grippers.fill_gripper`)."""


def _fields(schema: type) -> dict[str, dataclasses.Field]:
    return {f.name: f for f in dataclasses.fields(schema) if f.name not in NOT_CONFIG}


def _check_node(node: DictConfig, schema: type, prefix: str, constraints: dict | None = None) -> None:
    fields = _fields(schema)
    constraints = SCHEMA_CONSTRAINTS[schema] if constraints is None else constraints
    for key in node.keys():
        if key not in fields and key not in NOT_CONFIG:
            value = OmegaConf.select(node, str(key), throw_on_missing=False)
            where = f"group '{prefix[:-1]}'" if prefix else "the job config"
            raise ConfigError(
                f"{prefix}{key}={value!r} is invalid: {key!r} is not a key of {where}; "
                f"expected one of {', '.join(fields)}"
            )
    for name, field in fields.items():
        dotted = prefix + name
        if OmegaConf.is_missing(node, name):
            if schema is gripper.GripperConfig and name in FROM_URDF and node.urdf is not None:
                continue
            _missing(dotted)
        value = node[name]
        if schema is job.JobConfig and name == "planner":
            _check_planner(value)
            continue
        if dataclasses.is_dataclass(field.type):
            _check_node(value, _node_schema(value, field.type), dotted + ".")
            continue
        plain = OmegaConf.to_container(value) if OmegaConf.is_config(value) else value
        if not accepts(constraints[name], plain):
            raise ConfigError(f"{dotted}={plain!r} is invalid: expected {describe(constraints[name])}")


def _node_schema(node: DictConfig, declared: type) -> type:
    """The schema a node was composed from: a subclass of the declared one (a clutter mode's
    :class:`graspexp.config.mode.ClutterModeConfig` under ``mode``), else the declared one."""
    actual = OmegaConf.get_type(node)
    return actual if isinstance(actual, type) and issubclass(actual, declared) else declared


def _check_planner(node: DictConfig) -> None:
    """The ``planner`` node against the schema and constraints of the planner it names."""
    if OmegaConf.is_missing(node, "name"):
        _missing("planner.name")
    try:
        found = get_plugin(node.name)
    except PluginError as exc:
        raise ConfigError(str(exc)) from None
    _check_node(node, found.plugin.config, "planner.", dict(found.plugin.constraints))
    why = found.plugin.unavailable() if found.plugin.unavailable is not None else ""
    if why:
        raise ConfigError(f"planner={node.name} cannot run here: {why}")


def _missing(dotted: str) -> None:
    group, _, key = dotted.partition(".")
    if (group in SCHEMAS or group == "planner") and key in ("", "name"):
        raise ConfigError(
            f"{dotted} has no value: choose an option, {group}= one of {', '.join(group_options(group))}"
        )
    raise ConfigError(f"{dotted} has no value: set it with {dotted}=...")


def _check_relations(cfg: DictConfig) -> None:
    for left, op, right in RELATIONS:
        a, b = OmegaConf.select(cfg, left), OmegaConf.select(cfg, right)
        if a is not None and b is not None and not (a < b if op == "<" else a <= b):
            raise ConfigError(f"{left}={a!r} is invalid: expected {op} {right}={b!r}")


def _check_ranges(cfg: DictConfig) -> None:
    for key in RANGES:
        value = OmegaConf.select(cfg, key)
        if value is not None and value[0] > value[1]:
            raise ConfigError(f"{key}={list(value)!r} is invalid: expected [min, max] with min <= max")


def _check_urdf_named(node: DictConfig) -> None:
    """The ``urdf`` gripper option without a ``gripper.urdf`` file: one line saying how to give it."""
    if isinstance(node, DictConfig) and node.get("urdf", None) is None and node.get("name") == URDF_OPTION:
        _missing("gripper.urdf")


def _check_split(cfg: DictConfig) -> None:
    """A split and an explicit object list both choose the objects: refused, not silently merged."""
    split = OmegaConf.select(cfg, "dataset.split")
    for key in ("objects", "dataset.objects"):
        if split is not None and OmegaConf.select(cfg, key):
            raise ConfigError(
                f"dataset.split={split!r} is invalid together with {key}=[...]: both choose the objects; "
                "give one of them"
            )


def validate(cfg: DictConfig | Any) -> None:
    """Raise :class:`ConfigError` naming the first dotted key whose value is unknown, missing or invalid;
    reads no file and leaves ``cfg`` as it is (a URDF gripper may leave :data:`FROM_URDF` unset)."""
    _check_urdf_named(OmegaConf.select(cfg, "gripper", throw_on_missing=False))
    _check_node(cfg, job.JobConfig, "")
    _check_relations(cfg)
    _check_ranges(cfg)
    _check_split(cfg)
    _check_camera_extra(cfg)


def _check_camera_extra(cfg: DictConfig) -> None:
    """A job that renders the depth camera (``perception.source=depth``, or a planner that reads the
    camera) needs the ``camera`` extra: one line naming the install command when it is absent."""
    source = OmegaConf.select(cfg, "perception.source")
    planner = OmegaConf.select(cfg, "planner.name")
    if source == "depth":
        why = "perception.source=depth"
    elif get_plugin(planner).plugin.needs_observation:
        why = f"planner={planner} (it plans on the camera's cloud)"
    else:
        return
    missing = perception.missing_camera_extra()
    if missing:
        raise ConfigError(f"{why} needs {', '.join(missing)}, not installed: {perception.CAMERA_EXTRA}")
