"""The documentation stays true by construction: the configuration reference names every key of every
config group and installed planner (read here straight from the schemas, independently of the generator),
the tutorials' tested command blocks run, and the README stays short with its commands runnable."""

import dataclasses
import importlib.util
import os
import re
import shlex
import subprocess
import sys
import typing
from pathlib import Path

import pytest

import graspexp
from graspexp.config.job import JobConfig
from graspexp.config.plugins import LoadedPlanner, get_plugin, load_planners
from graspexp.config.reference import render
from graspexp.config.registry import SCHEMAS, SUBSCHEMAS, group_options
from graspexp.run.job_config import clutter_modes

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
    expected += [k for g, s in SUBSCHEMAS.values() for k in _keys(s, f"{g}.")]
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
LEARNED_PAGES = {"tutorials/learned_planner.md": "vgn"}
"""Pages whose tested blocks run a learned planner (page below ``docs/`` -> planner): their case is marked
``learned`` (``nox -s learned`` selects it) and skipped, with the planner's own reason, where the planner
cannot run (its optional extra or checkpoint missing)."""


def _page_case(page: Path):
    rel = str(page.relative_to(DOCS))
    return pytest.param(page, id=rel, marks=[pytest.mark.learned] if rel in LEARNED_PAGES else [])


def test_every_tutorial_has_a_tested_block():
    untested = [
        p.name for p in (DOCS / "tutorials").glob("*.md") if p.name != "index.md" and p not in TUTORIALS
    ]
    assert not untested, f"tutorials without a <!-- tested --> block: {untested}"


@pytest.mark.slow
@pytest.mark.parametrize("page", [_page_case(p) for p in TUTORIALS])
def test_the_tested_commands_of_a_page_run_as_written(page, tmp_path, monkeypatch):
    """Each page's tested blocks run in order in one fresh folder that holds a link to the checkout's
    ``examples/`` (the tutorials run from the checkout's root), with this checkout first on the path. A
    page of :data:`LEARNED_PAGES` reads the checkpoints from ``$GRASPEXP_CHECKPOINTS``, else ``peers/vgn``
    beside the shared data root (as ``tests/planning/test_vgn.py``)."""
    planner = LEARNED_PAGES.get(str(page.relative_to(DOCS)))
    if planner is not None:
        from helpers.config import shared_data_root

        default = str(shared_data_root().parent / "peers" / "vgn")
        monkeypatch.setenv("GRASPEXP_CHECKPOINTS", os.environ.get("GRASPEXP_CHECKPOINTS", default))
        reason = get_plugin(planner).plugin.unavailable()
        if reason:
            pytest.skip(f"{page.name} runs planner={planner}, which cannot run here: {reason}")
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


FRESH_INSTALL = (
    "python3 -m venv .venv && . .venv/bin/activate && pip install -e '.[test]' && python -m graspexp"
)
"""The README's first command (CI and other tools rely on it, word for word)."""
FRESH_TESTS = ". .venv/bin/activate && GRASPEXP_DATA=../shared/datasets python -m pytest -q -n 2"
"""The README's second command."""
RUN_FOR_REAL = (
    "python -m graspexp 'objects=[mug]'",
    "python -m graspexp replay ",
    "python -m graspexp.area ",
)
"""README commands cheap enough to run as written (one trial, its log replayed and re-simulated, the area
picture of the example part), in README order; the others run in their dry form."""
README_LIMIT = 200
"""Most lines the README may have: a newcomer reads it in five minutes; the rest lives in ``docs/``."""


def _bash_blocks(text: str) -> list[list[str]]:
    blocks, block = [], None
    for line in text.splitlines():
        if block is None and line.startswith("```bash"):
            block = []
        elif block is not None and line.startswith("```"):
            blocks.append(block)
            block = None
        elif block is not None:
            block.append(line)
    return blocks


def readme_commands() -> list[str]:
    """Every ``python -m graspexp...`` and ``nox`` command of the README's bash blocks, continuation lines
    joined and trailing comments dropped."""
    out = []
    for block in _bash_blocks(README.read_text()):
        joined = re.sub(r"\\\n\s*", "", "\n".join(block))
        for line in joined.splitlines():
            cmd = re.sub(r"\s+#\s.*$", "", line).strip()
            if cmd.startswith(("python -m graspexp", "nox ")):
                out.append(cmd)
    return out


def _first_value(arg: str) -> str:
    """``key=a,b`` -> ``key=a`` (a list value ``key=[a,b]`` stays whole)."""
    key, sep, value = arg.partition("=")
    return f"{key}={value.split(',')[0]}" if sep and not value.startswith("[") else arg


def dry_form(cmd: str, env: dict[str, str]) -> list[str]:
    """The command as a cheap check: a tool's ``--help``; a job's composed config (``--cfg job``, the first
    value of each swept key, without ``-m``), which validates every override as the run would."""
    from graspexp.tools import TOOLS

    words = shlex.split(cmd.replace("$PARTITION", env["PARTITION"]))
    module, args = words[2], words[3:]
    python = [sys.executable, "-m", module]
    if module != "graspexp":  # python -m graspexp.area, graspexp.run.suites
        return [*python, "--help"]
    if args and args[0] in TOOLS:
        return [*python, args[0], "--help"]
    return [*python, "--cfg", "job", *(_first_value(a) for a in args if a != "-m")]


