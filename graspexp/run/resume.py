"""Resuming a job into a directory that already holds trials: the checks that refuse a directory of
another config or another mesh, the lock, the finished trials read back, and the files moved aside.

A re-run reuses the trials whose log is complete, provided every log's recorded config equals this run's
on every key that affects a result (:mod:`graspexp.config.differences`); trials that ended in ``error``,
damaged logs and files that are not graspexp trial logs are moved into ``trials/.quarantine/`` (never
deleted) and redone."""

import datetime
import logging
import os
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

from omegaconf import DictConfig

from graspexp.config.differences import config_differences
from graspexp.core.outcome import FailureReason, TrialResult, result_from_dict
from graspexp.core.run_layout import (
    HYDRA_FILES,
    LOCK_NAME,
    LinkedRunPathError,
    check_not_linked,
    hydra_dir,
    quarantine_path,
    real_folder,
    results_csv,
    summary_md,
    trials_dir,
)
from graspexp.record import CorruptLogError, iter_trial_logs, read_result
from graspexp.record.reader import read_metadata
from graspexp.run.locks import DirectoryLock, RunError
from graspexp.run.objects import LoadedObject

log = logging.getLogger(__name__)
T = TypeVar("T")


def job_lock(run_dir: Path) -> DirectoryLock:
    """The exclusive lock of job directory ``run_dir`` (a context manager); RunError naming the holder if
    another run has it."""
    return DirectoryLock(run_dir, LOCK_NAME, "run")


def check_resumable(cfg: DictConfig, run_dir: Path, move_foreign: bool = True) -> None:
    """Raise RunError if a graspexp log in ``run_dir`` was made with a different config (see
    :mod:`graspexp.config.differences`); then move aside (:func:`quarantine`) the files in ``trials/`` that
    are not graspexp trial logs (no graspexp metadata, unreadable metadata): nothing is moved when the run
    is refused, nor with ``move_foreign`` False (the check before the lock). Partial logs and damaged results
    are left to :func:`finished_result`."""
    foreign = []
    for path in iter_trial_logs(run_dir):
        try:
            meta = read_metadata(path)
        except CorruptLogError as exc:
            foreign.append((path, str(exc)))
            continue
        if not meta or "config_yaml" not in meta:
            foreign.append((path, f"{path}: not a graspexp trial log (no graspexp metadata)"))
            continue
        try:
            diff = config_differences(meta["config_yaml"], cfg)
        except Exception as exc:  # a recorded config that is not YAML of a job config
            foreign.append((path, f"{path}: unreadable recorded config ({type(exc).__name__})"))
            continue
        if diff:
            keys = sorted(diff, key=lambda k: ("." in k and not k.endswith(".name"), k))  # choices first
            shown = "; ".join(f"{k}: {diff[k][0]!r} in the log, {diff[k][1]!r} now" for k in keys[:4])
            raise RunError(
                f"{run_dir} holds trial logs made with a different config; differing keys: {', '.join(keys)} "
                f"({path.relative_to(run_dir)}: {shown}); resume only reuses logs of the same config: "
                f"choose another output directory (hydra.run.dir / hydra.sweep.dir) or delete {trials_dir(run_dir)}"
            )
    for path, why in foreign if move_foreign else ():
        quarantine(path, run_dir, why)


def check_same_meshes(run_dir: Path, objects: dict[str, LoadedObject]) -> None:
    """Raise RunError if a log in ``run_dir`` was made on another geometry of its object than this run
    loads (another data root, a re-download, a rescaled file), with another collision shape (a cache entry
    rewritten by someone else) or another grasping area (an edited area spec): resume never mixes trials of
    two. Values a log does not record (written before graspexp recorded them) and unreadable logs are not
    compared."""
    for path in iter_trial_logs(run_dir):
        try:
            meta = read_metadata(path) or {}
        except CorruptLogError:
            continue
        loaded = objects.get(meta.get("object", ""))
        if loaded is None:
            continue
        model = loaded.model
        logged = meta.get("mesh_sha256")
        if logged is not None and logged != model.mesh_sha256:
            raise RunError(
                f"{run_dir} holds trials of {model.name} made on another mesh ({path.relative_to(run_dir)}: "
                f"{meta.get('mesh_source') or 'procedural'}, sha256 {logged[:12]}{_facts(meta)}; now "
                f"{model.source or 'procedural'}, sha256 {model.mesh_sha256[:12]}{_facts(model.mesh_facts)}); "
                f"resume only reuses trials of the same mesh: choose another output directory or delete "
                f"{trials_dir(run_dir)}"
            )
        for key, now, what in (
            ("collision_sha256", loaded.hulls.sha256, "collision shape (a changed cache entry?)"),
            ("area_sha256", model.area_sha256, "grasping area (an edited area spec?)"),
        ):
            if meta.get(key) and now and meta[key] != now:
                raise RunError(
                    f"{run_dir} holds trials of {model.name} made with another {what} "
                    f"({path.relative_to(run_dir)}: {key} {meta[key][:12]}, now {now[:12]}); resume only "
                    f"reuses trials of the same one: choose another output directory or delete {trials_dir(run_dir)}"
                )


