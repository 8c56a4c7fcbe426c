"""Every tool starts the same way (graspexp.tools.cli): its own --help, Hydra overrides composed in one place,
graspexp's help and bash completion that offer the config groups' options and never the schemas."""

import importlib
import subprocess
import sys
from pathlib import Path

import pytest
from helpers.cli import graspexp as _graspexp

from graspexp.config.registry import group_options
from graspexp.tools import TOOLS

REPO = Path(__file__).resolve().parents[2]
GRASPEXP_COMMAND = Path(sys.executable).parent / "graspexp"
"""The console script pip installs beside the interpreter."""


def test_help_names_graspexp_and_offers_options_not_schemas():
    proc = _graspexp("--help")
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.startswith("usage: graspexp ")
    assert "Hydra" not in proc.stdout.splitlines()[0] and "powered by Hydra" not in proc.stdout
    for group in ("dataset", "mode", "rot", "gripper", "planner", "cost", "sim"):
        assert f"  {group}: {', '.join(group_options(group))}\n" in proc.stdout
    assert "base_" not in proc.stdout and "schema" not in proc.stdout


def _complete(script: str, word: str) -> list[str]:
    """The words bash offers for ``graspexp <word><TAB>`` once ``script`` is installed."""
    call = (
        'COMP_LINE="$GX $WORD"; COMP_POINT=${#COMP_LINE}; COMP_WORDS=("$GX" "$WORD"); COMP_CWORD=1; '
        '_graspexp_complete; echo "${COMPREPLY[@]}"'
    )
    env = {"PATH": "/usr/bin:/bin", "GX": str(GRASPEXP_COMMAND), "WORD": word}
    done = subprocess.run(
        ["bash", "-c", script + call], capture_output=True, text=True, timeout=60, check=True, env=env
    )
    return done.stdout.split()


@pytest.mark.slow
def test_bash_completion_installs_and_completes_options_but_no_schema():
    script = _graspexp("--shell-completion", "install=bash")
    assert script.returncode == 0, script.stderr
    assert _complete(script.stdout, "mode=b") == ["mode=bin"]
    planners = _complete(script.stdout, "planner=")
    assert sorted(planners) == [f"planner={p}" for p in group_options("planner")]
    top = _complete(script.stdout, "")
    assert {"mode=", "planner=", "trials="} <= set(top)
    assert not any("schema" in w or "base_" in w for w in [*planners, *top])


def test_shell_completion_without_a_command_is_one_line():
    proc = _graspexp("--shell-completion")
    assert proc.returncode == 2
    assert proc.stderr == (
        "graspexp: error: --shell-completion needs install=bash, uninstall=bash or query=bash, got ''\n"
    )


def test_a_sweep_without_multirun_is_one_line():
    proc = _graspexp("mode=collab,bin", "trials=1")
    assert proc.returncode == 2
    assert proc.stderr == (
        "graspexp: error: mode=collab,bin sweeps over several values: add -m (--multirun), or give a list "
        "as key=[a,b]\n"
    )


def test_two_modes_are_refused_by_the_parser():
    proc = _graspexp("-m", "--cfg", "job", "mode=bin")
    assert proc.returncode == 2
    assert proc.stderr.splitlines()[-1] == (
        "graspexp: error: argument -c/--cfg: not allowed with argument -m/--multirun"
    )


@pytest.mark.parametrize("tool", TOOLS)
def test_every_tool_has_its_own_help(tool, capsys):
    with pytest.raises(SystemExit) as done:
        importlib.import_module(f"graspexp.tools.{tool}").main(["--help"])
    assert done.value.code == 0
    assert capsys.readouterr().out.startswith(f"usage: graspexp {tool} ")


@pytest.mark.slow
def test_tools_run_as_subcommands_and_are_listed_in_the_help():
    proc = _graspexp("compare", "--help")
    assert proc.returncode == 0 and proc.stdout.startswith("usage: graspexp compare "), proc.stderr
    assert f"tools (python -m graspexp TOOL --help): {', '.join(TOOLS)}" in _graspexp("--help").stdout
    bad = _graspexp("report", "/no/such/dir")
    assert bad.returncode == 2 and bad.stderr == "graspexp report: error: /no/such/dir is not a directory\n"


def test_a_tool_with_a_bad_override_is_one_line(capsys):
    from graspexp.tools.plan import main

    with pytest.raises(SystemExit) as done:
        main(["objects=[mug]", "mode=foo"])
    assert done.value.code == 2
    assert capsys.readouterr().err == (
        "graspexp plan: error: In 'config': Could not find 'mode/foo'; Available options in 'mode': bin, collab, packed, pile\n"
    )
