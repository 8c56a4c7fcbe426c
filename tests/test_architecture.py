"""The package's import graph: no cycle (type-level imports included), stages import one way
(config -> datasets/grippers -> perception -> planning -> sim -> record -> report -> run), the tools sit
above every stage, the package's top level holds only stage packages, the base package and the entry point,
the config stage reads no mesh or URDF file (the grippers stage does), and only the perception stage renders
depth, adds its noise, registers and fuses."""

import ast
import subprocess
import sys
from pathlib import Path

import graspexp

PACKAGE = Path(graspexp.__file__).parent

LEVELS = (
    ("config",),
    ("datasets", "grippers"),
    ("perception",),
    ("planning",),
    ("sim",),
    ("record",),
    ("report",),
    ("run",),
)
"""The stages in import order: a module of one stage imports only from its own stage or a stage of an
earlier level. The stages of one level import neither each other: objects (``datasets``) and grippers are
what exists, side by side; the camera (``perception``) looks at both; planners get what it gives."""
STAGES = tuple(stage for level in LEVELS for stage in level)
LEVEL = {stage: i for i, level in enumerate(LEVELS) for stage in level}
STAGE_OF_PACKAGE = {**{s: s for s in STAGES}, "quality": "planning"}
"""Packages that belong to a stage without carrying its name (grasp quality is a planning-side check)."""
BASE_PACKAGE = "core"
"""Modules every stage may import (geometry, seeding, outcome, body names): they import no stage."""
TOOLS_PACKAGE = "tools"
"""Command-line tools: thin ``main(argv)`` functions above every stage; no stage imports them."""
TOOL_ALIASES = ("area",)
"""Packages that only give a tool its own ``python -m graspexp.<name>``: they count as tools."""


def _module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _imports(path: Path, modules: set[str]) -> set[str]:
    """graspexp modules imported anywhere in ``path``: module or function level, and under
    ``if TYPE_CHECKING:`` too (a type-level import is a dependency; ``from pkg import mod`` resolves to
    the module)."""
    out = set()
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            names = [f"{node.module}.{a.name}" for a in node.names if f"{node.module}.{a.name}" in modules]
            names = names or [node.module]
        else:
            continue
        out.update(n for n in names if n.split(".")[0] == "graspexp")
    return out


def _graph() -> dict[str, set[str]]:
    files = {_module_name(p): p for p in PACKAGE.rglob("*.py")}
    return {name: _imports(path, set(files)) - {name} for name, path in files.items()}


def _kind(module: str) -> str:
    """``stage:<name>``, ``base``, ``tool`` or ``entry`` (the package itself and its ``__main__``)."""
    parts = module.split(".")
    if len(parts) == 1 or parts[1] == "__main__":
        return "entry"
    if parts[1] == BASE_PACKAGE:
        return "base"
    if parts[1] in (TOOLS_PACKAGE, *TOOL_ALIASES):
        return "tool"
    return f"stage:{STAGE_OF_PACKAGE[parts[1]]}"


def test_top_level_holds_only_packages_and_the_entry_point():
    modules = sorted(p.name for p in PACKAGE.glob("*.py"))
    assert modules == ["__init__.py", "__main__.py"], modules
    packages = {p.name for p in PACKAGE.iterdir() if (p / "__init__.py").is_file()}
    expected = {*STAGE_OF_PACKAGE, BASE_PACKAGE, TOOLS_PACKAGE, *TOOL_ALIASES}
    assert packages == expected, packages


def test_stages_import_one_way():
    graph = _graph()
    wrong = []
    for module, deps in graph.items():
        kind = _kind(module)
        for dep in deps:
            dep_kind = _kind(dep)
            if kind == "base" and dep_kind != "base":
                wrong.append(f"{module} (base) imports {dep}")
            elif kind.startswith("stage") and dep_kind in ("tool", "entry") and dep != "graspexp":
                wrong.append(f"{module} ({kind}) imports the tool {dep}")
            elif kind.startswith("stage") and dep_kind.startswith("stage") and dep_kind != kind:
                if LEVEL[dep_kind[6:]] >= LEVEL[kind[6:]]:
                    wrong.append(f"{module} ({kind}) imports {dep} ({dep_kind})")
    assert not wrong, (
        "imports against config -> datasets/grippers -> perception -> planning -> sim -> record -> report"
        " -> run:\n" + "\n".join(sorted(wrong))
    )


def test_no_import_cycle():
    """No cycle between modules (a package counts as importing its __init__'s imports)."""
    graph = _graph()
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(m: str) -> None:
        state[m] = 1
        stack.append(m)
        for dep in sorted(graph.get(m, ())):
            if state.get(dep) == 1:
                cycle = stack[stack.index(dep) :] + [dep]
                raise AssertionError("import cycle: " + " -> ".join(cycle))
            if dep not in state:
                visit(dep)
        stack.pop()
        state[m] = 2

    for m in sorted(graph):
        if m not in state:
            visit(m)


def test_planning_loads_neither_hydra_nor_sapien():
    code = "import sys, graspexp.planning; print(sorted({m.split('.')[0] for m in sys.modules}))"
    loaded = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True).stdout
    assert "'hydra'" not in loaded and "'sapien'" not in loaded, loaded


