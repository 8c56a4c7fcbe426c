"""The documentation stays true by construction: the configuration reference names every key of every
config group and installed planner (read here straight from the schemas, independently of the generator),
the tutorials' tested command blocks run, and the README stays short with its commands runnable."""

import dataclasses
import os
import re
import subprocess
import typing
from pathlib import Path

import pytest

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


def marked_blocks(page: Path) -> list[str]:
    """The fenced ``bash`` blocks of ``page`` right below a ``<!-- tested -->`` line, in order."""
    blocks, lines = [], page.read_text().splitlines()
    for i, line in enumerate(lines[:-1]):
        if line.strip() == TESTED and lines[i + 1].startswith("```bash"):
            end = next(j for j in range(i + 2, len(lines)) if lines[j].startswith("```"))
            blocks.append("\n".join(lines[i + 2 : end]))
    return blocks


TUTORIALS = sorted(p for p in DOCS.rglob("*.md") if marked_blocks(p))


def test_every_tutorial_has_a_tested_block():
    untested = [
        p.name for p in (DOCS / "tutorials").glob("*.md") if p.name != "index.md" and p not in TUTORIALS
    ]
    assert not untested, f"tutorials without a <!-- tested --> block: {untested}"


@pytest.mark.slow
@pytest.mark.sim
@pytest.mark.parametrize("page", TUTORIALS, ids=lambda p: str(p.relative_to(DOCS)))
def test_the_tested_commands_of_a_page_run_as_written(page, tmp_path):
    """Each page's tested blocks run in order in one fresh folder that holds a link to the checkout's
    ``examples/`` (the tutorials run from the checkout's root), with this checkout first on the path."""
    (tmp_path / "examples").symlink_to(ROOT / "examples")
    env = {
        **os.environ,
        "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH", "")])),
        "OMP_NUM_THREADS": "1",
        "GRASPEXP_CACHE": os.environ.get("GRASPEXP_CACHE", str(tmp_path / ".cache")),
    }
    for block in marked_blocks(page):
        proc = subprocess.run(
            ["bash", "-euo", "pipefail", "-c", block],
            cwd=tmp_path,
            env=env,
            capture_output=True,
            text=True,
            timeout=300,
        )
        assert proc.returncode == 0, (
            f"{page.name}: block failed ({proc.returncode}):\n{block}\n{proc.stdout[-2000:]}\n{proc.stderr[-3000:]}"
        )
