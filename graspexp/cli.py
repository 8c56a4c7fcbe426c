"""Command-line plumbing shared by the Hydra entry points: overrides are checked before Hydra runs,
so a typo, a wrong type or an out-of-range value is one line on stderr and exit status 2."""

import sys
from collections.abc import Callable

from omegaconf import DictConfig

from graspexp.config import ConfigError, register_configs, validate
from graspexp.config.plugins import PluginError, load_planners
from graspexp.config.registry import CONF_DIR

_VALUE_FLAGS = {
    "--cfg",
    "-c",
    "--package",
    "-p",
    "--config-path",
    "-cp",
    "--config-name",
    "-cn",
    "--config-dir",
    "-cd",
}


_MODE_FLAGS = {
    "--run": "--run",
    "-r": "--run",
    "--multirun": "--multirun",
    "-m": "--multirun",
    "--cfg": "--cfg",
    "-c": "--cfg",
    "--info": "--info",
    "-i": "--info",
    "--shell-completion": "--shell-completion",
    "-sc": "--shell-completion",
}
"""Hydra's mutually exclusive modes (its own check raises a traceback), short flag -> name."""


def split_argv(argv: list[str]) -> list[str]:
    """The override tokens of a Hydra command line (flags and their values removed)."""
    out, skip = [], False
    for tok in argv:
        if skip:
            skip = False
        elif tok in _VALUE_FLAGS:
            skip = True
        elif not tok.startswith("-"):
            out.append(tok)
    return out


def _one_line(exc: BaseException) -> str:
    text = str(exc) + ("\n" + str(exc.__cause__) if exc.__cause__ is not None else "")
    lines = [ln.strip() for ln in text.splitlines() if ln.strip()]
    msg = lines[0] if lines else type(exc).__name__
    for i, ln in enumerate(lines):
        if ln.startswith("Available options"):
            opts = [
                o for o in lines[i + 1 :] if not o.startswith(("Config search path", "provider=", "base_"))
            ]
            return f"{msg}; {ln.rstrip(':')}: {', '.join(opts)}"
    if len(lines) > 1 and lines[0].startswith(("Could not override", "Error merging override")):
        detail = next(
            (x for x in lines[1:] if not x.startswith(("To append", "full_key", "object_type"))), ""
        )
        return f"{msg} {detail}".strip()
    return msg


def compose_config(overrides: list[str], config_name: str = "config") -> DictConfig:
    """The job config composed from ``conf/`` with Hydra overrides, outside any Hydra run."""
    from hydra import compose, initialize_config_dir
    from hydra.core.global_hydra import GlobalHydra

    register_configs()
    GlobalHydra.instance().clear()
    try:
        with initialize_config_dir(config_dir=CONF_DIR, version_base="1.3"):
            return compose(config_name, overrides=list(overrides))
    finally:
        GlobalHydra.instance().clear()


def check_overrides(overrides: list[str], config_name: str = "config") -> None:
    """Compose every combination of the (possibly swept) overrides and validate it; exit 2 on error."""
    from hydra._internal.core_plugins.basic_sweeper import BasicSweeper
    from hydra.core.override_parser.overrides_parser import OverridesParser

    mine = [o for o in overrides if not o.lstrip("+~").startswith("hydra")]
    try:
        for o in mine:  # a broken planner plugin: its own error (naming the package), not "not found"
            if o.startswith("planner="):
                for name in o.split("=", 1)[1].split(","):
                    if isinstance(load_planners().get(name), PluginError):
                        raise load_planners()[name]
        parsed = OverridesParser.create().parse_overrides(mine)
        for batch in BasicSweeper.split_arguments(parsed, None):
            for combo in batch:
                validate(compose_config(combo, config_name))
    except (ConfigError, PluginError) as exc:
        fail(str(exc))
    except Exception as exc:  # Hydra/OmegaConf errors: report the reason, not the traceback
        fail(_one_line(exc))


def fail(message: str) -> None:
    """Print ``graspexp: error: <message>`` on stderr and exit with status 2."""
    print(f"graspexp: error: {message}", file=sys.stderr)
    raise SystemExit(2)


def run_checked(hydra_main: Callable[[], object], argv: list[str] | None = None) -> None:
    """Check the command line's overrides, then hand over to the Hydra main function."""
    argv = sys.argv[1:] if argv is None else argv
    modes = sorted({_MODE_FLAGS[a] for a in argv if a in _MODE_FLAGS})
    if len(modes) > 1:
        fail(f"{' and '.join(modes)} cannot be combined: give only one of --run, --multirun, --cfg, --info")
    if not any(a in ("--help", "-h", "--hydra-help", "--info", "-i") for a in argv):
        check_overrides(split_argv(argv))
    hydra_main()
