"""The main job: every trial of every object of the dataset, one MCAP log per trial, a results table.

Run directory layout (Hydra's output dir)::

    trials/<object>/<trial>.mcap   one log per trial (the source of truth)
    results.csv                    one row per trial (a cache rebuilt from the logs at the end)
    summary.md                     the per-object success table printed at the end

Re-running into the same directory resumes: trials whose log is complete are read back, not re-run,
provided every log's recorded config equals this run's on every key that affects a result
(:data:`RESULT_NEUTRAL_KEYS` are ignored); otherwise the job stops with :class:`RunError`. Trials that
ended in ``error`` and partial logs are redone. One job at a time writes into a directory (a file lock).
With ``record=false`` no log is written (faster, but nothing to replay and nothing to resume from).
"""

import dataclasses
import datetime
import errno
import functools
import hashlib
import logging
import os
import platform
import time
import traceback
from collections.abc import Callable
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

import pandas as pd
from omegaconf import DictConfig, OmegaConf
from threadpoolctl import threadpool_limits
from tqdm import tqdm

from graspexp.config.differences import config_differences
from graspexp.core.outcome import FailureReason, TrialResult, result_from_dict
from graspexp.core.seeding import trial_seed
from graspexp.datasets import ObjectError, job_object, resolve_root, select_objects
from graspexp.datasets.model import ObjectModel
from graspexp.planning import plan
from graspexp.quality import fc_min_mu
from graspexp.record import (
    TRIALS_DIR,
    CorruptLogError,
    iter_trial_logs,
    read_result,
    trial_log_path,
    trial_recorder,
)
from graspexp.record.reader import read_metadata
from graspexp.record.scene import ObjectScene, object_scene
from graspexp.record.writer import is_write_error
from graspexp.run.job_config import make_ready
from graspexp.run.locks import DirectoryLock, RunError
from graspexp.run.prepare import prepare_shapes
from graspexp.sim.collision_shapes import ShapeError, shape_with_fallback
from graspexp.sim.shape import CollisionShape
from graspexp.sim.trial import TrialContext, plain_config, run_trial

log = logging.getLogger(__name__)
LOCK_NAME = ".graspexp.lock"
"""Lock file in the job directory (``filelock``: flock(2), which Linux maps to POSIX locks on NFS, so it
holds across the nodes of a cluster; the kernel or the NFS server drops it when the holder dies)."""
HOLDER_NAME = ".graspexp.lock.holder"
QUARANTINE_DIR = ".quarantine"
"""Folder of ``trials/`` where resume moves files that are not usable trial logs (never deleted)."""
"""Who holds the lock (host, pid, start time, command), for the message of a second run."""
PACKAGES = ("graspexp", "sapien", "numpy", "scikit-learn", "trimesh", "coacd", "mcap", "hydra-core")


def package_versions() -> dict[str, str]:
    out = {"python": platform.python_version()}
    for name in PACKAGES:
        try:
            out[name] = version(name)
        except PackageNotFoundError:
            out[name] = "unknown"
    return out


NO_SPACE_ERRNOS = (errno.ENOSPC, errno.EFBIG, errno.EDQUOT)
"""Write errors that mean no room is left (a full disk or quota, a file-size limit)."""


@dataclasses.dataclass(frozen=True)
class LoadedObject:
    """An object ready for its trials: model, collision shape, Foxglove scene, and what was assumed."""

    model: ObjectModel
    hulls: CollisionShape
    scene: ObjectScene
    notes: tuple[str, ...]
    """The model's notes (units, mass, area) and the collision shape's (a fallback method)."""


def job_metadata(cfg: DictConfig) -> dict[str, str]:
    """The part of every trial's MCAP metadata that is the same for the whole job: the config, the seed,
    the data root it read, the package versions and the machine (:func:`machine_fingerprint`)."""
    meta = {"config_yaml": OmegaConf.to_yaml(cfg, resolve=True), "global_seed": str(cfg.seed)}
    meta["data_root"] = str(resolve_root(cfg.dataset).resolve())
    meta.update({f"version.{k}": v for k, v in package_versions().items()})
    meta.update({f"machine.{k}": v for k, v in machine_fingerprint().items()})
    return meta


@functools.cache
def machine_fingerprint() -> dict[str, str]:
    """What a trial's floating point may depend on besides the code: CPU model, its instruction-set flags
    (a hash: PhysX and numba pick vector paths by them), OS and architecture."""
    cpu, flags = platform.processor() or "unknown", ""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            key, _, value = line.partition(":")
            if key.strip() == "model name" and cpu in ("unknown", "", platform.machine()):
                cpu = value.strip()
            elif key.strip() in ("flags", "Features") and not flags:
                flags = " ".join(sorted(value.split()))
    except OSError:
        pass
    return {
        "cpu": cpu,
        "cpu_flags_sha256": hashlib.sha256(flags.encode()).hexdigest()[:16],
        "platform": platform.platform(),
        "arch": platform.machine(),
    }


