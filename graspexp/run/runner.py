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
import logging
import os
import platform
import socket
import sys
import time
import traceback
from collections.abc import Iterator
from contextlib import contextmanager
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

import pandas as pd
from filelock import FileLock, Timeout
from omegaconf import DictConfig, OmegaConf
from threadpoolctl import threadpool_limits
from tqdm import tqdm

from graspexp.config import BEFORE, validate
from graspexp.core.outcome import FailureReason, TrialResult
from graspexp.core.seeding import trial_seed
from graspexp.datasets import ObjectError, job_object, select_objects
from graspexp.datasets.model import ObjectModel
from graspexp.planning import plan
from graspexp.quality import fc_min_mu
from graspexp.record import (
    CorruptLogError,
    iter_trial_logs,
    read_result,
    read_trial,
    trial_log_path,
    trial_recorder,
)
from graspexp.record.reader import read_metadata
from graspexp.record.scene import ObjectScene, object_scene
from graspexp.record.writer import is_write_error
from graspexp.run.prepare import prepare_shapes
from graspexp.sim.collision_shapes import ShapeError, shape_with_fallback
from graspexp.sim.shape import CollisionShape
from graspexp.sim.trial import TrialContext, plain_config, run_trial

log = logging.getLogger(__name__)
RESULT_NEUTRAL_KEYS = (
    "progress",  # the progress bar
    "record",  # whether logs are written: a log that exists was recorded
    "trials",  # which trials run, not what one gives (a trial's seed derives from its object and index)
    "objects",
    "dataset.objects",
    "dataset.split",
    "objective",  # what the job returns to a sweeper, computed from the results
    "sim.cache_dir",  # where collision shapes are cached; entries are keyed by mesh content
    "sim.prepare_workers",  # how many processes build the collision shapes, not what they build
    "live",  # whether trials also stream to the Foxglove app
    "live_port",
)
"""Config keys (and their sub-keys) that resume ignores when it compares a log's recorded config with the
current one: they change what is shown or which trials run, never a trial's result. Add presentation-only
keys here (e.g. live-streaming flags). ``hydra.*`` is not part of the job config and never compared."""
LOCK_NAME = ".graspexp.lock"
"""Lock file in the job directory (``filelock``: flock(2), which Linux maps to POSIX locks on NFS, so it
holds across the nodes of a cluster; the kernel or the NFS server drops it when the holder dies)."""
HOLDER_NAME = ".graspexp.lock.holder"
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


class RunError(RuntimeError):
    """A job that cannot run as asked: a missing or unreadable input, an unwritable output folder, a
    directory held by another run or holding logs of another config. The message is one line."""


@dataclasses.dataclass(frozen=True)
class LoadedObject:
    """An object ready for its trials: model, collision shape, Foxglove scene, and what was assumed."""

    model: ObjectModel
    hulls: CollisionShape
    scene: ObjectScene
    notes: tuple[str, ...]
    """The model's notes (units, mass, area) and the collision shape's (a fallback method)."""


def job_metadata(cfg: DictConfig) -> dict[str, str]:
    """The part of every trial's MCAP metadata that is the same for the whole job."""
    meta = {"config_yaml": OmegaConf.to_yaml(cfg, resolve=True), "global_seed": str(cfg.seed)}
    meta.update({f"version.{k}": v for k, v in package_versions().items()})
    return meta


def _metadata(job_meta: dict[str, str], loaded: LoadedObject, trial: int, seed: int) -> dict[str, str]:
    """One trial's log metadata: the job's, the trial's seeds and what its object was made of (the mesh
    file, "" for a procedural one, the SHA-256 of the geometry used, the collision method it got, and what
    was assumed for it: units, mass, area)."""
    return {
        **job_meta,
        "object": loaded.model.name,
        "trial": str(trial),
        "trial_seed": str(seed),
        "mesh_source": loaded.model.source,
        "mesh_sha256": loaded.model.mesh_sha256,
        "collision_method": loaded.hulls.method,
        "object_notes": "\n".join(loaded.notes),
    }


def _unusable_object_trials(
    cfg: DictConfig, object_name: str, run_dir: Path, reason: str, bar: tqdm | None
) -> list[TrialResult]:
    """Every trial of an object that cannot be used: an ``error`` result with ``reason``, logged (when
    ``record``) so that the report counts it; resume tries the object again."""
    plain = plain_config(cfg)
    results = []
    for i in range(cfg.trials):
        seed = trial_seed(plain, object_name, i)
        result = _error_result(cfg, object_name, i, seed, ObjectError(reason))
        path = trial_log_path(run_dir, object_name, i)
        path.parent.mkdir(parents=True, exist_ok=True)
        meta = {**job_metadata(cfg), "object": object_name, "trial": str(i), "trial_seed": str(seed)}
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
            f"{meta.get('mesh_source') or 'procedural'}, sha256 {logged[:12]}; now "
            f"{model.source or 'procedural'}, sha256 {model.mesh_sha256[:12]}); resume only reuses trials "
            f"of the same mesh: choose another output directory or delete {run_dir / 'trials'}"
        )


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
        result = _finished(path)
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


def _finished(path: Path) -> TrialResult | None:
    """The result of a complete log at ``path``; None if absent, partial, corrupt or an ``error`` trial
    (then it is redone)."""
    if not path.exists():
        return None
    try:
        result = TrialResult.from_dict(read_result(path))
    except CorruptLogError as exc:
        log.warning("re-running trial: %s", exc)
        path.unlink()
        return None
    if result.reason == FailureReason.ERROR.value:
        log.info("re-running trial %s: it ended in an error (%s)", path, result.error)
        path.unlink()
        return None
    return result


