"""Compose a job config outside a Hydra run: the package's configs (:data:`CONF_DIR`) with Hydra
overrides, validated. Every problem (a bad override, an unknown option, a broken planner plugin, a value
out of range) is one :class:`ConfigError` whose message is one line naming it; the tools print it and exit
with status 2."""

import itertools
from collections.abc import Sequence

from omegaconf import DictConfig

from graspexp.config.plugins import PluginError, load_planners
from graspexp.config.registry import CONF_DIR, register_configs
from graspexp.config.validate import ConfigError, validate


def compose_config(overrides: Sequence[str], config_name: str = "config") -> DictConfig:
    """The job config composed from :data:`CONF_DIR` with Hydra overrides, outside any Hydra run (no
    output folder), not validated (see :func:`compose_validated`); Hydra's and OmegaConf's errors as they
    are."""
    from hydra import compose, initialize_config_dir
    from hydra.core.global_hydra import GlobalHydra

    register_configs()
    GlobalHydra.instance().clear()
    try:
        with initialize_config_dir(config_dir=CONF_DIR, version_base="1.3"):
            return compose(config_name, overrides=list(overrides))
    finally:
        GlobalHydra.instance().clear()


def one_line(exc: BaseException) -> str:
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
    return str(exc) if isinstance(exc, (ConfigError, PluginError)) else one_line(exc)


def compose_validated(overrides: Sequence[str]) -> DictConfig:
    """The validated job config of ``overrides``; :class:`ConfigError` (one line) for any problem."""
    try:
        _check_planner_plugins(overrides)
        cfg = compose_config(overrides)
        validate(cfg)
    except ConfigError:
        raise
    except Exception as exc:  # Hydra/OmegaConf/plugin errors: the reason, not the traceback
        raise ConfigError(config_error(exc)) from None
    return cfg


def search_ranges(overrides: Sequence[str]) -> list[str]:
    """The overrides that give a continuous search range (``interval(a, b)``, tagged or not), which only a
    sampling sweeper (Optuna) can draw from."""
    from hydra.core.override_parser.overrides_parser import OverridesParser
    from hydra.core.override_parser.types import IntervalSweep

    mine = [o for o in overrides if not o.lstrip("+~").startswith("hydra")]
    parsed = OverridesParser.create().parse_overrides(mine)
    return [text for text, o in zip(mine, parsed, strict=True) if isinstance(o.value(), IntervalSweep)]


def search_problems(overrides: Sequence[str]) -> list[str]:
    """Why an Optuna study of ``overrides`` could not start, found before Hydra does: a search range whose
    lower end is not below its upper end (a log range: not above 0), ``hydra.sweeper.n_trials`` not a
    positive integer. One message per problem, naming the override."""
    from hydra.core.override_parser.overrides_parser import OverridesParser
    from hydra.core.override_parser.types import IntervalSweep

    problems = []
    for text, o in zip(overrides, OverridesParser.create().parse_overrides(list(overrides)), strict=True):
        value = o.value()
        if isinstance(value, IntervalSweep):
            lo, hi = float(value.start), float(value.end)
            if not lo < hi:
                problems.append(
                    f"{text}: the search range's lower end {lo:g} is not below its upper end {hi:g}"
                )
            elif "log" in value.tags and not lo > 0:
                problems.append(f"{text}: a log search range needs a lower end above 0, got {lo:g}")
        elif o.get_key_element() == "hydra.sweeper.n_trials":
            n = value if isinstance(value, int) and not isinstance(value, bool) else None
            if n is None or n < 1:
                problems.append(f"{text}: the number of trials of a study must be a positive integer")
    return problems


def expand_sweeps(overrides: Sequence[str]) -> list[list[str]]:
    """Every combination of a multirun's overrides (``mode=collab,bin rot=z,xyz`` -> 4 override lists),
    in the order Hydra's basic sweeper launches them; ``hydra.*`` overrides are left out. An Optuna
    search range (``interval(a, b)``, also tagged: ``tag(log, interval(a, b))``) stands for its two ends,
    so both are checked; ``choice(...)`` and ``range(...)`` for each of their values."""
    from hydra.core.override_parser.overrides_parser import OverridesParser
    from hydra.core.override_parser.types import IntervalSweep

    mine = [o for o in overrides if not o.lstrip("+~").startswith("hydra")]
    choices: dict[str, list[str]] = {}
    for o in OverridesParser.create().parse_overrides(mine):
        key = o.get_key_element()
        value = o.value()
        if isinstance(value, IntervalSweep):
            choices[key] = [f"{key}={end!r}" for end in (value.start, value.end)]
        elif o.is_sweep_override():
            choices[key] = [f"{key}={v}" for v in o.sweep_string_iterator()]
        else:
            choices[key] = [f"{key}={o.get_value_element_as_str()}"]
    return [list(combo) for combo in itertools.product(*choices.values())]
