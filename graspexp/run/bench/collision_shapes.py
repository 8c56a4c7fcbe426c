"""Collision-shape benchmark, measured: each object's collision shape against its mesh, its cold preparation
time and its physics cost per step (``python -m graspexp bench.collision_shapes`` parses and prints)."""

import statistics
import tempfile
import time

import numpy as np
import trimesh
from omegaconf import OmegaConf

from graspexp.config.compose import compose_config
from graspexp.datasets import job_object
from graspexp.run.objects import LoadedObject, trial_context
from graspexp.run.prepare import staged_objects
from graspexp.sim.collision_accuracy import shape_accuracy, surface_points, uncovered_m
from graspexp.sim.collision_shapes import collision_shape
from graspexp.sim.scene import build_scene
from graspexp.sim.trial import plain_config, run_trial

REST_STEPS = 600
"""Steps of the resting scene (2.5 s at 1/240 s), after the object has landed."""


def _rest_scene(shape, mesh, mass_kg: float, cfg) -> tuple[float, float]:
    """(wall s of the first scene build, which cooks the shape in PhysX; wall us per physics step of the
    object standing on the support box, z up, mesh bottom on it)."""
    pose = np.eye(4)
    pose[2, 3] = cfg.mode.support_height_m - mesh.bounds[0, 2] + 1e-3
    t0 = time.perf_counter()
    ts = build_scene(shape, mass_kg, pose, cfg.mode, cfg.sim)
    cook_s = time.perf_counter() - t0
    for _ in range(240):  # land
        ts.scene.step()
    t0 = time.perf_counter()
    for _ in range(REST_STEPS):
        ts.scene.step()
    return cook_s, (time.perf_counter() - t0) / REST_STEPS * 1e6


def measure(overrides: list[str], dataset: str, name: str, trials: int, samples: int) -> dict:
    """One row of the table for object ``name`` of ``dataset`` under the config ``overrides``."""
    cfg = compose_config([*overrides, f"dataset={dataset}", "mode=collab", "rot=z"])
    plain = plain_config(cfg)
    model = job_object(cfg, name)
    with tempfile.TemporaryDirectory() as cache:
        sim = OmegaConf.to_object(cfg.sim)
        sim.cache_dir = cache
        t0, c0 = time.perf_counter(), time.process_time()
        shape = collision_shape(model.mesh, sim)
        prep_wall, prep_cpu = time.perf_counter() - t0, time.process_time() - c0
        acc = shape_accuracy(surface_points(shape, samples, rng=np.random.default_rng(0)), model.mesh)
        mesh_pts, _ = trimesh.sample.sample_surface(model.mesh, samples // 2, seed=1)
        gap_p90 = float(np.percentile(uncovered_m(mesh_pts, shape), 90)) * 1e3
        cook, rest = _rest_scene(shape, model.mesh, model.mass_kg, plain)
        per_step, ok = [], 0
        loaded = LoadedObject(model, shape, None, ())  # the shape just built in the empty cache
        for i in range(trials):
            res = run_trial(trial_context(plain, loaded, i))
            ok += res.success
            if res.steps:
                per_step.append(res.timings_s["physics"] / res.steps * 1e6)
    return {
        "dataset": dataset,
        "object": name,
        "method": cfg.sim.collision_method,
        "parts": len(shape.parts),
        "faces": sum(len(f) for _, f in shape.parts),
        "prep_wall_s": prep_wall,
        "prep_cpu_s": prep_cpu,
        "cook_s": cook,
        "out_p50_mm": acc.outside_p50_mm,
        "out_p90_mm": acc.outside_p90_mm,
        "out_max_mm": acc.outside_max_mm,
        "in_p90_mm": acc.inside_p90_mm,
        "uncovered_p90_mm": gap_p90,
        "rest_us": rest,
        "trial_us": statistics.median(per_step) if per_step else float("nan"),
        "trials_ok": f"{ok}/{trials}",
    }


def staged_pairs(datasets: list[str], objects: list[str]) -> list[tuple[str, str]]:
    """(dataset, object) of every staged object of ``datasets``, or of those named in ``objects``."""
    pairs = []
    for ds in datasets:
        names = staged_objects(compose_config([f"dataset={ds}"]).dataset)
        pairs += [(ds, n) for n in names if not objects or n in objects]
    return pairs
