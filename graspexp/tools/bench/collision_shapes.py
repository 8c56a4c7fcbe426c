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

from pathlib import Path

import pandas as pd
from threadpoolctl import threadpool_limits

from graspexp.run.bench.collision_shapes import measure, staged_pairs
from graspexp.tools.cli import take_sweep, tool_parser


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
    pairs = staged_pairs(datasets, names)
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
