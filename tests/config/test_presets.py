"""A preset states only what differs from its schema: no value in a YAML option under ``conf/`` repeats its
schema's default (the schema's default is the effective default of the preset that selects it; the base
planner of a shared schema uses every default, its variants state their differences)."""

import dataclasses
from pathlib import Path

import pytest
import yaml

from graspexp.config.job import JobConfig
from graspexp.config.plugins import get_plugin
from graspexp.config.registry import CONF_DIR, NESTED_SCHEMAS, SCHEMAS

CONF = Path(CONF_DIR)
HYDRA_OWN = "hydra"
"""Options of Hydra's own groups (``conf/hydra/``) follow Hydra's schemas, not graspexp's."""


def _presets() -> list[Path]:
    return sorted(p for p in CONF.rglob("*.yaml") if p.relative_to(CONF).parts[0] != HYDRA_OWN)


def _schema(path: Path, data: dict) -> type:
    """The schema that the option's defaults list names (``/schema_<group>@_here_``,
    ``/schema_planner_<name>@_here_``; ``schema_job`` for ``config.yaml``)."""
    (first, *_) = data["defaults"]
    name = first.split("@")[0].lstrip("/")
    if name == "schema_job":
        return JobConfig
    if name.startswith("schema_planner_"):
        return get_plugin(name.removeprefix("schema_planner_")).plugin.config
    return {**SCHEMAS, **NESTED_SCHEMAS}[name.removeprefix("schema_")]


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


def repeated_defaults(path: Path) -> list[str]:
    """``key: value`` of every value of the YAML option ``path`` that equals its schema's default."""
    data = yaml.safe_load(path.read_text())
    fields = {f.name: f for f in dataclasses.fields(_schema(path, data))}
    return [
        f"{key}: {value!r}"
        for key, value in data.items()
        if key in fields and key != "defaults" and _same(value, _default(fields[key]))
    ]


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
