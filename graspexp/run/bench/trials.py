"""Trial benchmark, measured: per-phase time split, the overhead ratio of a trial to its physics steps with
and without MCAP logging, and trials/s with 1 and 2 processes (``python -m graspexp bench.trials`` parses
and prints)."""

import statistics
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np
from threadpoolctl import threadpool_limits

from graspexp.config.compose import compose_config
from graspexp.record import TrialRecorder
from graspexp.run.objects import load_sim_object, trial_context
from graspexp.sim.trial import plain_config, run_trial

PHASES = ("build", "settle", "plan", "quality", "execute", "log")
TARGET_LOGGED, TARGET_UNLOGGED = 1.3, 1.2
"""Targets of the overhead ratio with and without logging (issues 14 and 15)."""


class _TimedRecorder(TrialRecorder):
    """A trial recorder that adds up the time of its per-tick calls (message building and writing)."""

    def __init__(self, path: Path, metadata: dict[str, str]):
        super().__init__(path, metadata)
        self.spent = {"tf": 0.0, "contacts": 0.0, "ticks": 0}

    def transforms(self, t_s, frames) -> None:
        t0 = time.perf_counter()
        super().transforms(t_s, frames)
        self.spent["tf"] += time.perf_counter() - t0
        self.spent["ticks"] += 1

    def contacts(self, t_s, contacts) -> None:
        t0 = time.perf_counter()
        super().contacts(t_s, contacts)
        self.spent["contacts"] += time.perf_counter() - t0


class _Object:
    """One object's model, hulls and scene, built once."""

    def __init__(self, overrides: list[str], name: str):
        cfg = compose_config(overrides)
        self.plain = plain_config(cfg)
        self.name = name
        self.loaded = load_sim_object(cfg, name, self.plain)

    def trial(self, i: int, out: str | None) -> dict:
        """Trial ``i``, logged into folder ``out`` (None: unlogged); wall and CPU time with the timings."""
        t0, c0 = time.perf_counter(), time.thread_time()
        if out is None:
            res = run_trial(trial_context(self.plain, self.loaded, i))
        else:
            path = Path(out) / self.name / f"{i:03d}.mcap"
            with _TimedRecorder(path, {"object": self.name}) as rec:
                res = run_trial(trial_context(self.plain, self.loaded, i, rec))
            spent = rec.spent
        wall, cpu = time.perf_counter() - t0, time.thread_time() - c0
        ticks = {} if out is None else {f"tick_{k}": v for k, v in spent.items()}
        return {
            **ticks,
            "wall": wall,
            "cpu": cpu,
            "success": res.success,
            "sim_time_s": res.sim_time_s,
            "steps": res.steps,
            **res.timings_s,
        }


def _run_object(args: tuple[list[str], str, int, str]) -> int:
    """All logged trials of one object (a throughput job); the number of trials run."""
    overrides, name, trials, out = args
    threadpool_limits(limits=1)
    obj = _Object(overrides, name)
    for i in range(trials):
        obj.trial(i, out)
    return trials


def throughput(overrides: list[str], names: list[str], trials: int, workers: int) -> float:
    """Logged trials per second of ``names`` (``trials`` each) run by ``workers`` processes."""
    with tempfile.TemporaryDirectory() as out:
        jobs = [(overrides, n, trials, out) for n in names]
        t0 = time.perf_counter()
        if workers == 1:
            n = sum(_run_object(j) for j in jobs)
        else:
            with ProcessPoolExecutor(workers) as pool:
                n = sum(pool.map(_run_object, jobs))
        return n / (time.perf_counter() - t0)


def _median(rows: list[dict], key) -> float:
    return statistics.median(key(r) for r in rows)


def bench_mode(overrides: list[str], names: list[str], trials: int) -> dict[str, list[dict]]:
    """Logged and unlogged rows of every trial of every object, the two variants alternated per trial."""
    rows: dict[str, list[dict]] = {"logged": [], "unlogged": []}
    with tempfile.TemporaryDirectory() as out:
        for name in names:
            obj = _Object(overrides, name)
            obj.trial(0, out)  # warm caches (decomposition, imports, first-call costs)
            for i in range(trials):
                rows["logged"].append(obj.trial(i, out))
                rows["unlogged"].append(obj.trial(i, None))
    return rows


def report_mode(mode: str, rows: dict[str, list[dict]], log_rate_hz: float) -> None:
    """Print one mode's per-phase split, overhead ratios and per-tick logging cost."""
    logged, bare = rows["logged"], rows["unlogged"]
    print(f"\n[{mode}] per-phase wall time of logged trials, median over {len(logged)} trials (ms):")
    for ph in (*PHASES, "physics"):
        vals = [1e3 * r[ph] for r in logged]
        print(f"  {ph:<8} p50 {statistics.median(vals):8.2f}   p95 {np.percentile(vals, 95):8.2f}")
    print(
        f"  {'trial':<8} p50 {1e3 * _median(logged, lambda r: r['wall']):8.2f}"
        f"   (CPU time {1e3 * _median(logged, lambda r: r['cpu']):8.2f})"
    )
    ticks = [r for r in logged if r["tick_ticks"]]
    per_tick = {
        "pose reads, contact extraction, phases": _median(
            ticks, lambda r: 1e6 * (r["log"] - r["tick_tf"] - r["tick_contacts"]) / r["tick_ticks"]
        ),
        "/tf message": _median(ticks, lambda r: 1e6 * r["tick_tf"] / r["tick_ticks"]),
        "/contacts message": _median(ticks, lambda r: 1e6 * r["tick_contacts"] / r["tick_ticks"]),
    }
    for label, rs, target in (("logged", logged, TARGET_LOGGED), ("unlogged", bare, TARGET_UNLOGGED)):
        ratio = _median(rs, lambda r: r["wall"] / r["physics"])
        busy = _median(rs, lambda r: r["cpu"] / r["wall"])
        print(
            f"  overhead ratio {label:<8} (trial / physics steps): median {ratio:.3f}  (target <= {target};"
            f" CPU/wall {busy:.2f}: below ~0.9 the machine is busy and figures scatter)"
        )
    loop = _median(bare, lambda r: 1e6 * (r["settle"] + r["execute"] - r["physics"]) / max(1, r["steps"]))
    split = {ph: _median(bare, lambda r, ph=ph: r[ph] / r["physics"]) for ph in ("build", "plan", "quality")}
    split["settling and execution besides physics"] = _median(
        bare, lambda r: (r["settle"] + r["execute"] - r["physics"]) / r["physics"]
    )
    print(
        "  unlogged overhead as fractions of the physics time: "
        + ", ".join(f"{ph} {v:.3f}" for ph, v in split.items())
        + f" ({loop:.1f} us per step)"
    )
    print(
        f"  logging per {log_rate_hz:g} Hz tick, median us: total "
        f"{_median(ticks, lambda r: 1e6 * r['log'] / r['tick_ticks']):.1f} = "
        + " + ".join(f"{k} {v:.1f}" for k, v in per_tick.items())
    )
    print(f"  success: {sum(r['success'] for r in logged)}/{len(logged)}")