def check_run_files(run_dir: Path) -> None:
    """Raise RunError if a file or folder the job writes in ``run_dir`` is a symbolic link (checked before the
    first trial; every write checks again): nothing is written through a link planted in a shared
    directory."""
    try:
        for path in (trials_dir(run_dir), results_csv(run_dir), summary_md(run_dir), hydra_dir(run_dir)):
            check_not_linked(path)
        if hydra_dir(run_dir).is_dir():
            for name in HYDRA_FILES:
                check_not_linked(hydra_dir(run_dir) / name)
    except LinkedRunPathError as exc:
        raise RunError(str(exc)) from None


def _facts(meta: dict[str, str]) -> str:
    """ ", N faces, area A m^2, volume V m^3" from recorded mesh facts ("" for logs without them)."""
    if "mesh_faces" not in meta:
        return ""
    volume = f", volume {float(meta['mesh_volume_m3']):.4g} m^3" if meta.get("mesh_volume_m3") else ""
    return f", {meta['mesh_faces']} faces, area {float(meta['mesh_area_m2']):.4g} m^2{volume}"


def finished_log(
    path: Path, run_dir: Path, what: str, read: Callable[[Path], T], redo: Callable[[T], str]
) -> T | None:
    """The result ``read(path)`` of a complete log at ``path``; None if absent. A log that cannot be read
    (:class:`CorruptLogError`, ``ValueError``), or whose result ``redo`` gives a reason to run again (a
    non-empty string), is moved aside (:func:`quarantine`) and its ``what`` ("trial", "round") is redone."""
    if not path.exists():
        return None
    try:
        result = read(path)
        why = redo(result)
    except (CorruptLogError, ValueError) as exc:
        why = str(exc)
    if why:
        quarantine(path, run_dir, f"re-running {what}: {why}")
        return None
    return result


def finished_result(path: Path, run_dir: Path, object_name: str, trial: int) -> TrialResult | None:
    """The result of a complete log at ``path``; None if absent. A log whose /result is unreadable or not
    a valid result of this trial, and a trial that ended in ``error``, are moved aside
    (:func:`quarantine`) and redone."""

    def redo(result: TrialResult) -> str:
        if (result.object, result.trial) != (object_name, trial):
            return f"its result is of {result.object} trial {result.trial}"
        if result.reason == FailureReason.ERROR.value:
            return f"it ended in an error ({result.error})"
        if not result.at_rest and result.reason != FailureReason.NOT_AT_REST.value:
            return "it planned on a moving object (before not_at_rest)"
        return ""

    return finished_log(path, run_dir, "trial", lambda p: result_from_dict(read_result(p)), redo)


def quarantine(path: Path, run_dir: Path, why: str) -> Path:
    """Move ``path`` out of ``trials/`` into ``trials/.quarantine/<object>/<name>.<UTC time>`` (never
    deleted: a foreign or damaged file may be someone's data) and log ``why`` with where it went."""
    stamp = datetime.datetime.now(datetime.timezone.utc).strftime("%Y%m%dT%H%M%S%fZ")
    target = quarantine_path(run_dir, path, stamp)
    try:
        real_folder(run_dir, target.parent)
    except LinkedRunPathError as exc:
        raise RunError(str(exc)) from None
    os.replace(path, target)
    log.warning("%s; %s moved to %s", why, path, target)
    return target


def kept_results(run_dir: Path, done: set[tuple[str, int]]) -> list[TrialResult]:
    """The results of the directory's other complete logs (same config: :func:`check_resumable`), e.g. the
    trials 3-9 a run with ``trials=3`` keeps from an earlier ``trials=10``: results.csv and summary.md
    describe every trial the directory holds, never fewer."""
    out = []
    for path in iter_trial_logs(run_dir):
        key = (path.parent.name, int(path.stem)) if path.stem.isdigit() else None
        if key is None or key in done:
            continue
        try:
            out.append(result_from_dict(read_result(path)))
        except (CorruptLogError, ValueError):
            continue  # a damaged log is moved aside when its trial is run again
    return out
