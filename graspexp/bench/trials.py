"""Trial benchmark: per-phase time split, trials/s with 1 and 2 processes, and the overhead ratio
(full trial incl. planning and MCAP logging) / (time spent in the physics steps of the same trial).

    python -m graspexp.bench.trials [dataset=ycb] [mode=bin] [--trials 10] [--objects a,b]

Figures are medians over trials (per-phase) and over repeats (throughput).
"""

import argparse
import statistics
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from contextlib import nullcontext
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

from graspexp.cli import compose_config
from graspexp.datasets import available_objects, load_object
from graspexp.record import TrialRecorder
from graspexp.seeding import derive_seed
from graspexp.sim.collision_shapes import collision_shape
from graspexp.sim.trial import NullRecorder, TrialContext, plain_config, run_trial, trial_seed

PHASES = ("build", "settle", "plan", "quality", "execute", "log")


def _run_object(args: tuple[list[str], str, int, str | None]) -> list[dict]:
    """All trials of one object with MCAP logging into ``out`` (None: no logging); per-trial timings."""
    overrides, name, trials, out = args
    threadpool_limits(limits=1)
    cfg = compose_config(overrides)
    plain = plain_config(cfg)
    model = load_object(cfg.dataset, name, cfg.planner.n_points, derive_seed(cfg.seed, "cloud", name))
    hulls = collision_shape(model.mesh, plain.sim)
    rows = []
    for i in range(trials):
        t0 = time.perf_counter()
        if out is None:
            recorder = nullcontext(NullRecorder())
        else:
            path = Path(out) / name / f"{i:03d}.mcap"
            path.parent.mkdir(parents=True, exist_ok=True)
            recorder = TrialRecorder(path, {"object": name})
        with recorder as rec:
            res = run_trial(TrialContext(plain, model, hulls, i, trial_seed(plain, name, i), rec))
        rows.append({"wall": time.perf_counter() - t0, "success": res.success, **res.timings_s})
    return rows


def _throughput(overrides: list[str], names: list[str], trials: int, workers: int) -> float:
    with tempfile.TemporaryDirectory() as out:
        jobs = [(overrides, n, trials, out) for n in names]
        t0 = time.perf_counter()
        if workers == 1:
            n = sum(len(_run_object(j)) for j in jobs)
        else:
            with ProcessPoolExecutor(workers) as pool:
                n = sum(len(r) for r in pool.map(_run_object, jobs))
        return n / (time.perf_counter() - t0)


def main(argv: list[str] | None = None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("overrides", nargs="*", help="Hydra overrides, e.g. dataset=ycb mode=bin")
    ap.add_argument("--trials", type=int, default=10, help="trials per object")
    ap.add_argument("--objects", default="", help="comma-separated subset")
    ap.add_argument("--repeats", type=int, default=3, help="repeats of the throughput runs")
    args = ap.parse_args(argv)
    threadpool_limits(limits=1)
    cfg = compose_config(args.overrides)
    names = args.objects.split(",") if args.objects else available_objects(cfg.dataset)
    print(
        f"trial benchmark: {cfg.dataset.name} {cfg.mode.name} rot={cfg.rot.name}, {len(names)} objects x {args.trials}"
    )
    _run_object((args.overrides, names[0], 1, tempfile.mkdtemp()))  # warm caches (decomposition, imports)
    with tempfile.TemporaryDirectory() as out:
        rows = [r for n in names for r in _run_object((args.overrides, n, args.trials, out))]
    print(f"\nper-phase wall time, median over {len(rows)} trials (ms):")
    for ph in (*PHASES, "physics"):
        vals = [1e3 * r[ph] for r in rows]
        print(f"  {ph:<8} p50 {statistics.median(vals):8.2f}   p95 {np.percentile(vals, 95):8.2f}")
    total = [r["wall"] for r in rows]
    ratio = [r["wall"] / r["physics"] for r in rows]
    print(f"  {'trial':<8} p50 {1e3 * statistics.median(total):8.2f}")
    print(
        f"\noverhead ratio (full trial incl. planning + logging) / (physics steps): median {statistics.median(ratio):.3f}"
        f"  (target <= 1.25)"
    )
    bare = [r for n in names for r in _run_object((args.overrides, n, args.trials, None))]
    print(
        "overhead ratio without MCAP logging (record=false): median "
        f"{statistics.median(r['wall'] / r['physics'] for r in bare):.3f}"
    )
    print(f"success: {sum(r['success'] for r in rows)}/{len(rows)}")
    tp = {
        w: statistics.median(_throughput(args.overrides, names, args.trials, w) for _ in range(args.repeats))
        for w in (1, 2)
    }
    print(
        f"\nthroughput (median of {args.repeats}): 1 process {tp[1]:.2f} trials/s, 2 processes {tp[2]:.2f} trials/s "
        f"(x{tp[2] / tp[1]:.2f})"
    )


if __name__ == "__main__":
    main()
