"""The main job: every trial of every object of the dataset, one MCAP log per trial, a results table.

Run directory layout (Hydra's output dir)::

    trials/<object>/<trial>.mcap   one log per trial (the source of truth)
    results.csv                    one row per trial (a cache rebuilt from the logs at the end)
    summary.md                     the per-object success table printed at the end

Re-running into the same directory resumes: trials whose log is complete are read back, not re-run.
With ``record=false`` no log is written (faster, but nothing to replay and nothing to resume from).
"""

import logging
import platform
import traceback
from contextlib import nullcontext
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

import pandas as pd
from omegaconf import DictConfig, OmegaConf
from threadpoolctl import threadpool_limits
from tqdm import tqdm

from graspexp.config import validate
from graspexp.datasets import DatasetError, available_objects, dataset_objects, load_object
from graspexp.prepare import prepare_shapes
from graspexp.record import CorruptLogError, TrialRecorder, read_result
from graspexp.seeding import derive_seed
from graspexp.sim.collision_shapes import collision_shape
from graspexp.sim.outcome import FailureReason, TrialResult
from graspexp.sim.trial import NullRecorder, TrialContext, plain_config, run_trial, scene_entities, trial_seed

log = logging.getLogger(__name__)
PACKAGES = ("graspexp", "sapien", "numpy", "scikit-learn", "trimesh", "coacd", "mcap", "hydra-core")


def package_versions() -> dict[str, str]:
    out = {"python": platform.python_version()}
    for name in PACKAGES:
        try:
            out[name] = version(name)
        except PackageNotFoundError:
            out[name] = "unknown"
    return out


def select_objects(cfg: DictConfig) -> list[str]:
    """The objects to run: ``objects=[...]`` if given (each must exist), else the dataset's list less
    the objects whose files are missing (named in a warning with the download command)."""
    names = dataset_objects(cfg.dataset)
    if cfg.objects:
        unknown = [o for o in cfg.objects if o not in names]
        if unknown:
            raise DatasetError(f"unknown object(s) {unknown} in dataset {cfg.dataset.name!r}; valid: {names}")
        return list(cfg.objects)
    present = available_objects(cfg.dataset)
    if not present:
        load_object(cfg.dataset, names[0], 16, 0)  # raises the DatasetError that names the missing path
    missing = [o for o in names if o not in present]
    if missing:
        log.warning(
            "dataset %s: no mesh for %s under the data root; skipping them (get them with "
            "`python -m graspexp.download dataset=%s`)",
            cfg.dataset.name,
            missing,
            cfg.dataset.name,
        )
    return [o for o in names if o in present]


def trial_log_path(run_dir: Path, object_name: str, trial: int) -> Path:
    return run_dir / "trials" / object_name / f"{trial:03d}.mcap"


def job_metadata(cfg: DictConfig) -> dict[str, str]:
    """The part of every trial's MCAP metadata that is the same for the whole job."""
    meta = {"config_yaml": OmegaConf.to_yaml(cfg, resolve=True), "global_seed": str(cfg.seed)}
    meta.update({f"version.{k}": v for k, v in package_versions().items()})
    return meta


def _metadata(job_meta: dict[str, str], object_name: str, trial: int, seed: int) -> dict[str, str]:
    return {**job_meta, "object": object_name, "trial": str(trial), "trial_seed": str(seed)}


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


def run_object_trials(
    cfg: DictConfig, object_name: str, run_dir: Path, bar: tqdm | None = None
) -> list[TrialResult]:
    """Every trial of one object; finished trials found in ``run_dir`` are read back instead of re-run."""
    plain = plain_config(cfg)
    job_meta = job_metadata(cfg)
    model = hulls = entities = load_error = None
    results = []
    for i in range(cfg.trials):
        path = trial_log_path(run_dir, object_name, i)
        seed = trial_seed(plain, object_name, i)
        result = _finished(path)
        if result is None:
            path.parent.mkdir(parents=True, exist_ok=True)
            recorder = (
                TrialRecorder(path, _metadata(job_meta, object_name, i, seed))
                if cfg.record
                else nullcontext(NullRecorder())
            )
            with recorder as rec:
                try:
                    if load_error is not None:
                        raise load_error
                    if model is None:
                        cloud_seed = derive_seed(cfg.seed, "cloud", object_name)
                        model = load_object(cfg.dataset, object_name, cfg.planner.n_points, cloud_seed)
                        hulls = collision_shape(model.mesh, plain.sim)
                        entities = scene_entities(plain, hulls)
                    result = run_trial(TrialContext(plain, model, hulls, i, seed, rec, entities))
                except Exception as exc:  # one trial's error is recorded; the sweep goes on
                    if model is None:
                        load_error = exc
                    if i == 0 or model is not None:
                        log.error("%s trial %d failed with an error: %s", object_name, i, exc)
                    result = _error_result(cfg, object_name, i, seed, exc)
                    rec.result(0.0, result.to_dict())
        results.append(result)
        if bar is not None:
            bar.set_postfix_str(f"{object_name} #{i}: {'ok' if result.success else result.reason}")
            bar.update()
    return results


def _finished(path: Path) -> TrialResult | None:
    """The result of a complete log at ``path``; None if absent, partial or corrupt (then it is redone)."""
    if not path.exists():
        return None
    try:
        return TrialResult.from_dict(read_result(path))
    except CorruptLogError as exc:
        log.warning("re-running trial: %s", exc)
        path.unlink()
        return None


def summarize(df: pd.DataFrame) -> pd.DataFrame:
    """Per-object success rate (%) and failure counts, plus an Average row."""
    g = df.groupby("object", sort=False)
    table = pd.DataFrame({"trials": g.size(), "success_%": 100.0 * g["success"].mean()})
    reasons = df[~df["success"]].pivot_table(
        index="object", columns="reason", values="trial", aggfunc="count"
    )
    table = table.join(reasons.fillna(0).astype(int)) if not reasons.empty else table
    table.loc["Average"] = table.mean(numeric_only=True)
    return table.fillna(0)


def run_job(cfg: DictConfig) -> float:
    """Run every trial for every selected object; returns the overall success rate in [0, 1]."""
    from hydra.core.hydra_config import HydraConfig

    validate(cfg)
    run_dir = Path(HydraConfig.get().runtime.output_dir)
    with threadpool_limits(limits=1):  # trials are sequential and small: one core per job process
        return _run(cfg, run_dir)


def _run(cfg: DictConfig, run_dir: Path) -> float:
    objects = select_objects(cfg)
    prepare_shapes(cfg.dataset, cfg.sim, objects, cfg.progress)
    results: list[TrialResult] = []
    with tqdm(
        total=len(objects) * cfg.trials,
        desc=f"{cfg.mode.name}/{cfg.rot.name}/{cfg.dataset.name}",
        disable=not cfg.progress,
    ) as bar:
        for name in objects:
            results.extend(run_object_trials(cfg, name, run_dir, bar))
    df = pd.DataFrame([r.to_dict() for r in results])
    df.to_csv(run_dir / "results.csv", index=False)
    table = summarize(df)
    text = table.to_markdown(floatfmt=".3g")
    (run_dir / "summary.md").write_text(text + "\n")
    print(
        f"\n{cfg.mode.name} / rot {cfg.rot.name} / {cfg.dataset.name} / planner {cfg.planner.name}: {run_dir}"
    )
    print(text)
    return float(df["success"].mean())
