"""The documentation stays true by construction: the configuration reference names every key of every
config group and installed planner (read here straight from the schemas, independently of the generator),
the tutorials' tested command blocks run, and the README stays short with its commands runnable."""

import dataclasses
import re
import typing
from pathlib import Path

import graspexp
from graspexp.config.job import JobConfig
from graspexp.config.plugins import LoadedPlanner, load_planners
from graspexp.config.registry import SCHEMAS, group_options
from graspexp.tools.config_reference import render

ROOT = Path(graspexp.__file__).resolve().parent.parent
DOCS = ROOT / "docs"
README = ROOT / "README.md"
TESTED = "<!-- tested -->"
"""The marker line right above a fenced ``bash`` block that a test runs as written."""


def _keys(schema: type, prefix: str) -> list[str]:
    hints = typing.get_type_hints(schema)
    out = []
    for f in dataclasses.fields(schema):
        if f.name == "defaults" or (schema is JobConfig and f.name in (*SCHEMAS, "planner")):
            continue
        t = hints[f.name]
        out += _keys(t, f"{prefix}{f.name}.") if dataclasses.is_dataclass(t) else [f"{prefix}{f.name}"]
    return out


def _planner_sections(text: str) -> dict[str, str]:
    parts = re.split(r"^### `planner=([^`]+)`$", text, flags=re.M)
    return dict(zip(parts[1::2], parts[2::2], strict=True))


def test_the_reference_names_every_key_of_every_group_and_planner():
    text = render()
    expected = _keys(JobConfig, "") + [k for g, s in SCHEMAS.items() for k in _keys(s, f"{g}.")]
    missing = [k for k in expected if f"| `{k}` |" not in text]
    sections = _planner_sections(text)
    for name, found in load_planners().items():
        assert isinstance(found, LoadedPlanner), found
        assert name in sections, f"planner={name} has no section"
        missing += [
            f"{name}: {k}"
            for k in _keys(found.plugin.config, "planner.")
            if f"| `{k}` |" not in sections[name]
        ]
    assert not missing, f"keys missing from the configuration reference: {missing}"
    for group in (*SCHEMAS, "planner"):
        for option in group_options(group):
            assert f"`{group}={option}`" in text, f"option {group}={option} missing from the reference"


def test_the_reference_gives_type_unit_default_range_and_docstring():
    row = next(line for line in render().splitlines() if line.startswith("| `sim.approach_settle_s` |"))
    cells = [c.strip() for c in row.strip("|").split("|")]
    assert cells[1:5] == ["`float`", "s", "`0.2`", "a number in [0, 60] s"], cells
    assert "holds the grasp pose after the approach" in cells[5] and "before it behaved as `0`" in cells[5]


def test_the_reference_tool_writes_the_page(tmp_path):
    from graspexp.tools import config_reference

    assert config_reference.main(["--out", str(tmp_path / "c.md")]) == 0
    assert (tmp_path / "c.md").read_text() == render()
