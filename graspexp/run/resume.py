"""Resuming a job into a directory that already holds trials: the checks that refuse a directory of
another config, another mesh or another clutter pool, the lock, the finished trials read back, and the files
moved aside.

A re-run reuses the trials whose log is complete, provided every log's recorded config equals this run's
on every key that affects a result (:mod:`graspexp.config.differences`); trials that ended in ``error``,
damaged logs and files that are not graspexp trial logs are moved into ``trials/.quarantine/`` (never
deleted) and redone. The rows of the tables that no log backs (``record=false`` runs) are checked the same
way against the run record (:mod:`graspexp.run.run_record`), and kept: one rule, logged or not."""

import datetime
import json
import logging
import os
from collections.abc import Callable
from pathlib import Path
from typing import TypeVar

from omegaconf import DictConfig

from graspexp.config.differences import config_differences
from graspexp.core.outcome import FailureReason, TrialResult, result_from_dict
from graspexp.core.run_layout import (
    ATTEMPTS_CSV,
    HYDRA_FILES,
    LOCK_NAME,
    ROUNDS_CSV,
    LinkedRunPathError,
    check_not_linked,
    hydra_dir,
    quarantine_path,
    real_folder,
    results_csv,
    run_record_path,
    summary_md,
    trials_dir,
)
from graspexp.record import CorruptLogError, iter_trial_logs, read_result
from graspexp.record.reader import read_metadata
from graspexp.run.locks import DirectoryLock, RunError
from graspexp.run.objects import LoadedObject
from graspexp.run.provenance import pool_metadata, recorded_pool
from graspexp.run.run_record import read_run_record, table_results, table_rounds

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
            raise RunError(_config_refusal(run_dir, path, diff, "trial logs", "the log"))
    _check_tables_record(cfg, run_dir)
    for path, why in foreign if move_foreign else ():
        quarantine(path, run_dir, why)


def _config_refusal(
    run_dir: Path, path: Path, diff: dict[str, tuple[object, object]], what: str, where: str
) -> str:
    keys = sorted(diff, key=lambda k: ("." in k and not k.endswith(".name"), k))  # choices first
    shown = "; ".join(f"{k}: {diff[k][0]!r} in {where}, {diff[k][1]!r} now" for k in keys[:4])
    return (
        f"{run_dir} holds {what} made with a different config; differing keys: {', '.join(keys)} "
        f"({path.relative_to(run_dir)}: {shown}); resume only reuses {what} of the same config: {afresh(run_dir)}"
    )


def afresh(run_dir: Path) -> str:
    """What a refused run can do: another output directory, or delete what ``run_dir`` holds of earlier runs
    (its logs, tables and their record: :mod:`graspexp.run.run_record`)."""
    held = [
        trials_dir(run_dir),
        results_csv(run_dir),
        *(Path(run_dir) / n for n in (ROUNDS_CSV, ATTEMPTS_CSV)),
    ]
    held = [p for p in (*held, run_record_path(run_dir)) if p.exists()] or [trials_dir(run_dir)]
    return "choose another output directory (hydra.run.dir / hydra.sweep.dir) or delete " + ", ".join(
        map(str, held)
    )


def _check_tables_record(cfg: DictConfig, run_dir: Path) -> None:
    """Raise RunError if the tables hold rows that no log backs (those of ``record=false`` runs) and the run
    record (:mod:`graspexp.run.run_record`) that says what made them has a different config, or there is no
    record (tables written before graspexp kept it: rows of an unknown config, neither kept nor
    overwritten). Such rows are kept, so they are checked readable here. A record with no such row to
    speak for is not compared (a run killed before its tables were written)."""
    record = read_run_record(run_dir)
    path = run_record_path(run_dir)
    for table, rows in ((results_csv(run_dir), table_results), (Path(run_dir) / ROUNDS_CSV, table_rounds)):
        try:
            check_not_linked(table)
        except LinkedRunPathError as exc:
            raise RunError(str(exc)) from None
        unbacked = rows(run_dir)
        if not unbacked:
            continue
        if record is None:
            shown = ", ".join(_row_name(k) for k in list(unbacked)[:4])
            raise RunError(
                f"{table} holds {len(unbacked)} rows that no log backs ({shown}{', ...' if len(unbacked) > 4 else ''}) "
                f"and no {path.name} says what config made them (written before graspexp kept it); resume "
                f"never overwrites nor mixes rows of an unknown config: {afresh(run_dir)}"
            )
        try:
            diff = config_differences(record["config_yaml"], cfg)
        except Exception as exc:  # a recorded config that is not YAML of a job config
            raise RunError(
                f"{path} is not a graspexp run record (its config: {type(exc).__name__}); {afresh(run_dir)}"
            ) from None
        if diff:
            raise RunError(_config_refusal(run_dir, path, diff, "results", "its record"))


def _row_name(key: tuple[str, int] | int) -> str:
    return f"round {key}" if isinstance(key, int) else f"{key[0]} trial {key[1]}"