def _metadata(job_meta: dict[str, str], loaded: LoadedObject, trial: int, seed: int) -> dict[str, str]:
    """One trial's log metadata: the job's, the trial's seeds and what its object was made of (the mesh
    file, "" for a procedural one, the SHA-256 of the geometry used with its face count, surface area and
    volume, the collision method it got, and what was assumed for it: units, mass, area)."""
    return {
        **job_meta,
        "object": loaded.model.name,
        "trial": str(trial),
        "trial_seed": str(seed),
        "mesh_source": loaded.model.source,
        "mesh_sha256": loaded.model.mesh_sha256,
        **loaded.model.mesh_facts,
        "collision_method": loaded.hulls.method,
        "collision_key": loaded.hulls.key,
        "object_notes": "\n".join(loaded.notes),
    }


def _unusable_object_trials(
    cfg: DictConfig, object_name: str, run_dir: Path, reason: str, bar: tqdm | None
) -> list[TrialResult]:
    """Every trial of an object that cannot be used: an ``error`` result with ``reason``, logged (when
    ``record``) so that the report counts it; resume tries the object again."""
    plain, job_meta = plain_config(cfg), job_metadata(cfg)
    results = []
    for i in range(cfg.trials):
        seed = trial_seed(plain, object_name, i)
        result = _error_result(cfg, object_name, i, seed, ObjectError(reason))
        path = trial_log_path(run_dir, object_name, i)
        path.parent.mkdir(parents=True, exist_ok=True)
        meta = {**job_meta, "object": object_name, "trial": str(i), "trial_seed": str(seed)}
        with trial_recorder(path if cfg.record else None, meta, plain) as rec:
            rec.result(0.0, result.to_dict())
        results.append(result)
        if bar is not None:
            bar.update()
    return results


def check_same_meshes(run_dir: Path, models: dict[str, ObjectModel]) -> None:
    """Raise RunError if a log in ``run_dir`` was made on another geometry of its object than this run
    loads (another data root, a re-download, a rescaled file): resume never mixes trials of two meshes.
    Logs that record no mesh (written before graspexp recorded it) and unreadable ones are not compared."""
    for path in iter_trial_logs(run_dir):
        try:
            meta = read_metadata(path) or {}
        except CorruptLogError:
            continue
        model = models.get(meta.get("object", ""))
        logged = meta.get("mesh_sha256")
        if model is None or logged is None or logged == model.mesh_sha256:
            continue
        raise RunError(
            f"{run_dir} holds trials of {model.name} made on another mesh ({path.relative_to(run_dir)}: "
            f"{meta.get('mesh_source') or 'procedural'}, sha256 {logged[:12]}{_facts(meta)}; now "
            f"{model.source or 'procedural'}, sha256 {model.mesh_sha256[:12]}{_facts(model.mesh_facts)}); "
            f"resume only reuses trials of the same mesh: choose another output directory or delete "
            f"{run_dir / 'trials'}"
        )


def _facts(meta: dict[str, str]) -> str:
    """ ", N faces, area A m^2, volume V m^3" from recorded mesh facts ("" for logs without them)."""
    if "mesh_faces" not in meta:
        return ""
    volume = f", volume {float(meta['mesh_volume_m3']):.4g} m^3" if meta.get("mesh_volume_m3") else ""
    return f", {meta['mesh_faces']} faces, area {float(meta['mesh_area_m2']):.4g} m^2{volume}"


def _error_result(
    cfg: DictConfig, object_name: str, trial: int, seed: int, exc: BaseException
) -> TrialResult:
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


def load_models(cfg: DictConfig, objects: list[str]) -> tuple[dict[str, LoadedObject], dict[str, str]]:
    """({name: loaded object}, {name: why it cannot be used}), before any trial runs. An object whose mesh,
    sidecar or area is unusable (:class:`ObjectError`) or for which no collision shape can be built
    (:class:`ShapeError`) fails alone; a missing data folder or file, or a broken region spec file, stops
    the job here (DatasetError) instead of filling a table."""
    plain = plain_config(cfg)
    out, failed = {}, {}
    for name in objects:
        try:
            model = job_object(cfg, name)
            hulls, shape_note = shape_with_fallback(model.mesh, plain.sim)
        except (ObjectError, ShapeError) as exc:
            log.error("object %s cannot be used: %s", name, exc)
            failed[name] = str(exc)
            continue
        notes = (*model.notes, shape_note) if shape_note else model.notes
        out[name] = LoadedObject(model, hulls, object_scene(plain, hulls), notes)
    return out, failed


