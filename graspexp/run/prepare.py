"""Collision shapes built before the trials: every object's shape built once, in parallel, with progress.

The runner calls :func:`prepare_shapes` before its trials, so a first run shows this progress instead of
sitting at 0 %; ``python -m graspexp prepare`` fills the cache ahead of a sweep.
"""

import logging
import multiprocessing
import time
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait

from omegaconf import DictConfig, OmegaConf
from tqdm import tqdm

from graspexp.config import SimConfig
from graspexp.datasets import DatasetError, available_objects, catalogue
from graspexp.datasets.loader import object_mesh
from graspexp.sim.collision_shapes import ShapeError, is_cached, shape_with_fallback

log = logging.getLogger(__name__)
REFRESH_S = 5.0
"""The progress bar redraws (elapsed time, objects in work) at least this often, s."""


def _build_one(dataset: dict, sim: SimConfig | DictConfig, name: str) -> tuple[str, float, float, int]:
    """Build (and cache) one object's shape; (name, wall s, CPU s, parts)."""
    t0, c0 = time.perf_counter(), time.process_time()
    shape, _ = shape_with_fallback(object_mesh(OmegaConf.create(dataset), name)[0].mesh, sim)
    return name, time.perf_counter() - t0, time.process_time() - c0, len(shape.parts)


def prepare_shapes(
    dataset_cfg: DictConfig, sim: SimConfig | DictConfig, names: list[str], progress: bool = True
) -> dict[str, str]:
    """Build the missing collision shapes of objects ``names`` of ``dataset_cfg`` into the cache.

    Objects whose shape is cached are skipped; the rest are built by ``sim.prepare_workers`` processes,
    one object each, with a progress bar that names the objects in work. Returns ``{name: why}`` for the
    objects whose mesh cannot be loaded or whose shape cannot be built (their trials record it).
    """
    failed: dict[str, str] = {}
    missing = [n for n in names if _needs_build(dataset_cfg, sim, n, failed)]
    if not missing:
        return failed
    dataset = OmegaConf.to_container(dataset_cfg, resolve=True)
    workers = max(1, min(int(sim.prepare_workers), len(missing))) if _can_spawn() else 1
    desc = f"collision shapes ({sim.collision_method}, {dataset_cfg.name})"
    with tqdm(total=len(missing), desc=desc, disable=not progress) as bar:
        if workers == 1:
            for name in missing:
                bar.set_postfix_str(f"building {name}")
                try:
                    _report(bar, _build_one(dataset, sim, name))
                except (DatasetError, ShapeError) as exc:
                    failed[name] = str(exc)
                    bar.update()
            return failed
        ctx = multiprocessing.get_context("spawn")  # no fork of a process that holds PhysX threads
        with ProcessPoolExecutor(workers, mp_context=ctx) as pool:
            running = {pool.submit(_build_one, dataset, sim, n): n for n in missing}
            while running:
                busy = sorted(n for f, n in running.items() if f.running())
                bar.set_postfix_str("in work: " + ", ".join(busy) if busy else "starting workers")
                done, _ = wait(running, timeout=REFRESH_S, return_when=FIRST_COMPLETED)
                for fut in done:
                    name = running.pop(fut)
                    if fut.exception() is not None:
                        log.error("collision shape of %s failed: %s", name, fut.exception())
                        failed[name] = str(fut.exception())
                        bar.update()
                    else:
                        _report(bar, fut.result())
                bar.refresh()
    return failed


def _can_spawn() -> bool:
    """False inside a worker of a joblib (loky) pool, e.g. a job of the benchmark or of
    ``hydra/launcher=joblib``: its start method is ``loky``, which children spawned by plain
    multiprocessing cannot re-create (they die with "cannot find context for 'loky'"). The pool already
    uses the cores, so the shapes are built in this process."""
    return multiprocessing.get_start_method(allow_none=True) in (None, "fork", "spawn", "forkserver")


def _needs_build(
    dataset_cfg: DictConfig, sim: SimConfig | DictConfig, name: str, failed: dict[str, str]
) -> bool:
    try:
        return not is_cached(object_mesh(dataset_cfg, name)[0].mesh, sim)
    except DatasetError as exc:
        failed[name] = str(exc)  # the object's trials report the missing or broken mesh
        return False


def _report(bar: tqdm, result: tuple[str, float, float, int]) -> None:
    name, wall, cpu, parts = result
    log.info("collision shape of %s: %d part(s), %.1f s wall, %.1f s CPU", name, parts, wall, cpu)
    bar.update()


def staged_objects(dataset_cfg: DictConfig) -> list[str]:
    """Every catalogue object of the dataset whose mesh file exists under the data root."""
    every = OmegaConf.merge(dataset_cfg, {"objects": list(catalogue(dataset_cfg))})
    return available_objects(every)
