"""An Optuna study of ``python -m graspexp -m hydra/sweeper=study ...`` (or ``hydra/sweeper=optuna`` with
``hydra.sweeper.storage=sqlite:///...``), resumable and saved with its sweep.

:class:`OptunaStudy` is a Hydra callback (``hydra.callbacks`` in ``conf/config.yaml``) that acts only when
the sweeper has a ``storage``:

- before the sweep, it creates the sweep directory (SQLite needs the folder of its file), records the
  study's storage and command there (:data:`graspexp.report.study.STUDY_YAML`) and, for a new
  study, enqueues the config's own values of the searched keys as trial 0 (the paper's constants are
  scored under the same conditions as every candidate);
- a sweep directory holding a study of other overrides (``hydra.*`` aside) is refused in one line;
- for a study that already has trials (the same command run again after a kill), it marks the trials left
  ``RUNNING`` as FAIL and enqueues their parameters again (with ``record=true`` their job directory, named
  by the same overrides, resumes from its logs), and runs only what is missing to reach
  ``hydra.sweeper.n_trials`` finished trials (counted over the whole study: a finished study runs nothing;
  raise ``n_trials`` to extend it), with the sampler's seed moved on by the number of trials so far (a
  seeded sampler would otherwise draw the first run's parameters again);
- after the sweep, it writes the study's history (:data:`graspexp.report.study.TRIALS_CSV`, one row per trial) and its plots
  (:func:`graspexp.report.study.plot_study`) into the sweep directory.
"""

from __future__ import annotations

import logging
import sys
from pathlib import Path
from typing import Any

from hydra.experimental.callback import Callback
from omegaconf import DictConfig, OmegaConf, read_write

log = logging.getLogger(__name__)
INTERRUPTED = "graspexp_interrupted"
"""System attribute of a trial whose process was killed: marked FAIL, run again, not counted as finished."""


def _as_dict(overrides: list[str]) -> dict[str, str]:
    """key -> value of command-line overrides, the last of a repeated key winning (as in Hydra)."""
    return {k: v for k, _, v in (o.partition("=") for o in overrides)}


def _directions(direction: Any) -> list[str]:
    """The sweeper's ``direction`` (a name, its Enum, or a list of either) as Optuna's direction names."""
    items = list(direction) if OmegaConf.is_list(direction) or isinstance(direction, list) else [direction]
    return [str(getattr(d, "name", d)) for d in items]


def _refuse(message: str) -> None:
    """A study that cannot start or resume: one ``graspexp: error:`` line, exit status 2."""
    print(f"graspexp: error: {message}", file=sys.stderr)
    raise SystemExit(2)


def study_inputs(config: DictConfig) -> dict[str, str]:
    """What a study's trials read besides their config: the data root and the SHA-256 of each selected
    object's mesh (as every trial log records it), recorded with the study and compared on resume: the
    same command on another data root (``record=false`` leaves no log to compare) must not mix meshes."""
    from graspexp.datasets import DatasetError, job_object, resolve_root, select_objects

    out = {"data_root": str(resolve_root(config.dataset).resolve())}
    try:
        names = select_objects(config.dataset, config.objects)
    except DatasetError:
        return out  # the first job says what is missing
    for name in names:
        try:
            out[f"mesh.{name}"] = job_object(config, name).mesh_sha256
        except DatasetError as exc:
            out[f"mesh.{name}"] = f"unusable: {str(exc)[:80]}"
    return out