def run_object_trials(
    cfg: DictConfig,
    object_name: str,
    run_dir: Path,
    bar: tqdm | None = None,
    loaded: LoadedObject | str | None = None,
) -> list[TrialResult]:
    """Every trial of one object; finished trials found in ``run_dir`` are read back instead of re-run.

    ``loaded``: the object from :func:`load_models`, or the reason it cannot be used (then every trial is
    an ``error`` result with that reason); loaded here if None. An exception inside a trial is that trial's
    ``error`` result; an unwritable log stops the job (RunError).
    """
    plain = plain_config(cfg)
    job_meta = job_metadata(cfg)
    if loaded is None:
        ready, failed = load_models(cfg, [object_name])
        loaded = ready.get(object_name) or failed[object_name]
    if isinstance(loaded, str):
        return _unusable_object_trials(cfg, object_name, run_dir, loaded, bar)
    model, hulls, scene = loaded.model, loaded.hulls, loaded.scene
    results = []
    for i in range(cfg.trials):
        path = trial_log_path(run_dir, object_name, i)
        seed = trial_seed(plain, object_name, i)
        result = _finished(path, run_dir, object_name, i)
        if result is None:
            try:
                path.parent.mkdir(parents=True, exist_ok=True)
                meta = _metadata(job_meta, loaded, i, seed)
                recorder = trial_recorder(path if cfg.record else None, meta, plain)
                with recorder as rec:
                    try:
                        result = run_trial(
                            TrialContext(
                                plain, model, hulls, i, seed, rec, scene, plan=plan, quality=fc_min_mu
                            )
                        )
                    except Exception as exc:  # one trial's error is recorded; the sweep goes on
                        if is_write_error(exc):
                            raise
                        log.error("%s trial %d failed with an error: %s", object_name, i, exc)
                        result = _error_result(cfg, object_name, i, seed, exc)
                        rec.result(0.0, result.to_dict())
            except Exception as exc:
                if not is_write_error(exc):
                    raise
                why = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
                full = not isinstance(exc, OSError) or exc.errno in NO_SPACE_ERRNOS
                hint = (
                    "; the disk may be full: free space, then run the same command again (finished "
                    "trials are kept and reused)"
                    if full
                    else ""
                )
                raise RunError(f"cannot write the trial log {path}: {why}{hint}") from None
        results.append(result)
        if bar is not None:
            bar.set_postfix_str(f"{object_name} #{i}: {'ok' if result.success else result.reason}")
            bar.update()
    return results


def _finished(path: Path, run_dir: Path, object_name: str, trial: int) -> TrialResult | None:
    """The result of a complete log at ``path``; None if absent. A log whose /result is unreadable or not
    a valid result of this trial, and a trial that ended in ``error``, are moved aside
    (:func:`quarantine`) and redone."""
    if not path.exists():
        return None
    try:
        result = result_from_dict(read_result(path))
        if (result.object, result.trial) != (object_name, trial):
            raise ValueError(f"its result is of {result.object} trial {result.trial}")
    except (CorruptLogError, ValueError) as exc:
        quarantine(path, run_dir, f"re-running trial: {exc}")
        return None
    if result.reason == FailureReason.ERROR.value:
        quarantine(path, run_dir, f"re-running trial: it ended in an error ({result.error})")
        return None
    return result


def quarantine(path: Path, run_dir: Path, why: str) -> Path:
    """Move ``path`` out of ``trials/`` into ``trials/.quarantine/<object>/<name>.<UTC time>`` (never
    deleted: a foreign or damaged file may be someone's data) and log ``why`` with where it went."""
    stamp = datetime.datetime.now(datetime.timezone.utc).strftime("%Y%m%dT%H%M%S%fZ")
    target = run_dir / TRIALS_DIR / QUARANTINE_DIR / path.parent.name / f"{path.name}.{stamp}"
    target.parent.mkdir(parents=True, exist_ok=True)
    os.replace(path, target)
    log.warning("%s; %s moved to %s", why, path, target)
    return target


def check_resumable(cfg: DictConfig, run_dir: Path, move_foreign: bool = True) -> None:
    """Raise RunError if a graspexp log in ``run_dir`` was made with a different config (see
    :mod:`graspexp.config.differences`); then move aside (:func:`quarantine`) the files in ``trials/`` that
    are not graspexp trial logs (no graspexp metadata, unreadable metadata): nothing is moved when the run
    is refused, nor with ``move_foreign`` False (the check before the lock). Partial logs and damaged results
    are left to :func:`_finished`."""
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
                f"choose another output directory (hydra.run.dir / hydra.sweep.dir) or delete {run_dir / 'trials'}"
            )
    for path, why in foreign if move_foreign else ():
        quarantine(path, run_dir, why)