def test_tests_are_laid_out_by_stage():
    tests = Path(__file__).parent
    dirs = {p.name for p in tests.iterdir() if p.is_dir() and not p.name.startswith((".", "_"))} - {"helpers"}
    assert dirs == {*STAGES, TOOLS_PACKAGE}, dirs
    assert sorted(p.name for p in tests.glob("*.py")) == ["conftest.py", "test_architecture.py"]


FILE_READERS = frozenset({"trimesh", "xml", "open3d", "sapien", "pymeshfix", "coacd", "vhacdx", "urdfpy"})
"""Libraries that read mesh or URDF files: the config stage imports none of them."""
FILE_CALLS = frozenset({"open", "read_text", "read_bytes", "load_hand", "hand_of"})
"""Calls that open a file (or a gripper's URDF): the config stage makes none of them."""
READS_PRESETS = frozenset({"reference.py"})
"""config/ modules that read the presets' own YAML (``conf/``) to document them: never a mesh or URDF."""


def test_the_config_stage_opens_no_mesh_or_urdf_file():
    """``config/`` holds schemas and value checks: no module of it imports a mesh or URDF reader or calls
    ``open``/``read_text``/``read_bytes`` (the gripper's files are the grippers stage's)."""
    wrong = []
    for path in sorted((PACKAGE / "config").rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Import):
                names = [a.name for a in node.names]
            elif isinstance(node, ast.ImportFrom) and node.module:
                names = [node.module]
            elif isinstance(node, ast.Call):
                f = node.func
                name = f.id if isinstance(f, ast.Name) else f.attr if isinstance(f, ast.Attribute) else ""
                if name in FILE_CALLS and path.name not in READS_PRESETS:
                    wrong.append(f"{path.relative_to(PACKAGE)}:{node.lineno} calls {name}")
                continue
            else:
                continue
            wrong += [
                f"{path.relative_to(PACKAGE)} imports {n}" for n in names if n.split(".")[0] in FILE_READERS
            ]
    assert not wrong, "\n".join(wrong)


PERCEPTION_LIBRARIES = frozenset({"embreex", "open3d"})
"""The ray caster and the registration/fusion library: only ``graspexp/perception/`` imports them."""
PERCEPTION_API = frozenset(
    {
        "graspexp.perception",  # the types a planner reads: Observation, CameraView
        "graspexp.perception.observation",
        "graspexp.perception.scene_view",  # the planner's view of a scene: what the simulator asks for
        "graspexp.perception.tsdf",  # the views fused for a volumetric planner
    }
)
"""What a later stage may import of perception; rendering (``camera``), depth noise (``depth_noise``),
``observe``/``estimate_pose`` and registration are its own. The run stage's benches and the tools sit above
every stage and may call any of it."""


def test_perception_is_one_stage():
    """Nothing outside ``graspexp/perception/`` renders depth, adds depth noise, registers or fuses: no other
    module imports the libraries that do it, nor a perception module beyond :data:`PERCEPTION_API`."""
    wrong = []
    for path in sorted(PACKAGE.rglob("*.py")):
        module = _module_name(path)
        if module.startswith("graspexp.perception"):
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            names = [a.name for a in node.names] if isinstance(node, ast.Import) else []
            names += [node.module] if isinstance(node, ast.ImportFrom) and node.module else []
            wrong += [f"{module} imports {n}" for n in names if n.split(".")[0] in PERCEPTION_LIBRARIES]
    graph = _graph()
    for module, deps in graph.items():
        if _kind(module) != "tool" and not module.startswith(("graspexp.perception", "graspexp.run.bench")):
            inside = {d for d in deps if d.startswith("graspexp.perception")} - PERCEPTION_API
            wrong += [f"{module} imports {d}" for d in sorted(inside)]
    assert not wrong, "perception outside graspexp/perception/:\n" + "\n".join(wrong)


def _private_imports(path: Path) -> list[str]:
    """``from graspexp.x import _name`` in ``path`` (another module's private name; a module may import
    its own package's private helpers only through a public name)."""
    out = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module and node.module.split(".")[0] == "graspexp":
            out += [f"from {node.module} import {a.name}" for a in node.names if a.name.startswith("_")]
    return out


def test_no_module_imports_another_modules_private_names():
    wrong = [
        f"{p.relative_to(PACKAGE.parent)}: {line}"
        for p in PACKAGE.rglob("*.py")
        for line in _private_imports(p)
    ]
    assert not wrong, (
        "private names imported across modules (make them public or keep them home):\n" + "\n".join(wrong)
    )


def test_the_private_import_check_finds_one(tmp_path):
    bad = tmp_path / "m.py"
    bad.write_text("from graspexp.sim.trial import _settle, run_trial\nfrom os import _exit\n")
    assert _private_imports(bad) == ["from graspexp.sim.trial import _settle"]


TOOL_MAX_LINES = 150
"""A command-line tool is a thin ``main(argv)``: parse, call one library function, print."""
SHARED_PARSER = "cli.py"
"""The tools' shared parser and helpers (``graspexp/tools/cli.py``): the one tool module allowed longer."""


def test_tool_modules_are_thin():
    tools = [p for p in (PACKAGE / TOOLS_PACKAGE).rglob("*.py") if p.name != SHARED_PARSER]
    long = {
        str(p.relative_to(PACKAGE)): n
        for p in tools
        if (n := len(p.read_text().splitlines())) > TOOL_MAX_LINES
    }
    assert not long, f"tool modules over {TOOL_MAX_LINES} lines (move the work into a stage): {long}"