def test_the_readme_is_short_and_opens_with_the_two_fresh_machine_commands():
    text = README.read_text()
    assert len(text.splitlines()) <= README_LIMIT, f"README.md has {len(text.splitlines())} lines"
    assert _bash_blocks(text)[:2] == [[FRESH_INSTALL], [FRESH_TESTS]]
    assert "python -m graspexp.area" in text and "gripper=urdf gripper.urdf=" in text
    links = re.findall(r"\]\(([^)#]+)(?:#[^)]*)?\)", text)
    dead = [link for link in links if "://" not in link and not (ROOT / link).exists()]
    assert not dead, f"README links to missing files: {dead}"


@pytest.mark.slow
def test_every_readme_command_runs_as_written_or_dry(tmp_path):
    """A few commands run as written (:data:`RUN_FOR_REAL`); the other tools answer ``--help`` and the other
    jobs compose and validate (``--cfg job``), from a folder that holds the README's example inputs
    (``my_parts/bracket.stl`` in mm, ``my_gripper/gripper.urdf``); the nox sessions exist."""
    import trimesh
    from helpers.objects import write_urdf_gripper

    (tmp_path / "my_parts").mkdir()
    trimesh.creation.box((50, 30, 80)).export(tmp_path / "my_parts" / "bracket.stl")
    (tmp_path / "my_gripper").mkdir()
    write_urdf_gripper(tmp_path / "my_gripper")
    env = {
        **os.environ,
        "PARTITION": "debug",
        "OMP_NUM_THREADS": "1",
        "GRASPEXP_CACHE": os.environ.get("GRASPEXP_CACHE", str(tmp_path / ".cache")),
        "PYTHONPATH": os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH", "")])),
    }
    sessions = set(re.findall(r"^def (\w+)\(session", (ROOT / "noxfile.py").read_text(), flags=re.M))
    commands = readme_commands()
    assert len(commands) >= 12, commands
    for cmd in commands:
        if cmd.startswith("nox "):
            assert cmd.split()[2] in sessions, cmd
            continue
        argv = ["bash", "-c", cmd] if cmd.startswith(RUN_FOR_REAL) else dry_form(cmd, env)
        proc = subprocess.run(argv, cwd=tmp_path, env=env, capture_output=True, text=True, timeout=300)
        if "planner=vgn" in cmd and importlib.util.find_spec("torch") is None:
            # without the optional extra the job is refused in one line naming its install command
            assert proc.returncode == 2 and "pip install -e '.[learned]'" in proc.stderr, (cmd, proc.stderr)
            continue
        assert proc.returncode == 0, f"{cmd}\n-> {argv}\n{proc.stderr[-2000:]}"


@pytest.mark.slow
def test_the_site_builds_strictly(tmp_path):
    """``mkdocs build --strict`` (what ``nox -s docs`` runs): a dead link, a page left out of the nav or a
    docstring mkdocstrings cannot read fails. Skipped where the ``docs`` extra is not installed."""
    pytest.importorskip("mkdocs")
    pytest.importorskip("material")
    pytest.importorskip("mkdocstrings")
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
    cmd = [sys.executable, "-m", "mkdocs", "build", "--strict", "--site-dir", str(tmp_path / "site")]
    proc = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr[-3000:]
    assert (
        "sim.approach_settle_s"
        in (tmp_path / "site" / "reference" / "configuration" / "index.html").read_text()
    )


def test_every_key_of_graspexp_has_a_docstring():
    """STYLE 12: a key is documented once, in its schema; the reference shows that text, so an empty
    description cell is a key nobody explained (planners of other packages are not held to it)."""
    text = render()
    own = {
        n
        for n, p in load_planners().items()
        if isinstance(p, LoadedPlanner) and p.package.startswith("graspexp ")
    }
    sections = _planner_sections(text)
    checked = text.split("## `planner`")[0] + "".join(sections[n] for n in own)
    rows = [re.split(r"(?<!\\)\|", r) for r in checked.splitlines() if r.startswith("| `")]
    empty = [cells[1].strip() for cells in rows if len(cells) == 8 and not cells[6].strip()]
    assert not empty, f"keys without a docstring: {empty}"


@pytest.mark.parametrize("page", [README, DOCS / "guide" / "config_groups.md"], ids=lambda p: p.name)
def test_the_hand_written_group_tables_list_every_option(page):
    """The groups tables in words (README, guide) name every option graspexp ships for each group; the clutter
    modes are scene types' presets (a new one is a class and a preset, :mod:`graspexp.sim.scene_types`): the
    generated reference names every one (:func:`test_the_reference_names_every_key_of_every_group_and_planner`)."""
    rows = {
        line.split("|")[1].strip(" `"): line
        for line in page.read_text().splitlines()
        if line.startswith("| `")
    }
    own = {
        n
        for n, p in load_planners().items()
        if isinstance(p, LoadedPlanner) and p.package.startswith("graspexp ")
    }
    scene_presets = set(clutter_modes())  # a scene type's preset: named by the generated reference
    missing = [
        f"{group}={option}"
        for group in (*SCHEMAS, "planner")
        for option in group_options(group)
        if (group != "planner" or option in own)
        and not (group == "mode" and option in scene_presets)
        and f"`{option}`" not in rows.get(group, "")
    ]
    assert not missing, f"{page.name} does not list {missing}"
