"""Planner latency per paper Table 1/2 object, measured single-threaded (paper IV-F reports 0.1 s per plan;
``python -m graspexp bench.plan_latency`` parses and prints)."""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import time  # noqa: E402
from collections.abc import Callable  # noqa: E402

import numba  # noqa: E402
import numpy as np  # noqa: E402

from graspexp.datasets import DatasetError, available_objects, dataset_objects, job_object  # noqa: E402
from graspexp.planning import PlanRequest, kernels, plan  # noqa: E402
from graspexp.planning.clusters import segment  # noqa: E402
from graspexp.planning.cost import M_TO_MM  # noqa: E402
from graspexp.planning.optimal import kmeans_random_state, paper_candidates, path_costs  # noqa: E402
from graspexp.run.job_config import compose_job  # noqa: E402
from graspexp.run.upright import upright_request  # noqa: E402

PAPER_PLAN_S = 0.1
"""The paper's planner time (clusters + paths + cost), seconds (IV-F, i7-9700)."""
WARMUP_RUNS = 3
TARGETS_CPU_MS = {"optimal": (2.5, 5.0), "optimal_plus": (np.inf, 50.0)}
"""Per planner, the most CPU-time p50 and p95 of any object and mode, one thread, ms (issues 15 and 27)."""
SQRT_BLOCK = 2048 * 256
"""Elements per call of the sqrt-throughput probe: one cluster's (N x M) block at the defaults."""


def time_runs(fn: Callable[[], object], runs: int) -> np.ndarray:
    """(2, 2) ms: [[wall p50, wall p95], [CPU p50, CPU p95]] of ``runs`` calls of ``fn``, this thread."""
    wall, cpu = np.empty(runs), np.empty(runs)
    for i in range(runs):
        w0, c0 = time.perf_counter_ns(), time.thread_time_ns()
        fn()
        cpu[i], wall[i] = time.thread_time_ns() - c0, time.perf_counter_ns() - w0
    return np.percentile(np.stack([wall, cpu]), [50, 95], axis=1).T / 1e6


@numba.njit(fastmath=True, error_model="numpy", cache=True)
def _sqrt_sum(values: np.ndarray, passes: int) -> float:
    """Sum of float32 square roots, ``passes`` times over ``values``: the machine's sqrt throughput
    (vectorised as the Eq. (1) kernel is; numba's default error model would keep it scalar)."""
    total = np.float32(0.0)
    for _ in range(passes):
        for i in range(values.shape[0]):
            total += np.sqrt(values[i])
    return total


def sqrt_bound_ns(repeats: int) -> float:
    """CPU ns per float32 square root on this thread, at full throughput (median over ``repeats``)."""
    values = np.random.default_rng(0).uniform(1.0, 1e4, 2048).astype(np.float32)
    passes = SQRT_BLOCK // len(values)
    _sqrt_sum(values, 1)  # compile
    ms = np.median([time_runs(lambda: _sqrt_sum(values, passes), 10)[1, 0] for _ in range(repeats)])
    return float(ms * 1e6 / SQRT_BLOCK)


def timed_calls(req: PlanRequest) -> tuple[list[Callable[[], object]], int]:
    """The whole plan, its K-means, its Eq. (1)-(3) evaluation and the bare Eq. (1) kernel, as calls on
    ``req`` (paper planner), and the kernel's number of (path, point) elements."""
    cand = paper_candidates(req, "bench")
    area = cand.points[cand.area_mask]
    clusters = cand.clusters
    k, seed = len(clusters.centers_m), kmeans_random_state(req.seed, req.planner.seed)
    c = req.cost
    kernel_args = (
        np.ascontiguousarray(cand.points),
        np.ascontiguousarray(clusters.centers_m),
        M_TO_MM,
        clusters.radii_m * M_TO_MM,
        np.ascontiguousarray(cand.directions),
        np.ascontiguousarray(cand.feasible),
        c.distance_numerator_mm2,
        c.distance_offset_mm2,
        c.distance_cap,
    )
    calls = [
        lambda: plan(req),
        lambda: segment(area, k, random_state=seed),
        lambda: path_costs(req, cand.points, cand.axis, clusters, cand.directions, cand.feasible),
        lambda: kernels.distance_sums(*kernel_args),
    ]
    return calls, int(cand.feasible.sum()) * len(cand.points)


