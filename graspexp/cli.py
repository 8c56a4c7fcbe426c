"""The one way every graspexp tool starts: ``python -m graspexp[.<tool>] [--option ...] [key=value ...]``.

- ``--option``: the tool's own options, parsed by :mod:`argparse` from :func:`tool_parser` (``-h`` /
  ``--help`` says ``graspexp.<tool>``; a bad option is ``usage`` plus one error line, exit status 2).
- ``key=value``: Hydra overrides of ``conf/config.yaml``, for the tools that take a job config. They are
  composed by :func:`compose_config`, the one place that composes outside a Hydra run, and checked by
  :func:`compose_checked` (one ``graspexp.<tool>: error:`` line and exit status 2 on a bad one).

``python -m graspexp`` (also the ``graspexp`` command) is the Hydra app itself, because a run needs Hydra's
output directories, multirun and launchers. :func:`run_checked` parses its Hydra flags with the same
argparse shape, prints graspexp's own help (config groups and their options, never the schemas), prints
the bash completion script, and checks every job's overrides before Hydra starts.
"""

import argparse
import itertools
import sys
from collections.abc import Callable, Sequence

from omegaconf import DictConfig

from graspexp.config import ConfigError, validate
from graspexp.config.plugins import PluginError, load_planners
from graspexp.config.registry import CONF_DIR, group_options, register_configs

OVERRIDES_HELP = "Hydra overrides of conf/config.yaml, e.g. dataset=ycb mode=bin planner.m=128"

COMPLETION_SCRIPT = """\
_graspexp_complete() {
    local choices
    choices=$(COMP_POINT=$COMP_POINT COMP_LINE="$COMP_LINE" "${COMP_WORDS[0]}" -sc query=bash 2>/dev/null)
    COMPREPLY=($(compgen -o nospace -o default -W "$choices" -- "${COMP_WORDS[COMP_CWORD]}"))
}
COMP_WORDBREAKS=${COMP_WORDBREAKS//=}
complete -o nospace -o default -F _graspexp_complete graspexp
"""
"""Bash completion of the ``graspexp`` command: the words come from Hydra's completion query
(``graspexp -sc query=bash``), which lists config groups, their options and config keys."""


def fail(message: str, prog: str = "graspexp") -> None:
    """Print ``<prog>: error: <message>`` on stderr and exit with status 2."""
    print(f"{prog}: error: {message}", file=sys.stderr)
    raise SystemExit(2)


