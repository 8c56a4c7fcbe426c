"""Planner latency per paper Table 1/2 object, single-threaded (paper IV-F reports 0.1 s per plan).

Usage::

    GRASPEXP_DATA=/path/to/datasets python -m graspexp bench.plan_latency [--repeats 5] [--runs 30]
        [planner=optimal,optimal_plus] [dataset=ycb,linemod] [mode=collab,bin] [key=value ...]

One table per planner and dataset (``planner=``, ``dataset=`` and ``mode=`` take several values, Hydra's
syntax; default ``planner=optimal``, ``dataset=ycb`` and the paper's modes). Each object stands upright on
the support (:mod:`graspexp.run.upright`) (N = ``planner.n_points``; M = ``planner.m``), in each mode. One
repeat times ``--runs`` plans after a warm-up and takes their p50 and p95, on the wall clock and as CPU
time of this thread (the figure that stays stable when other processes share the machine); the table
shows the median over repeats of each. BLAS/OpenMP run on one thread (``OMP_NUM_THREADS=1`` and friends
set before numpy loads, and threadpoolctl). ``vs paper`` is the CPU p50 / 100 ms. More columns split the
paper's steps of the same request, each the CPU-time p50 (median over repeats): ``K-means``
(:func:`graspexp.planning.clusters.segment`), ``Eq.1-3`` (:func:`graspexp.planning.optimal.path_costs`,
every path above the support) and ``ns/el``, the compiled Eq. (1) kernel alone
(:func:`graspexp.planning.kernels.distance_sums`) per (path, point) element. Each table ends with its
planner's CPU target (:data:`TARGETS_CPU_MS`) and the rows over it. The header gives the float32
square-root throughput of this machine measured the same way (the bound that kernel runs against: one
sqrt per element) and what the first plan of the process cost (numba's import came before; its kernels
come from the on-disk cache or are compiled). Without ``objects=[...]`` it times the dataset's objects
staged under the data root and names the others; without any of its meshes it falls back to the
procedural ``primitives`` dataset and says so. Extra ``key=value`` arguments are Hydra
overrides.
"""

import sys  # noqa: E402
from collections.abc import Sequence  # noqa: E402

import numpy as np  # noqa: E402
from threadpoolctl import threadpool_limits  # noqa: E402

from graspexp.config import ConfigError  # noqa: E402
from graspexp.datasets import DatasetError  # noqa: E402
from graspexp.planning import plan  # noqa: E402
from graspexp.run.bench.plan_latency import (
    WARMUP_RUNS,
    first_plan_s,
    print_table,
    sqrt_bound_ns,
    staged_rows,
    time_runs,
    timed_calls,
)
from graspexp.run.suites import PAPER_MODES  # noqa: E402
from graspexp.tools.cli import fail, take_sweep, tool_parser  # noqa: E402


def main(argv: Sequence[str] | None = None) -> int:
    parser = tool_parser("graspexp bench.plan_latency", __doc__.split("\n")[0], overrides=True)
    parser.add_argument("--repeats", type=int, default=5, help="repeats per object and mode (median taken)")
    parser.add_argument("--runs", type=int, default=30, help="timed plans per repeat")
    args = parser.parse_intermixed_args(argv)
    prog = parser.prog
    planners, rest = take_sweep(args.overrides, "planner", ["optimal"])
    datasets, rest = take_sweep(rest, "dataset", ["ycb"])
    modes, rest = take_sweep(rest, "mode", PAPER_MODES)
    tables = []  # (planner, dataset, rows)
    for planner in planners:
        for dataset in datasets:
            try:
                rows, name, notes = staged_rows([f"planner={planner}", f"dataset={dataset}", *rest], modes)
            except (ConfigError, DatasetError) as err:
                fail(str(err), prog)
            for note in notes:
                print(note)
            tables.append((planner, name, rows))
    requests = [req for *_, rows in tables for *_, req in rows]
    first = first_plan_s(requests[0])
    tables = [  # K of each row's plan
        (planner, dataset, [(n, m, plan(req).grasp.extras.get("K", 0), a, req) for n, m, a, req in rows])
        for planner, dataset, rows in tables
    ]
    with threadpool_limits(limits=1):
        calls = [timed_calls(req) for req in requests]
        sqrt_ns = sqrt_bound_ns(args.repeats)
        print(
            f"plan latency, gripper={requests[0].gripper.name}, "
            f"1 thread, {args.repeats} round-robin repeats x {args.runs} runs (median of per-repeat p50/p95)\n"
            f"first plan of this process: {first[0]:.2f} s ({first[1]}); float32 sqrt bound of this "
            f"machine: {sqrt_ns:.3f} ns/element"
        )
        n_calls = len(calls[0][0])
        timings = np.empty((args.repeats, len(calls), n_calls, 2, 2))  # repeat, row, call, wall|CPU, p50|p95
        for row_calls, _ in calls:
            for fn in row_calls:
                for _ in range(WARMUP_RUNS):
                    fn()
        # Round-robin: a slow spell of this shared machine then hits every object, not one.
        for r in range(args.repeats):
            for i, (row_calls, _) in enumerate(calls):
                for c, fn in enumerate(row_calls):
                    timings[r, i, c] = time_runs(fn, args.runs)
    median = np.median(timings, axis=0)  # (row, call, wall|CPU, p50|p95)
    start = 0
    for planner, dataset, rows in tables:
        end = start + len(rows)
        print_table(planner, dataset, rows, median[start:end], calls[start:end])
        start = end
    return 0


if __name__ == "__main__":
    sys.exit(main())