def job_lock(run_dir: Path) -> DirectoryLock:
    """The exclusive lock of job directory ``run_dir`` (a context manager); RunError naming the holder if
    another run has it."""
    return DirectoryLock(run_dir, LOCK_NAME, "run")


def summarize(df: pd.DataFrame) -> pd.DataFrame:
    """Per-object success rate (%) and failure counts, plus an Average row."""
    g = df.groupby("object", sort=False)
    table = pd.DataFrame({"trials": g.size(), "success_%": 100.0 * g["success"].mean()})
    reasons = df[~df["success"]].pivot_table(
        index="object", columns="reason", values="trial", aggfunc="count"
    )
    if not reasons.empty:  # objects without any failure count 0 of each reason, also in the Average row
        table = table.join(reasons).fillna(0)
        table[list(reasons.columns)] = table[list(reasons.columns)].astype(int)
    table.loc["Average"] = table.mean(numeric_only=True)
    return table


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


def object_notes(models: dict[str, LoadedObject], unusable: dict[str, str]) -> str:
    """The summary's lines on what was assumed for each object and why an object could not be used
    ("" when there is nothing to say)."""
    lines = [f"- {name}: {'; '.join(o.notes)}" for name, o in models.items() if o.notes]
    lines += [f"- {name}: NOT RUN, {why}" for name, why in unusable.items()]
    return "\n\nObjects:\n" + "\n".join(lines) if lines else ""


OBJECTIVES = {"success": pd.Series.mean, "worst_object": pd.Series.min}
"""How each ``objective`` (:data:`graspexp.config.job.OBJECTIVES`) reduces the per-object success rates."""


def objective_value(df: pd.DataFrame, objective: str) -> float:
    """The job's ``objective`` (see :class:`graspexp.config.JobConfig`) from its results table (one row per
    trial, columns ``object`` and ``success``): a fraction in [0, 1]."""
    return float(OBJECTIVES[objective](df.groupby("object", sort=False)["success"].mean()))


def run_job(cfg: DictConfig) -> float:
    """Run every trial for every selected object; returns ``cfg.objective`` (:func:`objective_value`)."""
    from hydra.core.hydra_config import HydraConfig

    return run_in_dir(cfg, Path(HydraConfig.get().runtime.output_dir), write_hydra_record)


def write_hydra_record(cfg: DictConfig, run_dir: Path) -> None:
    """Hydra's record of an accepted run, ``.hydra/{config,hydra,overrides}.yaml`` (written here, after the
    checks, rather than by Hydra before them: ``hydra.output_subdir`` is null in ``conf/config.yaml``)."""
    from hydra.core.hydra_config import HydraConfig

    hc = HydraConfig.get()
    folder = run_dir / ".hydra"
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "config.yaml").write_text(OmegaConf.to_yaml(cfg))
    (folder / "hydra.yaml").write_text(OmegaConf.to_yaml({"hydra": hc}))
    (folder / "overrides.yaml").write_text(OmegaConf.to_yaml(list(hc.overrides.task)))


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
    objects = select_objects(cfg.dataset, cfg.objects)
    check_resumable(cfg, run_dir, move_foreign=False)
    prepare_shapes(cfg.dataset, cfg.sim, objects, cfg.progress)
    models, unusable = load_models(cfg, objects)
    with job_lock(run_dir):
        check_resumable(cfg, run_dir)
        check_same_meshes(run_dir, {name: loaded.model for name, loaded in models.items()})
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
    results: list[TrialResult] = []
    with tqdm(
        total=len(objects) * cfg.trials,
        desc=f"{cfg.mode.name}/{cfg.rot.name}/{cfg.dataset.name}",
        disable=not cfg.progress,
    ) as bar:
        for name in objects:
            results.extend(run_object_trials(cfg, name, run_dir, bar, models.get(name) or unusable[name]))
    results += kept_results(run_dir, {(r.object, r.trial) for r in results})
    df = pd.DataFrame([r.to_dict() for r in results])
    df.to_csv(run_dir / "results.csv", index=False)
    table = summarize(df)
    text = table.to_markdown(floatfmt=".3g") + object_notes(models, unusable)
    (run_dir / "summary.md").write_text(text + "\n")
    print(
        f"\n{cfg.mode.name} / rot {cfg.rot.name} / {cfg.dataset.name} / planner {cfg.planner.name}: {run_dir}"
        f" ({len(df)} trials, {time.perf_counter() - wall0:.1f} s wall, {time.process_time() - cpu0:.1f} s CPU)"
    )
    print(text)
    return objective_value(df, cfg.objective)