class OptunaStudy(Callback):
    """Resume an Optuna study stored with its sweep, baseline first; save its history and plots at the end."""

    def on_multirun_start(self, config: DictConfig, **kwargs: Any) -> None:
        sweeper = config.hydra.sweeper
        storage = OmegaConf.select(sweeper, "storage", default=None)
        if not storage:
            return
        from graspexp.report.study import (  # here, not at the top: every job instantiates this callback
            FINISHED_STATES,
            recorded_inputs,
            recorded_overrides,
            searched_keys,
            sqlite_path,
            write_study_record,
        )

        overrides = [str(o) for o in config.hydra.overrides.task]
        recorded = recorded_overrides(Path(config.hydra.sweep.dir))
        if recorded is not None:
            old, new = _as_dict(recorded), _as_dict(overrides)
            changed = [
                f"{k}: {old.get(k, '<absent>')} in the study, {new.get(k, '<absent>')} now"
                for k in sorted(old.keys() | new.keys())
                if old.get(k) != new.get(k)
            ]
            if changed:
                _refuse(
                    f"{config.hydra.sweep.dir} holds a study of another command ({'; '.join(changed)}); a "
                    "study resumes only with the same overrides: use another hydra.sweep.dir"
                )
        db = sqlite_path(str(storage))
        Path(config.hydra.sweep.dir).mkdir(parents=True, exist_ok=True)
        if db is not None:
            db.parent.mkdir(parents=True, exist_ok=True)
        inputs = study_inputs(config)
        recorded_in = recorded_inputs(Path(config.hydra.sweep.dir))
        changed_in = [k for k in sorted(recorded_in) if recorded_in[k] != inputs.get(k)]
        if recorded_in and changed_in:
            key = changed_in[0]
            _refuse(
                f"{config.hydra.sweep.dir} holds a study made on other inputs ({key}: "
                f"{recorded_in.get(key, '<absent>')[:60]} in the study, {inputs.get(key, '<absent>')[:60]} now); "
                "a study resumes only on the same data root and meshes: use another hydra.sweep.dir"
            )
        import optuna

        try:
            study = optuna.create_study(
                study_name=sweeper.study_name,
                storage=str(storage),
                directions=_directions(sweeper.direction),
                load_if_exists=True,
            )
        except Exception as exc:  # a damaged or foreign database: SQLAlchemy's and Optuna's many types
            why = " ".join(str(exc).split())[:200]
            _refuse(
                f"the study's storage {storage} cannot be opened ({type(exc).__name__}: {why}); move the damaged "
                "file aside or use another hydra.sweep.dir"
            )
        write_study_record(
            Path(config.hydra.sweep.dir), str(storage), str(sweeper.study_name), overrides, inputs
        )
        keys = searched_keys(overrides)
        trials = study.get_trials(deepcopy=False)
        if not trials:
            choices = config.hydra.runtime.choices  # a searched config group: its default option
            baseline = {k: choices[k] if k in choices else OmegaConf.select(config, k) for k in keys}
            study.enqueue_trial(baseline)
            log.info("study %s: trial 0 scores the config's own values %s", study.study_name, baseline)
        for t in trials:
            if t.state == optuna.trial.TrialState.RUNNING:  # its process was killed: run it again
                study._storage.set_trial_system_attr(t._trial_id, INTERRUPTED, True)
                study.tell(t.number, state=optuna.trial.TrialState.FAIL)
                study.enqueue_trial(t.params)
                log.info("study %s: trial %d was interrupted; it runs again", study.study_name, t.number)
        finished = sum(t.state.name in FINISHED_STATES and INTERRUPTED not in t.system_attrs for t in trials)
        if finished:
            left = max(0, int(sweeper.n_trials) - finished)
            log.info("study %s resumes: %d trial(s) finished, %d to go", study.study_name, finished, left)
            with read_write(sweeper):
                sweeper.n_trials = left
                if OmegaConf.select(sweeper, "sampler.seed") is not None:  # not the first run's draws again
                    sweeper.sampler.seed = int(sweeper.sampler.seed) + len(trials)

    def on_multirun_end(self, config: DictConfig, **kwargs: Any) -> None:
        sweeper = config.hydra.sweeper
        storage = OmegaConf.select(sweeper, "storage", default=None)
        if not storage:
            return
        from graspexp.report.study import TRIALS_CSV, load_study, plot_study, study_table

        study = load_study(str(storage), str(sweeper.study_name))
        sweep_dir = Path(config.hydra.sweep.dir)
        table = study_table(study)
        table.to_csv(sweep_dir / TRIALS_CSV, index=False)
        written = plot_study(study, sweep_dir)
        print(f"graspexp: study history: {sweep_dir / TRIALS_CSV}, {', '.join(map(str, written))}")
