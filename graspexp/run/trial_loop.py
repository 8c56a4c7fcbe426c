"""The trials of one object: each run (or read back when finished) and logged into its MCAP file; an
exception inside a trial becomes that trial's ``error`` result, an unwritable log stops the job."""

import errno
import logging
import traceback
from collections.abc import Mapping
from pathlib import Path

from omegaconf import DictConfig
from tqdm import tqdm

from graspexp.core.outcome import FailureReason, TrialResult
from graspexp.core.run_layout import LinkedRunPathError, real_folder, trial_log_path
from graspexp.core.seeding import trial_seed
from graspexp.datasets import ObjectError
from graspexp.record import trial_recorder
from graspexp.record.writer import is_write_error
from graspexp.run.locks import RunError
from graspexp.run.objects import LoadedObject, load_models, trial_context
from graspexp.run.provenance import job_metadata, trial_metadata, unusable_trial_metadata
from graspexp.run.resume import finished_result
from graspexp.sim.trial import plain_config, run_trial

log = logging.getLogger(__name__)

NO_SPACE_ERRNOS = (errno.ENOSPC, errno.EFBIG, errno.EDQUOT)
"""Write errors that mean no room is left (a full disk or quota, a file-size limit)."""


def run_object_trials(
    cfg: DictConfig,
    object_name: str,
    run_dir: Path,
    bar: tqdm | None = None,
    loaded: LoadedObject | str | None = None,
    *,
    finished_rows: Mapping[tuple[str, int], TrialResult] | None = None,
) -> list[TrialResult]:
    """Every trial of one object; finished trials found in ``run_dir`` are read back instead of re-run.

    ``loaded``: the object from :func:`graspexp.run.objects.load_models`, or the reason it cannot be used
    (then every trial without a finished result, a log or one of ``finished_rows``, is an ``error`` result
    with that reason: :func:`_unusable_object_trials`); loaded here if None. An exception inside a trial is
    that trial's ``error`` result; an unwritable log stops the job (RunError).
    """
    plain = plain_config(cfg)
    job_meta = job_metadata(cfg)
    if loaded is None:
        ready, failed = load_models(cfg, [object_name])
        loaded = ready.get(object_name) or failed[object_name]
    first = trial_log_path(run_dir, object_name, 0)
    try:  # the object's folder of logs: never a link to somewhere else (a shared sweep directory)
        real_folder(run_dir, first.parent)
    except LinkedRunPathError as exc:
        raise RunError(str(exc)) from None
    except OSError as exc:
        raise RunError(write_failure(first, exc)) from None
    if isinstance(loaded, str):
        return _unusable_object_trials(cfg, object_name, run_dir, loaded, bar, finished_rows or {})
    results = []
    for i in range(cfg.trials):
        path = trial_log_path(run_dir, object_name, i)
        seed = trial_seed(plain, object_name, i)
        result = finished_result(path, run_dir, object_name, i)
        if result is None:
            try:
                meta = trial_metadata(job_meta, loaded, i, seed)
                with trial_recorder(path if cfg.record else None, meta, plain) as rec:
                    try:
                        result = run_trial(trial_context(plain, loaded, i, rec))
                    except Exception as exc:  # one trial's error is recorded; the sweep goes on
                        if is_write_error(exc):
                            raise
                        log.error("%s trial %d failed with an error: %s", object_name, i, exc)
                        result = error_result(cfg, object_name, i, seed, exc)
                        rec.result(0.0, result.to_dict())
            except Exception as exc:
                if not is_write_error(exc):
                    raise
                raise RunError(write_failure(path, exc)) from None
        results.append(result)
        if bar is not None:
            bar.set_postfix_str(f"{object_name} #{i}: {'ok' if result.success else result.reason}")
            bar.update()
    return results


def write_failure(path: Path, exc: BaseException, kind: str = "trial") -> str:
    """The message of a ``kind`` (trial, round) log that cannot be written (with what to do when the disk is
    full)."""
    why = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
    full = not isinstance(exc, OSError) or exc.errno in NO_SPACE_ERRNOS
    hint = (
        "; the disk may be full: free space, then run the same command again (finished "
        f"{kind}s are kept and reused)"
        if full
        else ""
    )
    return f"cannot write the {kind} log {path}: {why}{hint}"


def _unusable_object_trials(
    cfg: DictConfig,
    object_name: str,
    run_dir: Path,
    reason: str,
    bar: tqdm | None,
    finished_rows: Mapping[tuple[str, int], TrialResult],
) -> list[TrialResult]:
    """Every trial of an object that cannot be used now. A trial that has a finished result, its complete log
    or a row of ``finished_rows`` (a ``record=false`` run's), keeps it: nothing finished is overwritten by an
    error (a damaged or ``error`` log is moved aside as on any resume). Each other trial is an ``error``
    result with ``reason``, logged (when ``record``) so that the report counts it; resume tries the object
    again."""
    plain, job_meta = plain_config(cfg), job_metadata(cfg)
    results, kept = [], []
    for i in range(cfg.trials):
        path = trial_log_path(run_dir, object_name, i)
        result = finished_result(path, run_dir, object_name, i) or finished_rows.get((object_name, i))
        if result is not None and result.reason != FailureReason.ERROR.value:
            kept.append(f"{i} ({path if path.exists() else 'its row of results.csv'})")
        else:
            seed = trial_seed(plain, object_name, i)
            result = error_result(cfg, object_name, i, seed, ObjectError(reason))
            meta = unusable_trial_metadata(job_meta, object_name, i, seed)
            with trial_recorder(path if cfg.record else None, meta, plain) as rec:
                rec.result(0.0, result.to_dict())
        results.append(result)
        if bar is not None:
            bar.update()
    if kept:
        log.warning(
            "%s cannot be used now; its finished trials are kept, not overwritten: %s; the other %d are not run",
            object_name, ", ".join(kept), cfg.trials - len(kept),
        )  # fmt: skip
    return results


def error_result(cfg: DictConfig, object_name: str, trial: int, seed: int, exc: BaseException) -> TrialResult:
    """The ``error`` result of a trial that raised ``exc`` (its one-line description recorded)."""
    return TrialResult(
        dataset=cfg.dataset.name,
        object=object_name,
        mode=cfg.mode.name,
        rot=cfg.rot.name,
        planner=cfg.planner.name,
        trial=trial,
        seed=seed,
        success=False,
        reason=FailureReason.ERROR.value,
        error="".join(traceback.format_exception_only(type(exc), exc)).strip(),
    )
