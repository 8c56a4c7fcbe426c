"""An Optuna study's history as a table and plots: the objective against each searched parameter, and
against the trial number with the best so far (matplotlib, headless).

Parameter names are the Hydra override keys the study searched (``cost.angle_weight``); the objective is
what each job returned (``objective`` in the job config, a fraction in [0, 1]).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
from omegaconf import OmegaConf  # noqa: E402

if TYPE_CHECKING:
    import optuna

TRIALS_CSV = "optuna_trials.csv"
"""The study's history in its sweep directory: one row per trial (number, state, value, parameters, s)."""
STUDY_YAML = "optuna_study.yaml"
"""Written into the sweep directory when a study starts: its storage URL, name and overrides."""
PARAMS_PNG = "study_params.png"
HISTORY_PNG = "study_history.png"
BASELINE_COLOUR = "#d62728"


FINISHED_STATES = ("COMPLETE", "FAIL", "PRUNED")
"""Names of the trial states that count as done; RUNNING and WAITING do not."""


def searched_keys(overrides: list[str]) -> list[str]:
    """The keys of the overrides that give a search space (``interval``, ``choice``, ``range``, ``a,b``),
    in command-line order; ``hydra.*`` overrides are not searched."""
    from hydra.core.override_parser.overrides_parser import OverridesParser

    mine = [o for o in overrides if not o.lstrip("+~").startswith("hydra")]
    return [
        o.get_key_element() for o in OverridesParser.create().parse_overrides(mine) if o.is_sweep_override()
    ]


def load_study(storage: str, study_name: str) -> optuna.Study:
    """The stored study; ValueError (one line) when the storage holds no study of that name."""
    import optuna

    try:
        return optuna.load_study(study_name=study_name, storage=storage)
    except KeyError:
        raise ValueError(f"no Optuna study {study_name!r} in {storage}") from None


@dataclass(frozen=True)
class SweepStudy:
    """An Optuna study found in a sweep directory, with the command line that made it."""

    study: optuna.Study
    storage: str
    task_overrides: list[str]
    """The sweep's overrides (``hydra.overrides.task`` of ``multirun.yaml``), search ranges included."""

    @property
    def searched(self) -> list[str]:
        return searched_keys(self.task_overrides)


def sqlite_path(storage: str) -> Path | None:
    """The database file of an SQLite storage URL (``sqlite:///rel/path.db``, ``sqlite:////abs/path.db``);
    None for any other storage."""
    prefix = "sqlite:///"
    return Path(storage[len(prefix) :]) if storage.startswith(prefix) else None


def write_study_record(
    sweep_dir: Path, storage: str, study_name: str, task_overrides: list[str], inputs: dict[str, str]
) -> None:
    """Write :data:`STUDY_YAML` into ``sweep_dir``: where the study is stored, the command's overrides and
    the inputs its trials read (data root, mesh SHA-256s: :func:`graspexp.run.study.study_inputs`)."""
    record = {
        "storage": storage,
        "study_name": study_name,
        "task_overrides": task_overrides,
        "inputs": inputs,
    }
    OmegaConf.save(OmegaConf.create(record), sweep_dir / STUDY_YAML)


def recorded_inputs(sweep_dir: Path) -> dict[str, str]:
    """The inputs recorded with the study in ``sweep_dir`` ({} for none, or a study recorded before them)."""
    path = sweep_dir / STUDY_YAML
    if not path.is_file():
        return {}
    inputs = OmegaConf.load(path).get("inputs")
    return {str(k): str(v) for k, v in inputs.items()} if inputs else {}


def recorded_overrides(sweep_dir: Path) -> list[str] | None:
    """The overrides of the study recorded in ``sweep_dir`` (:data:`STUDY_YAML`); None when there is none."""
    path = sweep_dir / STUDY_YAML
    return [str(o) for o in OmegaConf.load(path).task_overrides] if path.is_file() else None


