"""The package's import graph: no cycle, and stages import one way
(config -> datasets -> planning -> sim -> record -> report). Module-level and function-level imports count."""

import ast
import subprocess
import sys
from pathlib import Path

import graspexp

PACKAGE = Path(graspexp.__file__).parent

STAGES = ("config", "datasets", "planning", "sim", "record", "report")
"""The stages in import order: a module of one stage imports only from its own stage or an earlier one."""
STAGE_OF_PACKAGE = {**{s: s for s in STAGES}, "quality": "planning", "compare": "report"}
"""Packages that belong to a stage without carrying its name (grasp quality is a planning-side check)."""
BASE_MODULES = {"graspexp", "graspexp.geometry", "graspexp.seeding", "graspexp.outcome"}
"""Modules every stage may import: they import no stage themselves."""


def _module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _runtime_nodes(tree: ast.AST):
    """Every node of ``tree`` except those under ``if TYPE_CHECKING:`` (annotations only, never imported)."""
    for node in ast.iter_child_nodes(tree):
        if (
            isinstance(node, ast.If)
            and getattr(node.test, "id", getattr(node.test, "attr", "")) == "TYPE_CHECKING"
        ):
            yield from (n for child in node.orelse for n in (child, *_runtime_nodes(child)))
            continue
        yield node
        yield from _runtime_nodes(node)


def _imports(path: Path, modules: set[str]) -> set[str]:
    """graspexp modules imported anywhere in ``path`` at run time, module or function level (``from pkg
    import mod`` resolves to the module)."""
    out = set()
    for node in _runtime_nodes(ast.parse(path.read_text())):
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


def _stage(module: str) -> str | None:
    """The stage of ``module``; None for a tool (a top-level module, or a package's ``__main__``)."""
    parts = module.split(".")
    return STAGE_OF_PACKAGE.get(parts[1]) if len(parts) > 1 and parts[-1] != "__main__" else None


def test_stages_import_one_way():
    graph = _graph()
    wrong = []
    for module, deps in graph.items():
        stage = _stage(module)
        for dep in deps:
            dep_stage = _stage(dep)
            if module in BASE_MODULES and dep not in BASE_MODULES:
                wrong.append(f"{module} (base) imports {dep}")
            elif stage is not None and dep_stage is None and dep not in BASE_MODULES:
                wrong.append(f"{module} ({stage}) imports the tool module {dep}")
            elif stage is not None and dep_stage is not None:
                if STAGES.index(dep_stage) > STAGES.index(stage):
                    wrong.append(f"{module} ({stage}) imports {dep} ({dep_stage})")
    assert not wrong, (
        "imports against config -> datasets -> planning -> sim -> record -> report:\n"
        + "\n".join(sorted(wrong))
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
