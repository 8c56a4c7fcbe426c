"""The one way every graspexp tool starts: ``python -m graspexp <tool> [--option ...] [key=value ...]``.

- ``--option``: the tool's own options, parsed by :mod:`argparse` from :func:`tool_parser` (``-h`` /
  ``--help`` says ``graspexp <tool>``; a bad option is ``usage`` plus one error line, exit status 2).
- ``key=value``: Hydra overrides of the job config (``conf/config.yaml``), for the tools that take
  one. They are composed by :func:`graspexp.run.job_config.compose_job`, the one place that composes
  outside a Hydra run, which raises :class:`~graspexp.config.ConfigError`; :func:`compose_checked` turns it
  into one ``graspexp <tool>: error:`` line and exit status 2.

``python -m graspexp`` without a tool (also the ``graspexp`` command) is the Hydra app itself, because a
run needs Hydra's output directories, multirun and launchers. :func:`run_checked` parses its Hydra flags
with the same argparse shape, prints graspexp's own help (config groups and their options, never the
schemas, and the tools), prints the bash completion script, and checks every job's overrides before Hydra
starts.
"""

import argparse
import sys
from collections.abc import Callable, Sequence

from omegaconf import DictConfig

from graspexp.config import ConfigError
from graspexp.config.compose import expand_sweeps, one_line, search_problems, search_ranges
from graspexp.config.registry import group_options
from graspexp.run.job_config import compose_job
from graspexp.run.launchers import submitit_guard
from graspexp.tools import TOOLS

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


def positive_int(text: str) -> int:
    """An argparse type: an integer >= 1 (``--n-jobs 0`` is refused at once, not after the work)."""
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected an integer >= 1, got {text!r}") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected an integer >= 1, got {value}")
    return value


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


def compose_checked(overrides: Sequence[str], prog: str = "graspexp") -> DictConfig:
    """The validated job config of ``overrides``; a bad override exits with ``<prog>: error:`` (status 2)."""
    try:
        return compose_job(overrides)
    except ConfigError as exc:
        fail(str(exc), prog)
        raise  # unreachable: fail exits


def take_sweep(overrides: Sequence[str], key: str, default: Sequence[str]) -> tuple[list[str], list[str]]:
    """The values a tool sweeps itself for ``key`` (Hydra's syntax: ``key=a,b``, or one value), else
    ``default``, and the other overrides; a malformed override exits with one line."""
    from hydra.core.override_parser.overrides_parser import OverridesParser

    values, rest = list(default), []
    for text in overrides:
        try:
            (o,) = OverridesParser.create().parse_overrides([text])
        except Exception as exc:  # a syntax error in an override
            fail(one_line(exc))
        if o.get_key_element() != key:
            rest.append(text)
        elif o.is_sweep_override():
            values = [str(v) for v in o.sweep_string_iterator()]
        else:
            values = [o.get_value_element_as_str()]
    return values, rest


def check_overrides(overrides: Sequence[str], multirun: bool = True) -> None:
    """Compose and validate every combination of the (possibly swept) overrides; exit 2 on the first error
    (also for a sweep without ``multirun``)."""
    try:
        combos = expand_sweeps(overrides)
    except Exception as exc:  # a syntax error in an override
        fail(one_line(exc))
    if len(combos) > 1 and not multirun:
        swept = [o for o in overrides if len(expand_sweeps([o])) > 1]
        fail(
            f"{' '.join(swept)} sweeps over several values: add -m (--multirun), or give a list as key=[a,b]"
        )
    ranges = search_ranges(overrides)
    if ranges and not any(o.startswith("hydra/sweeper=") for o in overrides):
        fail(
            f"{' '.join(ranges)} is a search range, which only an Optuna study draws from: add hydra/sweeper=study"
        )
    problems = search_problems(overrides)
    if problems:
        fail(problems[0])
    for combo in combos:
        compose_checked(combo)


def _groups_epilog() -> str:
    lines = ["config groups (group=option; keys as group.key=value, e.g. planner.m=128):"]
    lines += [
        f"  {g}: {', '.join(group_options(g))}"
        for g in ("dataset", "mode", "rot", "gripper", "planner", "cost", "sim")
    ]
    lines.append(
        "top-level keys: trials, seed, objects, record, live, live_port, progress, objective, perception.noise.*"
    )
    lines.append(f"tools (python -m graspexp TOOL --help): {', '.join(TOOLS)}")
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
    with submitit_guard(args.overrides if args.multirun else ()):
        hydra_main()
