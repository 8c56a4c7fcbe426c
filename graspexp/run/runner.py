"""The main job: every trial of every object of the dataset, one MCAP log per trial, a results table.

The run directory (Hydra's output dir) is laid out as :mod:`graspexp.core.run_layout` says. Re-running
into the same directory resumes (:mod:`graspexp.run.resume`): trials whose log is complete are read back,
not re-run, provided every log's recorded config equals this run's on every key that affects a result;
otherwise the job stops with :class:`graspexp.run.locks.RunError`. One job at a time writes into a directory (a file lock).
With ``record=false`` no log is written (faster, but nothing to replay); its rows are kept by later runs of
the same config under the same rule, through the run record (:mod:`graspexp.run.run_record`).

The job's steps live in modules of one concern each: provenance (what each log records), resume, objects
(loading, a trial's context), trial_loop (one object's trials) and summary (results.csv, summary.md).
"""

import sys
import time
from collections.abc import Callable
from pathlib import Path

from omegaconf import DictConfig, OmegaConf
from threadpoolctl import threadpool_limits
from tqdm import tqdm

from graspexp.config.mode import is_clutter
from graspexp.core.outcome import TrialResult
from graspexp.datasets import select_objects
from graspexp.record.live import live_channels
from graspexp.record.log_size import log_size_warning
from graspexp.run.job_config import make_ready
from graspexp.run.objects import LoadedObject, load_models
from graspexp.run.prepare import prepare_shapes
from graspexp.run.provenance import write_hydra_record
from graspexp.run.resume import (
    check_resumable,
    check_run_files,
    check_same_meshes,
    check_same_pool,
    job_lock,
    kept_results,
)
from graspexp.run.round_loop import clutter_pool, timed_rounds
from graspexp.run.run_record import table_results, write_run_record
from graspexp.run.summary import objective_value, write_summary
from graspexp.run.trial_loop import run_object_trials


def run_job(cfg: DictConfig) -> float:
    """Run every trial for every selected object; returns ``cfg.objective`` (:func:`objective_value`)."""
    from hydra.core.hydra_config import HydraConfig

    return run_in_dir(cfg, Path(HydraConfig.get().runtime.output_dir), write_hydra_record)


def run_in_dir(
    cfg: DictConfig, run_dir: Path, on_accepted: Callable[[DictConfig, Path], None] | None = None
) -> float:
    """:func:`run_job` into ``run_dir`` (resumable, locked), outside a Hydra run (e.g. the benchmark). The
    config is validated, then frozen: nothing in the job can change it (a write raises). ``on_accepted``
    runs once every check that can refuse the run has passed (before the first trial)."""
    make_ready(cfg)
    OmegaConf.set_readonly(cfg, True)
    with threadpool_limits(limits=1):  # trials are sequential: one core per job
        return _run(cfg, run_dir, on_accepted)


def _run(cfg: DictConfig, run_dir: Path, on_accepted: Callable[[DictConfig, Path], None] | None) -> float:
    """The checks that need no lock and write nothing into ``run_dir`` (inputs, the logs' config), the
    objects' loading, then under the lock the checks again and the trials: a refused run leaves
    ``run_dir`` as it found it."""
    wall0, cpu0 = time.perf_counter(), time.process_time()
    if cfg.live:  # a taken port refuses the run before anything is written (LiveViewError)
        live_channels(int(cfg.live_port))
    if warning := log_size_warning(cfg):
        print(f"graspexp: warning: {warning}", file=sys.stderr)
    objects = select_objects(cfg.dataset, cfg.objects)
    check_resumable(cfg, run_dir, move_foreign=False)
    prepare_shapes(cfg.dataset, cfg.sim, objects, cfg.progress)
    models, unusable = load_models(cfg, objects)
    with job_lock(run_dir):
        check_resumable(cfg, run_dir)
        check_same_meshes(run_dir, models)
        pool = None
        if is_clutter(cfg.mode):
            pool = [models[n] for n in clutter_pool(objects, models)]
            check_same_pool(run_dir, cfg.mode.name, pool, unusable)
        check_run_files(run_dir)
        write_run_record(cfg, run_dir, models, pool)
        if on_accepted is not None:
            on_accepted(cfg, run_dir)
        return _run_trials(cfg, run_dir, objects, models, unusable, wall0, cpu0)


def _run_trials(
    cfg: DictConfig,
    run_dir: Path,
    objects: list[str],
    models: dict[str, LoadedObject],
    unusable: dict[str, str],
    wall0: float,
    cpu0: float,
) -> float:
    if is_clutter(cfg.mode):
        return timed_rounds(cfg, run_dir, objects, models, wall0, cpu0)
    results: list[TrialResult] = []
    rows = table_results(run_dir)  # the rows of record=false runs of this config (no log behind them)
    with tqdm(
        total=len(objects) * cfg.trials,
        desc=f"{cfg.mode.name}/{cfg.rot.name}/{cfg.dataset.name}",
        disable=not cfg.progress,
    ) as bar:
        for name in objects:
            loaded = models.get(name) or unusable[name]
            results.extend(run_object_trials(cfg, name, run_dir, bar, loaded, finished_rows=rows))
    done = {(r.object, r.trial) for r in results}
    results += kept_results(run_dir, done)
    done |= {(r.object, r.trial) for r in results}
    results += [row for key, row in rows.items() if key not in done]
    df, text = write_summary(run_dir, results, models, unusable)
    print(
        f"\n{cfg.mode.name} / rot {cfg.rot.name} / {cfg.dataset.name} / planner {cfg.planner.name}: {run_dir}"
        f" ({len(df)} trials, {time.perf_counter() - wall0:.1f} s wall, {time.process_time() - cpu0:.1f} s CPU)"
    )
    print(text)
    return objective_value(df, cfg.objective)
