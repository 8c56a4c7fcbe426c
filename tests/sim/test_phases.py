"""Every phase the protocols log is declared once (:class:`graspexp.core.phases.Phase`): each ``phase(...)``
call in the package names a member, never a string, and the log schema describes exactly those."""

import ast
from pathlib import Path

import graspexp
from graspexp.core.phases import Phase
from graspexp.record import schemas

PACKAGE = Path(graspexp.__file__).parent


def _phase_arguments() -> list[tuple[str, ast.expr]]:
    """(where, first phase argument) of every call ``<x>.phase(...)`` in the package: the simulator's
    ``sim.phase(name, ...)`` and a recorder's ``phase(t, name, ...)`` (the name is its second argument)."""
    out = []
    for path in PACKAGE.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            if (
                isinstance(node, ast.Call)
                and isinstance(node.func, ast.Attribute)
                and node.func.attr == "phase"
            ):
                recorder = isinstance(node.func.value, ast.Attribute) and node.func.value.attr in (
                    "recorder",
                    "rec",
                )
                args = node.args[1:] if recorder else node.args
                if args:
                    out.append((f"{path.relative_to(PACKAGE.parent)}:{node.lineno}", args[0]))
    return out


def _member(arg: ast.expr) -> str | None:
    """``X`` of ``Phase.X`` or ``Phase.X.value``; None for anything else (a string, a variable)."""
    if isinstance(arg, ast.Attribute) and arg.attr == "value":
        arg = arg.value
    if isinstance(arg, ast.Attribute) and isinstance(arg.value, ast.Name) and arg.value.id == "Phase":
        return arg.attr
    return None


def test_every_phase_call_names_a_declared_phase():
    calls = _phase_arguments()
    assert len(calls) >= 20, calls  # the trial's and the round's phases are found
    wrong = [f"{where}: {ast.unparse(arg)}" for where, arg in calls if _member(arg) not in Phase.__members__]
    # the simulator's own method forwards its argument; nothing else may pass a name
    wrong = [w for w in wrong if not w.startswith("graspexp/sim/trial.py") or "phase.value" not in w]
    assert not wrong, "phase names not from graspexp.core.phases.Phase:\n" + "\n".join(wrong)


def test_the_log_schema_describes_the_declared_phases():
    assert schemas.PHASE_NAMES == tuple(p.value for p in Phase)
    used = {_member(arg) for _, arg in _phase_arguments()} - {None}
    assert used <= set(Phase.__members__)
    unused = set(Phase.__members__) - used
    assert not unused, f"declared phases no protocol logs: {sorted(unused)}"
