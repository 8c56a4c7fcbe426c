"""Score an Optuna study's best parameters beside the baseline (the config's own values of the searched
keys: the paper's constants) on another object split, with the study's other settings unchanged.

Each set is one job (:func:`graspexp.run.runner.run_in_dir`) in ``SWEEP_DIR/score/<split>_<label>``, so
a second call resumes from its logs when ``record=true``.
"""

from __future__ import annotations

import time
from collections.abc import Sequence
from pathlib import Path

import pandas as pd
from omegaconf import OmegaConf

from graspexp.core.run_layout import results_csv
from graspexp.report.study import SweepStudy
from graspexp.report.tuning import ScoredSet
from graspexp.run.job_config import compose_job
from graspexp.run.runner import run_in_dir

REPLACED_KEYS = ("objects", "dataset.objects", "dataset.split", "trials", "progress")
"""Overrides of the study that the scoring jobs set themselves (which objects, how many trials)."""


def score_overrides(sweep: SweepStudy, split: str, trials: int, extra: Sequence[str]) -> list[str]:
    """The study's fixed overrides less :data:`REPLACED_KEYS`, then the split, the trials and ``extra``."""
    drop = {*sweep.searched, *REPLACED_KEYS}
    kept = [o for o in sweep.task_overrides if o.split("=", 1)[0].lstrip("+~") not in drop]
    return [*kept, f"dataset.split={split}", f"trials={trials}", "progress=false", *extra]


def score_study(
    sweep: SweepStudy,
    sweep_dir: Path,
    split: str,
    trials: int,
    extra: Sequence[str] = (),
    candidate: int | None = None,
) -> list[ScoredSet]:
    """Run the baseline and the study's trial ``candidate`` (None: its best trial) on ``split``
    (``trials`` per object); returns both, the baseline first. Raises
    :class:`graspexp.config.ConfigError` for a bad override."""
    base = score_overrides(sweep, split, trials, extra)
    cfg = compose_job(base)
    baseline = {k: OmegaConf.select(cfg, k) for k in sweep.searched}
    label = "paper" if not any(o.startswith("cost=") for o in base) else "baseline"
    out = []
    best = sweep.study.best_trial
    chosen = best if candidate is None else sweep.study.trials[candidate]
    tuned = "tuned" if chosen.number == best.number else f"trial {chosen.number}"
    for name, params, number in ((label, baseline, None), (tuned, dict(chosen.params), chosen.number)):
        job = compose_job([*base, *(f"{k}={v!r}" for k, v in params.items())])
        run_dir = sweep_dir / "score" / f"{split}_{name.replace(' ', '')}"
        t0 = time.perf_counter()
        run_in_dir(job, run_dir)
        results = pd.read_csv(results_csv(run_dir))
        out.append(ScoredSet(name, params, results, run_dir, time.perf_counter() - t0, number))
    return out