def _flatten(node: object, prefix: str = "") -> dict[str, object]:
    if isinstance(node, dict):
        out: dict[str, object] = {}
        for k, v in node.items():
            out.update(_flatten(v, f"{prefix}{k}."))
        return out
    return {prefix[:-1]: node}


def _neutral(key: str) -> bool:
    return any(key == n or key.startswith(n + ".") for n in RESULT_NEUTRAL_KEYS)


_NO_DEFAULT = object()


def _value_before(cfg: DictConfig, key: str) -> object:
    """The value dotted ``key`` had before graspexp added it: its schema field's ``metadata["before"]``
    (:data:`graspexp.config.BEFORE`) when the key came with a new behaviour, else its default; else
    ``_NO_DEFAULT``."""
    parent, _, leaf = key.rpartition(".")
    node = OmegaConf.select(cfg, parent) if parent else cfg
    schema = OmegaConf.get_type(node) if isinstance(node, DictConfig) else None
    for f in dataclasses.fields(schema) if dataclasses.is_dataclass(schema) else ():
        if f.name != leaf:
            continue
        if BEFORE in f.metadata:
            return f.metadata[BEFORE]
        if f.default is not dataclasses.MISSING:
            return f.default
        if f.default_factory is not dataclasses.MISSING:
            return f.default_factory()
    return _NO_DEFAULT


def config_differences(recorded_yaml: str, cfg: DictConfig) -> dict[str, tuple[object, object]]:
    """dotted key -> (value in the log, value now) for every key that affects a result and differs; a key
    absent on one side shows as ``<absent>``. A key the log lacks is not a difference when it now has the
    value the code had before the key was added (:func:`_value_before`)."""
    old = _flatten(OmegaConf.to_container(OmegaConf.create(recorded_yaml), resolve=True))
    new = _flatten(OmegaConf.to_container(cfg, resolve=True))
    absent = "<absent>"
    return {
        k: (old.get(k, absent), new.get(k, absent))
        for k in sorted(old.keys() | new.keys())
        if not _neutral(k)
        and old.get(k, absent) != new.get(k, absent)
        and not (k not in old and k in new and new[k] == _value_before(cfg, k))
    }


def check_resumable(cfg: DictConfig, run_dir: Path) -> None:
    """Raise RunError if a finished log in ``run_dir`` was made with a different config (see
    :data:`RESULT_NEUTRAL_KEYS`); partial and unreadable logs are left to be redone."""
    for path in iter_trial_logs(run_dir):
        try:
            recorded = read_trial(path).metadata.get("config_yaml", "")
        except CorruptLogError:
            continue
        diff = config_differences(recorded, cfg)
        if diff:
            keys = sorted(diff, key=lambda k: ("." in k and not k.endswith(".name"), k))  # choices first
            shown = "; ".join(f"{k}: {diff[k][0]!r} in the log, {diff[k][1]!r} now" for k in keys[:4])
            raise RunError(
                f"{run_dir} holds trial logs made with a different config; differing keys: {', '.join(keys)} "
                f"({path.relative_to(run_dir)}: {shown}); resume only reuses logs of the same config: "
                f"choose another output directory (hydra.run.dir / hydra.sweep.dir) or delete {run_dir / 'trials'}"
            )


@contextmanager
def job_lock(run_dir: Path) -> Iterator[None]:
    """Hold the exclusive lock of ``run_dir`` for the block; RunError naming the holder if another run has it."""
    holder = run_dir / HOLDER_NAME
    lock = FileLock(run_dir / LOCK_NAME, timeout=0)
    try:
        run_dir.mkdir(parents=True, exist_ok=True)
        lock.acquire()
    except Timeout:
        try:
            who = holder.read_text().strip()
        except OSError:
            who = "unknown"
        raise RunError(
            f"{run_dir} is in use by another run ({who}); wait for it to finish or use another "
            "output directory (hydra.run.dir / hydra.sweep.dir)"
        ) from None
    except OSError as exc:
        raise RunError(f"cannot write to the output directory {run_dir}: {exc.strerror or exc}") from None
    try:
        now = datetime.datetime.now().astimezone().isoformat(timespec="seconds")
        cmd = " ".join(sys.argv)
        holder.write_text(f"pid {os.getpid()} on {socket.gethostname()} since {now}: {cmd}\n")
        yield
    finally:
        lock.release()


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

    return run_in_dir(cfg, Path(HydraConfig.get().runtime.output_dir))


def run_in_dir(cfg: DictConfig, run_dir: Path) -> float:
    """:func:`run_job` into ``run_dir`` (resumable, locked), outside a Hydra run (e.g. the benchmark). The
    config is validated, then frozen: nothing in the job can change it (a write raises)."""
    validate(cfg)
    OmegaConf.set_readonly(cfg, True)
    with job_lock(run_dir), threadpool_limits(limits=1):  # trials are sequential: one core per job
        return _run(cfg, run_dir)


def _run(cfg: DictConfig, run_dir: Path) -> float:
    wall0, cpu0 = time.perf_counter(), time.process_time()
    objects = select_objects(cfg.dataset, cfg.objects)
    check_resumable(cfg, run_dir)
    prepare_shapes(cfg.dataset, cfg.sim, objects, cfg.progress)
    models, unusable = load_models(cfg, objects)
    check_same_meshes(run_dir, {name: loaded.model for name, loaded in models.items()})
    results: list[TrialResult] = []
    with tqdm(
        total=len(objects) * cfg.trials,
        desc=f"{cfg.mode.name}/{cfg.rot.name}/{cfg.dataset.name}",
        disable=not cfg.progress,
    ) as bar:
        for name in objects:
            results.extend(run_object_trials(cfg, name, run_dir, bar, models.get(name) or unusable[name]))
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
