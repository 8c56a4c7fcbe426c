"""Collision-shape benchmark: each object's collision shape against its mesh, its cold preparation
time and its physics cost per step.

    python -m graspexp bench.collision_shapes [--out DIR] [dataset=ycb,linemod] [objects=[a,b]]
        [sim.collision_method=mesh,coacd,vhacd] [trials=3] [sim.coacd_threshold=0.05 ...]

Per object and method: collision parts, their triangles, cold preparation (built into an empty
temporary cache; wall and CPU seconds of this process, all its threads), the first scene build
(``cook_s``: PhysX cooks the shape, an SDF for ``mesh``; once per process, not cached on disk), the collision surface
outside the mesh (median, 90th percentile, max; mm, see :mod:`graspexp.sim.collision_accuracy`) and
inside it (90th percentile), how far the mesh surface lies outside the collision shape
(``uncovered_p90_mm``: missing material, e.g. a dropped part), the physics wall time per step with the object resting on the support box
(``rest_us``) and, median over ``trials=`` (default 3) full collab trials with the gripper closing on it
(``trial_us``). Prints one row per object, then the median and worst per method, and writes
``DIR/collision_shapes.csv`` (default ``outputs/bench``). ``dataset=`` and ``sim.collision_method=`` take
several values (default ``ycb,linemod`` and ``mesh``); ``objects=[...]`` picks staged objects (default every
staged one); other arguments are Hydra overrides (e.g. ``sim.coacd_threshold=0.05``).
"""

import statistics
import tempfile
import time
from pathlib import Path

import numpy as np
import pandas as pd
import trimesh
from omegaconf import OmegaConf
from threadpoolctl import threadpool_limits

from graspexp.config.compose import compose_config
from graspexp.datasets import job_object
from graspexp.run.objects import LoadedObject, trial_context
from graspexp.run.prepare import staged_objects
from graspexp.sim.collision_accuracy import shape_accuracy, surface_points, uncovered_m
from graspexp.sim.collision_shapes import collision_shape
from graspexp.sim.scene import build_scene
from graspexp.sim.trial import plain_config, run_trial
from graspexp.tools.cli import take_sweep, tool_parser

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


def _objects(datasets: list[str], objects: list[str]) -> list[tuple[str, str]]:
    """(dataset, object) of every staged object of ``datasets``, or of those named in ``objects``."""
    pairs = []
    for ds in datasets:
        names = staged_objects(compose_config([f"dataset={ds}"]).dataset)
        pairs += [(ds, n) for n in names if not objects or n in objects]
    return pairs


def main(argv: list[str] | None = None) -> None:
    ap = tool_parser("graspexp bench.collision_shapes", __doc__.splitlines()[0], overrides=True)
    ap.add_argument("--out", type=Path, default=Path("outputs/bench"), help="output folder")
    ap.add_argument("--samples", type=int, default=10000, help="collision-surface samples per object")
    args = ap.parse_intermixed_args(argv)
    threadpool_limits(limits=1)
    datasets, rest = take_sweep(args.overrides, "dataset", ["ycb", "linemod"])
    methods, rest = take_sweep(rest, "sim.collision_method", ["mesh"])
    objects, rest = take_sweep(rest, "objects", [])
    trials, rest = take_sweep(rest, "trials", ["3"])
    names = [n.strip() for o in objects for n in o.strip("[]").split(",") if n.strip()]
    pairs = _objects(datasets, names)
    if not pairs:
        ap.error(f"no staged object of {','.join(datasets)} matches objects={objects}")
    rows = []
    for method in methods:
        for ds, name in pairs:
            row = measure([*rest, f"sim.collision_method={method}"], ds, name, int(trials[0]), args.samples)
            rows.append(row)
            print(
                f"{method:6s} {name:26s} parts {row['parts']:3d} prep {row['prep_wall_s']:6.1f} s "
                f"(CPU {row['prep_cpu_s']:6.1f}) cook {row['cook_s']:.2f} s out p50 {row['out_p50_mm']:.2f} p90 {row['out_p90_mm']:.2f} "
                f"max {row['out_max_mm']:.1f} mm, in p90 {row['in_p90_mm']:.2f} mm, "
                f"uncovered p90 {row['uncovered_p90_mm']:.2f} mm, "
                f"rest {row['rest_us']:.0f} us/step, trial {row['trial_us']:.0f} us/step",
                flush=True,
            )
    df = pd.DataFrame(rows)
    out = args.out / "collision_shapes.csv"
    out.parent.mkdir(parents=True, exist_ok=True)
    df.to_csv(out, index=False)
    print()
    print(df.drop(columns=["dataset"]).to_markdown(index=False, floatfmt=".2f"))
    g = df.groupby("method", sort=False)
    summary = pd.DataFrame(
        {
            "objects": g.size(),
            "p90_median_mm": g["out_p90_mm"].median(),
            "p90_worst_mm": g["out_p90_mm"].max(),
            "over_1mm": g["out_p90_mm"].apply(lambda s: int((s > 1.0).sum())),
            "uncovered_p90_worst_mm": g["uncovered_p90_mm"].max(),
            "parts_median": g["parts"].median(),
            "prep_cpu_total_s": g["prep_cpu_s"].sum(),
            "prep_wall_total_s": g["prep_wall_s"].sum(),
            "cook_total_s": g["cook_s"].sum(),
            "rest_us_median": g["rest_us"].median(),
            "trial_us_median": g["trial_us"].median(),
        }
    )
    print()
    print(summary.to_markdown(floatfmt=".2f"))
    print(f"\nwrote {out}")


if __name__ == "__main__":
    main()