def tool_parser(prog: str, description: str, overrides: bool = False) -> argparse.ArgumentParser:
    """The argument parser every tool starts from: ``prog`` (``graspexp.<tool>``) in its usage and errors;
    with ``overrides`` it takes any number of ``key=value`` Hydra overrides (``args.overrides``), anywhere
    among the options (parse them with ``parse_intermixed_args``)."""
    parser = argparse.ArgumentParser(
        prog=prog, description=description, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    if overrides:
        parser.add_argument("overrides", nargs="*", metavar="key=value", help=OVERRIDES_HELP)
    return parser


def compose_config(overrides: Sequence[str], config_name: str = "config") -> DictConfig:
    """The job config composed from ``conf/`` with Hydra overrides, outside any Hydra run (no output
    folder), not validated (see :func:`compose_checked`)."""
    from hydra import compose, initialize_config_dir
    from hydra.core.global_hydra import GlobalHydra

    register_configs()
    GlobalHydra.instance().clear()
    try:
        with initialize_config_dir(config_dir=CONF_DIR, version_base="1.3"):
            return compose(config_name, overrides=list(overrides))
    finally:
        GlobalHydra.instance().clear()


def _one_line(exc: BaseException) -> str:
    text = str(exc) + ("\n" + str(exc.__cause__) if exc.__cause__ is not None else "")
    lines = [ln.strip() for ln in text.splitlines() if ln.strip()]
    msg = lines[0] if lines else type(exc).__name__
    for i, ln in enumerate(lines):
        if ln.startswith("Available options"):
            opts = [o for o in lines[i + 1 :] if not o.startswith(("Config search path", "provider="))]
            return f"{msg}; {ln.rstrip(':')}: {', '.join(opts)}"
    if len(lines) > 1 and lines[0].startswith(("Could not override", "Error merging override")):
        detail = next(
            (x for x in lines[1:] if not x.startswith(("To append", "full_key", "object_type"))), ""
        )
        return f"{msg} {detail}".strip()
    return msg


def _check_planner_plugins(overrides: Sequence[str]) -> None:
    """A broken planner plugin named by ``planner=``: its own error (naming the package), not "not found"."""
    for o in overrides:
        if o.startswith("planner="):
            for name in o.split("=", 1)[1].split(","):
                if isinstance(load_planners().get(name), PluginError):
                    raise load_planners()[name]


def config_error(exc: Exception) -> str:
    """The one-line message of a composition or validation error."""
    return str(exc) if isinstance(exc, (ConfigError, PluginError)) else _one_line(exc)


def compose_checked(overrides: Sequence[str], prog: str = "graspexp") -> DictConfig:
    """The validated job config of ``overrides``; a bad override exits with ``<prog>: error:`` (status 2)."""
    try:
        _check_planner_plugins(overrides)
        cfg = compose_config(overrides)
        validate(cfg)
    except Exception as exc:  # Hydra/OmegaConf/config errors: the reason, not the traceback
        fail(config_error(exc), prog)
    return cfg


def expand_sweeps(overrides: Sequence[str]) -> list[list[str]]:
    """Every combination of a multirun's overrides (``mode=collab,bin rot=z,xyz`` -> 4 override lists),
    in the order Hydra's basic sweeper launches them; ``hydra.*`` overrides are left out."""
    from hydra.core.override_parser.overrides_parser import OverridesParser

    mine = [o for o in overrides if not o.lstrip("+~").startswith("hydra")]
    choices: dict[str, list[str]] = {}
    for o in OverridesParser.create().parse_overrides(mine):
        key = o.get_key_element()
        if o.is_sweep_override():
            choices[key] = [f"{key}={v}" for v in o.sweep_string_iterator()]
        else:
            choices[key] = [f"{key}={o.get_value_element_as_str()}"]
    return [list(combo) for combo in itertools.product(*choices.values())]


def check_overrides(overrides: Sequence[str], multirun: bool = True) -> None:
    """Compose and validate every combination of the (possibly swept) overrides; exit 2 on the first error
    (also for a sweep without ``multirun``)."""
    try:
        combos = expand_sweeps(overrides)
    except Exception as exc:  # a syntax error in an override
        fail(_one_line(exc))
    if len(combos) > 1 and not multirun:
        swept = [o for o in overrides if len(expand_sweeps([o])) > 1]
        fail(
            f"{' '.join(swept)} sweeps over several values: add -m (--multirun), or give a list as key=[a,b]"
        )
    for combo in combos:
        compose_checked(combo)


def _groups_epilog() -> str:
    lines = ["config groups (group=option; keys as group.key=value, e.g. planner.m=128):"]
    lines += [
        f"  {g}: {', '.join(group_options(g))}"
        for g in ("dataset", "mode", "rot", "gripper", "planner", "cost", "sim")
    ]
    lines.append(
        "top-level keys: trials, seed, objects, record, live, live_port, progress, perception.noise.*"
    )
    lines.append(
        'bash completion of the graspexp command: eval "$(graspexp --shell-completion install=bash)"'
    )
    return "\n".join(lines)


def main_parser() -> argparse.ArgumentParser:
    """The parser of ``python -m graspexp``: Hydra's flags that graspexp supports, and the overrides."""
    parser = argparse.ArgumentParser(
        prog="graspexp",
        description="Run grasp trials for every object of a dataset (python -m graspexp, or graspexp).",
        epilog=_groups_epilog(),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("overrides", nargs="*", metavar="key=value", help=OVERRIDES_HELP)
    modes = parser.add_mutually_exclusive_group()
    modes.add_argument("-r", "--run", action="store_true", help="run one job (the default)")
    modes.add_argument(
        "-m", "--multirun", action="store_true", help="one job per combination of comma-separated values"
    )
    modes.add_argument(
        "-c", "--cfg", choices=["job", "hydra", "all"], help="print the composed config instead of running"
    )
    modes.add_argument(
        "-i",
        "--info",
        nargs="?",
        const="all",
        choices=["all", "config", "defaults", "defaults-tree", "plugins", "searchpath"],
        help="print Hydra information",
    )
    modes.add_argument(
        "-sc",
        "--shell-completion",
        action="store_true",
        help="with install=bash: print the bash completion script (uninstall=bash: remove it)",
    )
    modes.add_argument("--hydra-help", action="store_true", help="Hydra's own help")
    parser.add_argument("--resolve", action="store_true", help="with --cfg: resolve interpolations")
    parser.add_argument("-p", "--package", help="with --cfg: the config package to print")
    return parser


def _shell_completion(words: list[str], hydra_main: Callable[[], object]) -> None:
    if words == ["install=bash"]:
        print(COMPLETION_SCRIPT, end="")
    elif words == ["uninstall=bash"]:
        print("complete -r graspexp; unset -f _graspexp_complete")
    elif words == ["query=bash"]:
        hydra_main()  # Hydra answers the query (COMP_LINE) from the config groups and keys
    else:
        fail(f"--shell-completion needs install=bash, uninstall=bash or query=bash, got {' '.join(words)!r}")


def run_checked(hydra_main: Callable[[], object], argv: list[str] | None = None) -> None:
    """Parse ``python -m graspexp``'s command line (:func:`main_parser`), check its overrides, then hand over
    to the Hydra main function (which reads ``sys.argv`` itself)."""
    argv = sys.argv[1:] if argv is None else argv
    parser = main_parser()
    args = parser.parse_intermixed_args(argv)
    if args.shell_completion:
        _shell_completion(args.overrides, hydra_main)
        return
    if not (args.hydra_help or args.info):
        check_overrides(args.overrides, multirun=args.multirun)
    hydra_main()
