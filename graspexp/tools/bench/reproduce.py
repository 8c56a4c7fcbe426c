"""Reproduction benchmark: the paper reproduction with the paper's planner, logged, with 1 and 2 workers.

    python -m graspexp bench.reproduce [--workers 1,2] [trials=1] [dataset=ycb objects=[a,b]] [key=value ...]

The sweep is ``nox -s reproduce``'s with ``planner=optimal`` only: Tables 1 and 2 (``dataset=ycb,linemod``) x
``mode=collab,bin`` x ``rot=z,xyz`` x 9 objects x 10 trials = 720 trials, ``record=true``, run by Hydra's
joblib launcher (``hydra.launcher.n_jobs`` = the workers) into a temporary directory, once per worker count.
Overrides replace the suite's values of the same key (``trials=1`` or ``dataset=ycb objects=[...]`` for a
quick subset) and go to every job. The collision-shape cache is filled first, so the timings are the
trials' (warm cache). Printed per worker count: wall time, CPU time of the sweep's processes (user +
system, workers included) and trials/s.
"""

import csv
import resource
import subprocess
import tempfile
import time
from pathlib import Path

from omegaconf import OmegaConf

from graspexp.datasets import select_objects
from graspexp.run.multirun import multirun_command
from graspexp.run.prepare import prepare_shapes
from graspexp.run.suites import paper_suite
from graspexp.tools.cli import compose_checked, take_sweep, tool_parser

PLANNER = "optimal"
"""The paper's planner as this project reads it."""


def sweep_overrides(overrides: list[str]) -> list[str]:
    """The suite's multirun overrides with ``planner=optimal``, those of a key in ``overrides`` replaced by
    them, and ``record=true progress=false``."""
    given = {o.split("=")[0] for o in overrides}
    suite = [o for o in paper_suite(planners=(PLANNER,)) if o.split("=")[0] not in given]
    return [*suite, *overrides, "record=true", "progress=false"]


def warm_cache(sweep: list[str]) -> None:
    """Build the collision shapes every dataset of ``sweep`` needs (a no-op when they are cached)."""
    from hydra.core.override_parser.overrides_parser import OverridesParser

    datasets, rest = take_sweep(sweep, "dataset", [])
    parser = OverridesParser.create()
    fixed = [o for o in rest if not parser.parse_overrides([o])[0].is_sweep_override()]
    for dataset in datasets:
        cfg = compose_checked([*fixed, f"dataset={dataset}"], "graspexp bench.reproduce")
        names = select_objects(cfg.dataset, cfg.objects)
        prepare_shapes(cfg.dataset, OmegaConf.to_object(cfg.sim), names, progress=False)


def count_trials(sweep_dir: Path) -> int:
    """Rows of every ``results.csv`` under ``sweep_dir`` (one per trial)."""
    total = 0
    for path in sweep_dir.rglob("results.csv"):
        with path.open(newline="") as f:
            total += sum(1 for _ in csv.DictReader(f))
    return total


def run_sweep(sweep: list[str], workers: int) -> dict[str, float]:
    """Run ``sweep`` with ``workers`` joblib workers into a temporary directory; wall s, CPU s (the sweep's
    processes, children included), trials. Raises RuntimeError (with the output's tail) if it fails."""
    with tempfile.TemporaryDirectory(prefix="graspexp-reproduce-") as out:
        cmd = multirun_command(f"{out}/sweep", [*sweep, f"hydra.launcher.n_jobs={workers}"])
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        proc = subprocess.run(cmd, capture_output=True, text=True)
        wall = time.perf_counter() - t0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        if proc.returncode != 0:
            raise RuntimeError(f"sweep failed ({' '.join(cmd)}):\n{(proc.stdout + proc.stderr)[-3000:]}")
        cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
        return {"wall": wall, "cpu": cpu, "trials": count_trials(Path(out) / "sweep")}


def main(argv: list[str] | None = None) -> None:
    ap = tool_parser("graspexp bench.reproduce", __doc__.splitlines()[0], overrides=True)
    ap.add_argument("--workers", default="1,2", help="worker counts, comma-separated (default 1,2)")
    args = ap.parse_intermixed_args(argv)
    workers = [int(w) for w in args.workers.split(",")]
    sweep = sweep_overrides(args.overrides)
    t0 = time.perf_counter()
    warm_cache(sweep)
    print(f"reproduction benchmark: {' '.join(sweep)}")
    print(f"  collision-shape cache warm ({time.perf_counter() - t0:.1f} s)")
    rate = {}
    for n in workers:
        r = run_sweep(sweep, n)
        rate[n] = r["trials"] / r["wall"]
        speedup = f" (x{rate[n] / rate[workers[0]]:.2f})" if n != workers[0] else ""
        print(
            f"  {n} worker{'s' if n > 1 else ' '}: {r['trials']} trials, wall {r['wall']:.1f} s,"
            f" CPU {r['cpu']:.1f} s, {rate[n]:.2f} trials/s{speedup}"
        )


if __name__ == "__main__":
    main()