def check_same_meshes(run_dir: Path, objects: dict[str, LoadedObject]) -> None:
    """Raise RunError if a log in ``run_dir`` was made on another geometry of its object than this run
    loads (another data root, a re-download, a rescaled file), with another collision shape (a cache entry
    rewritten by someone else) or another grasping area (an edited area spec): resume never mixes trials of
    two. Values a log does not record (written before graspexp recorded them) and unreadable logs are not
    compared. The run record's objects (:mod:`graspexp.run.run_record`) that have rows no log backs are
    compared as logs are."""
    record = read_run_record(run_dir) or {}
    rows = {name for name, _ in table_results(run_dir)}  # objects with rows the record speaks for
    recorded = [
        (run_record_path(run_dir), {**m, "object": n})
        for n, m in record.get("objects", {}).items()
        if n in rows
    ]
    for path, meta in (*_log_metadata(run_dir), *recorded):
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
                f"resume only reuses trials of the same mesh: {afresh(run_dir)}"
            )
        for key, now, what in (
            ("collision_sha256", loaded.hulls.sha256, "collision shape (a changed cache entry?)"),
            ("area_sha256", model.area_sha256, "grasping area (an edited area spec?)"),
        ):
            if meta.get(key) and now and meta[key] != now:
                raise RunError(
                    f"{run_dir} holds trials of {model.name} made with another {what} "
                    f"({path.relative_to(run_dir)}: {key} {meta[key][:12]}, now {now[:12]}); resume only "
                    f"reuses trials of the same one: {afresh(run_dir)}"
                )


def _log_metadata(run_dir: Path) -> list[tuple[Path, dict[str, str]]]:
    """(path, metadata) of every readable trial or round log of ``run_dir``."""
    out = []
    for path in iter_trial_logs(run_dir):
        try:
            out.append((path, read_metadata(path) or {}))
        except CorruptLogError:
            continue
    return out


def check_same_pool(
    run_dir: Path, mode_name: str, pool: list[LoadedObject], unusable: dict[str, str]
) -> None:
    """Raise RunError if a round log of ``run_dir`` (or its run record) was drawn from another pool than
    ``pool`` (other objects, or the same in another order: a round draws by position) or made on another
    mesh, collision shape or grasping area of one of its objects; ``unusable``: {name: why} of the objects
    left out of the pool, named when the pool lost one. A round logged before graspexp recorded pools is
    compared by the objects it drew."""
    now = json.loads(pool_metadata(pool))
    record = read_run_record(run_dir) or {}
    sources = [(p, m) for p, m in _log_metadata(run_dir) if "round_pool" in m or "round_objects" in m]
    if "round_pool" in record and table_rounds(run_dir):  # rounds without a log: the record speaks for them
        sources.append((run_record_path(run_dir), record))
    for path, meta in sources:
        try:
            logged = recorded_pool(meta)
        except (ValueError, RecursionError) as exc:
            raise RunError(f"{path}: {exc}; {afresh(run_dir)}") from None
        why = _pool_difference(str(path.relative_to(run_dir)), logged, meta, now, unusable)
        if why:
            raise RunError(
                f"{run_dir} holds rounds of {mode_name} {why}; resume only "
                f"reuses rounds of the same pool and meshes: {afresh(run_dir)}"
            )


def _pool_difference(
    where: str,
    logged: list[dict[str, str]] | None,
    meta: dict,
    now: list[dict[str, str]],
    unusable: dict[str, str],
) -> str:
    """How the pool of the round log at ``where`` (``logged``; None: the objects it drew,
    ``meta['round_objects']``) differs from ``now`` ("" when it does not)."""
    names = [e["name"] for e in now]
    lost = "".join(
        f"; {n} cannot be used now: {unusable[n]}" for n in (e["name"] for e in logged or []) if n in unusable
    )
    if logged is None:
        drawn = str(meta.get("round_objects", "")).split()
        strangers = [n for n in dict.fromkeys(drawn) if n not in names]
        if not strangers:
            return ""
        lost = "".join(f"; {n} cannot be used now: {unusable[n]}" for n in strangers if n in unusable)
        return f"drawn from another pool ({where} drew {', '.join(strangers)}; the pool now: {', '.join(names)}{lost})"
    old = [e["name"] for e in logged]
    if old != names:
        only_log = [n for n in old if n not in names]
        only_now = [n for n in names if n not in old]
        parts = [f"only earlier: {', '.join(only_log)}"] * bool(only_log) + [
            f"only now: {', '.join(only_now)}"
        ] * bool(only_now) or ["the same objects in another order: a round draws them by position"]
        return f"drawn from another pool ({where}: {', '.join(old)}; now {', '.join(names)}: {'; '.join(parts)}{lost})"
    for was, is_ in zip(logged, now, strict=True):
        if was.get("mesh_sha256") and was["mesh_sha256"] != is_["mesh_sha256"]:
            return (
                f"made on another mesh of {is_['name']} ({where}: {was.get('mesh_source') or 'procedural'}, sha256 "
                f"{was['mesh_sha256'][:12]}; now {is_['mesh_source'] or 'procedural'}, sha256 {is_['mesh_sha256'][:12]})"
            )
        for key, what in (("collision_sha256", "collision shape"), ("area_sha256", "grasping area")):
            if was.get(key) and is_[key] and was[key] != is_[key]:
                return f"made with another {what} of {is_['name']} ({where}: {key} {was[key][:12]}, now {is_[key][:12]})"
    return ""


def check_run_files(run_dir: Path) -> None:
    """Raise RunError if a file or folder the job writes in ``run_dir`` is a symbolic link (checked before the
    first trial; every write checks again): nothing is written through a link planted in a shared
    directory."""
    try:
        tables = (
            results_csv(run_dir),
            Path(run_dir) / ROUNDS_CSV,
            Path(run_dir) / ATTEMPTS_CSV,
            run_record_path(run_dir),
        )
        for path in (trials_dir(run_dir), *tables, summary_md(run_dir), hydra_dir(run_dir)):
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
        if result.registration_fitness == 0.0 and result.reason != FailureReason.REGISTRATION_FAILED.value:
            return "it planned on a pose registered from nothing (fitness 0, before registration_failed)"
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