def first_plan_s(req: PlanRequest) -> tuple[float, str]:
    """Wall seconds of the first plan in this process and where its kernels came from."""
    start = time.perf_counter()
    plan(req)
    elapsed = time.perf_counter() - start
    dispatchers = [v for v in vars(kernels).values() if isinstance(v, numba.core.dispatcher.Dispatcher)]
    hits = sum(sum(d.stats.cache_hits.values()) for d in dispatchers)
    misses = sum(sum(d.stats.cache_misses.values()) for d in dispatchers)
    return elapsed, f"{hits} kernels loaded from the cache in {numba.config.CACHE_DIR}, {misses} compiled"


def staged_rows(overrides: list[str], modes: list[str]) -> tuple[list[tuple], str, list[str]]:
    """Every (object, mode) request of one planner and dataset (``overrides`` compose them, module doc):
    rows ``(name, mode, area size, request)``, the dataset's name (``primitives`` when its meshes are
    missing) and its note lines. Raises :class:`graspexp.config.ConfigError` for a bad override and
    :class:`DatasetError` for an object that cannot be loaded."""
    cfg = compose_job(overrides)
    dataset, notes = str(cfg.dataset.name), []
    names = list(cfg.objects) if cfg.objects else available_objects(cfg.dataset)
    if not cfg.objects and (missing := sorted(set(dataset_objects(cfg.dataset)) - set(names))):
        notes.append(
            f"note: {dataset}: {len(missing)} objects not staged under the data root: {', '.join(missing)}"
        )
    try:
        job_object(cfg, (names or dataset_objects(cfg.dataset))[0])  # none staged: the first one's error
    except DatasetError as err:
        notes.append(f"note: {dataset} meshes unavailable ({err}); falling back to the primitives dataset")
        cfg = compose_job([*overrides, "dataset=primitives"])
        dataset, names = "primitives", dataset_objects(cfg.dataset)
    configs = {mode: compose_job([*overrides, f"dataset={dataset}", f"mode={mode}"]) for mode in modes}
    rows = []
    for name in names:
        model = job_object(cfg, name)
        for (
            mode
        ) in modes:  # the mode's own support (height, whether it blocks the gripper), not only its name
            rows.append((name, mode, int(model.area_mask.sum()), upright_request(configs[mode], model)))
    return rows, dataset, notes


def print_table(planner: str, dataset: str, rows: list[tuple], median: np.ndarray, calls: list) -> None:
    """One planner's and dataset's table (module doc): ``median`` (row, call, wall|CPU, p50|p95) ms."""
    print(
        f"\n{planner}, {dataset}, N={rows[0][4].planner.n_points} M={rows[0][4].planner.m}:\n"
        f"{'':<42}{'wall ms':>16}{'CPU ms':>16}{'':>9}{'CPU p50 ms':>17}\n"
        f"{'object':<26}{'mode':<8}{'K':>3}{'area':>5}{'p50':>8}{'p95':>8}{'p50':>8}{'p95':>8}"
        f"{'vs paper':>9}{'K-means':>9}{'Eq.1-3':>8}{'ns/el':>7}"
    )
    for (name, mode, k, area, _), m, (_, elements) in zip(rows, median, calls, strict=True):
        print(
            f"{name:<26}{mode:<8}{k:>3}{area:>5}{m[0, 0, 0]:>8.2f}{m[0, 0, 1]:>8.2f}{m[0, 1, 0]:>8.2f}"
            f"{m[0, 1, 1]:>8.2f}{m[0, 1, 0] / (PAPER_PLAN_S * 1e3):>9.3f}{m[1, 1, 0]:>9.2f}{m[2, 1, 0]:>8.2f}"
            f"{m[3, 1, 0] * 1e6 / elements:>7.3f}"
        )
    wall, cpu50, cpu95 = np.median(median[:, 0, 0, 0]), median[:, 0, 1, 0], median[:, 0, 1, 1]
    p50_max, p95_max = TARGETS_CPU_MS.get(planner, (np.inf, np.inf))
    over = int(((cpu50 > p50_max) | (cpu95 > p95_max)).sum())
    target = " and ".join(f"{q} <= {v:g} ms" for q, v in (("p50", p50_max), ("p95", p95_max)) if v < np.inf)
    print(
        f"median p50 over objects and modes: CPU {np.median(cpu50):.2f} ms (worst p50 {cpu50.max():.2f} ms, "
        f"worst p95 {cpu95.max():.2f} ms) = {np.median(cpu50) / (PAPER_PLAN_S * 1e3):.3f} x the paper's 0.1 s, "
        f"wall {wall:.2f} ms; "
        + (f"{over} of {len(cpu50)} over the CPU target ({target})" if target else "no CPU target")
    )