def read_sweep_study(sweep_dir: Path) -> SweepStudy:
    """The study of the sweep in ``sweep_dir`` (its :data:`STUDY_YAML`; an SQLite file of that name in
    ``sweep_dir`` is used wherever the study ran from); ValueError (one line) when there is none."""
    path = sweep_dir / STUDY_YAML
    if not path.is_file():
        raise ValueError(f"{sweep_dir} holds no Optuna study: no {STUDY_YAML} (run with hydra/sweeper=study)")
    record = OmegaConf.load(path)
    storage = str(record.storage)
    db = sqlite_path(storage)
    if db is not None and (sweep_dir / db.name).is_file():
        storage = f"sqlite:///{sweep_dir / db.name}"
    study = load_study(storage, str(record.study_name))
    return SweepStudy(study, storage, [str(o) for o in record.task_overrides])


def study_table(study: optuna.Study) -> pd.DataFrame:
    """One row per trial: ``number``, ``state``, ``value`` (NaN unless COMPLETE; ``value_0``, ``value_1``,
    ... for several objectives), one column per parameter (its override key), ``duration_s`` (wall
    seconds, NaN while running)."""
    rows = []
    for t in study.get_trials(deepcopy=False):
        duration = t.duration.total_seconds() if t.duration is not None else np.nan
        values = t.values if t.state.name == "COMPLETE" and t.values else [np.nan] * len(study.directions)
        named = {"value": values[0]} if len(values) == 1 else {f"value_{i}": v for i, v in enumerate(values)}
        rows.append({"number": t.number, "state": t.state.name, **named, **t.params, "duration_s": duration})
    return pd.DataFrame(rows)


def is_log_scale(distribution: object) -> bool:
    """Whether an Optuna distribution was searched on a log scale (``tag(log, interval(...))``)."""
    return bool(getattr(distribution, "log", False)) or type(distribution).__name__.startswith("LogUniform")


def plot_study(study: optuna.Study, out_dir: Path) -> list[Path]:
    """Write :data:`PARAMS_PNG` (the objective against each parameter; trial 0, the config's own values,
    in red; log axes where the search was on a log scale) and :data:`HISTORY_PNG` (the objective per trial
    and the best so far) into ``out_dir``; returns their paths (none when no trial completed or the study
    has several objectives)."""
    done = [t for t in study.get_trials(deepcopy=False) if t.state.name == "COMPLETE"]
    if not done or len(study.directions) > 1:  # the plots show one objective
        return []
    out_dir.mkdir(parents=True, exist_ok=True)
    names = list(dict.fromkeys(k for t in done for k in t.params))
    ncols = min(3, max(1, len(names)))
    nrows = int(np.ceil(len(names) / ncols))
    fig, axes = plt.subplots(nrows, ncols, figsize=(4.2 * ncols, 3.2 * nrows), squeeze=False, sharey=True)
    for ax, name in zip(axes.flat, names, strict=False):
        pts = [(t.params[name], t.value, t.number) for t in done if name in t.params]
        x, y, n = (np.array(v) for v in zip(*pts, strict=True))
        ax.scatter(x[n != 0], y[n != 0], s=18)
        ax.scatter(x[n == 0], y[n == 0], s=40, color=BASELINE_COLOUR, zorder=3)  # on top of ties
        if is_log_scale(done[-1].distributions.get(name)):
            ax.set_xscale("log")
        ax.set_xlabel(name)
    for ax in axes.flat[len(names) :]:
        ax.set_visible(False)
    for ax in axes[:, 0]:
        ax.set_ylabel("objective")
    fig.suptitle(f"study {study.study_name}: objective per parameter (red: trial 0, the config's values)")
    fig.tight_layout()
    params_png = out_dir / PARAMS_PNG
    fig.savefig(params_png, dpi=110)
    plt.close(fig)

    fig, ax = plt.subplots(figsize=(6.5, 3.4))
    num = np.array([t.number for t in done])
    val = np.array([t.value for t in done], dtype=float)
    ax.scatter(num, val, s=18, label="trial")
    best = np.minimum if study.direction.name == "MINIMIZE" else np.maximum
    ax.step(num, best.accumulate(val), where="post", color="black", lw=1, label="best so far")
    ax.set_xlabel("trial number")
    ax.set_ylabel("objective")
    ax.set_title(f"study {study.study_name}: {len(done)} completed trial(s)")
    ax.legend(loc="lower right")
    fig.tight_layout()
    history_png = out_dir / HISTORY_PNG
    fig.savefig(history_png, dpi=110)
    plt.close(fig)
    return [params_png, history_png]
