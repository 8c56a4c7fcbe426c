"""A preset states only what differs from its schema: no value in a YAML option under ``conf/`` repeats its
schema's default (the schema's default is the effective default of the preset that selects it; the base
planner of a shared schema uses every default, its variants state their differences)."""

import dataclasses
import typing
from pathlib import Path

import pytest
import yaml

from graspexp.config.job import JobConfig
from graspexp.config.plugins import get_plugin
from graspexp.config.registry import CONF_DIR, NESTED_SCHEMAS, SCHEMAS, SUBSCHEMAS

CONF = Path(CONF_DIR)
HYDRA_OWN = "hydra"
"""Options of Hydra's own groups (``conf/hydra/``) follow Hydra's schemas, not graspexp's."""


def _presets() -> list[Path]:
    return sorted(p for p in CONF.rglob("*.yaml") if p.relative_to(CONF).parts[0] != HYDRA_OWN)


def _schema(name: str) -> type:
    """The schema stored as ``name`` (``schema_job``, ``schema_<group>``, ``schema_planner_<name>``)."""
    if name == "schema_job":
        return JobConfig
    if name.startswith("schema_planner_"):
        return get_plugin(name.removeprefix("schema_planner_")).plugin.config
    subschemas = {k: schema for k, (_, schema) in SUBSCHEMAS.items()}
    return {**SCHEMAS, **NESTED_SCHEMAS, **subschemas}[name.removeprefix("schema_")]


def _nodes(data: dict) -> list[tuple[str, dict, type]]:
    """(key, values, schema) of each node of an option that its defaults list types: ``/<schema>@_here_``
    types the option's own keys, ``/<schema>@<key>`` its node ``key`` (a ``# @package perception`` camera
    preset: ``camera`` and ``depth_noise``)."""
    out = []
    for entry in data["defaults"]:
        name, _, at = entry.partition("@") if isinstance(entry, str) else ("", "", "")
        if not name.lstrip("/").startswith("schema_"):
            continue
        if at in ("", "_here_"):
            out.append(("", {k: v for k, v in data.items() if k != "defaults"}, _schema(name.lstrip("/"))))
        else:
            out.append((f"{at}.", data.get(at) or {}, _schema(name.lstrip("/"))))
    return out


def _default(field: dataclasses.Field) -> object:
    if field.default_factory is not dataclasses.MISSING:
        return field.default_factory()
    return field.default


def _same(value: object, default: object) -> bool:
    """Equal as YAML values: 0.10 == 0.1 and 1 == 1.0, but true != 1."""
    if isinstance(value, bool) or isinstance(default, bool):
        return type(value) is type(default) and value == default
    if isinstance(value, list) and isinstance(default, list):
        return len(value) == len(default) and all(map(_same, value, default))
    return value == default


def _repeated(values: dict, schema: type, prefix: str) -> list[str]:
    """``key: value`` of every value of ``values`` (a node typed by ``schema``) that equals its schema's
    default, nested nodes (a dataclass field set as a mapping) checked against their own schema."""
    fields = {f.name: f for f in dataclasses.fields(schema)}
    hints = typing.get_type_hints(schema)
    out = []
    for key, value in values.items():
        if key not in fields:
            continue
        if dataclasses.is_dataclass(hints.get(key)) and isinstance(value, dict):
            out += _repeated(value, hints[key], f"{prefix}{key}.")
        elif _same(value, _default(fields[key])):
            out.append(f"{prefix}{key}: {value!r}")
    return out


def repeated_defaults(path: Path) -> list[str]:
    """``key: value`` of every value of the YAML option ``path`` that equals its schema's default, at any
    depth."""
    data = yaml.safe_load(path.read_text())
    return [line for prefix, values, schema in _nodes(data) for line in _repeated(values, schema, prefix)]


@pytest.mark.parametrize("path", _presets(), ids=lambda p: str(p.relative_to(CONF)))
def test_no_preset_value_repeats_its_schema_default(path):
    assert not repeated_defaults(path), f"{path.relative_to(CONF.parent)} repeats its schema's defaults"


def test_the_check_finds_a_repeated_default(tmp_path):
    option = tmp_path / "rg2.yaml"
    option.write_text(
        "defaults:\n  - /schema_gripper@_here_\nname: rg2\npad_friction: 1.0\nmin_width_m: 0.01\n"
    )
    assert repeated_defaults(option) == ["pad_friction: 1.0"]
    planner = tmp_path / "optimal_plus.yaml"
    planner.write_text(
        "defaults:\n  - /schema_planner_optimal_plus@_here_\nname: x\nm: 256\nrolls_deg: [0, 90]\n"
    )
    assert repeated_defaults(planner) == ["m: 256", "rolls_deg: [0, 90]"]
    camera = tmp_path / "kinect.yaml"
    camera.write_text(
        "# @package perception\ndefaults:\n  - /schema_camera@camera\n  - /schema_depth_noise@depth_noise\n"
        "camera:\n  name: kinect\n  width_px: 424\ndepth_noise:\n  axial_a_m: 0.002\n  edge_jump_m: 0.02\n"
    )
    assert repeated_defaults(camera) == ["camera.width_px: 424", "depth_noise.edge_jump_m: 0.02"]
    job = tmp_path / "config.yaml"
    job.write_text(
        "defaults:\n  - /schema_job@_here_\nseed: 7\nperception:\n  noise:\n    trans_mm: 0.0\n    rot_deg: 2.0\n"
    )
    assert repeated_defaults(job) == ["perception.noise.trans_mm: 0.0"]  # a nested key, found at its depth
