"""Trial benchmark: per-phase time split, the overhead ratio of a trial to its physics steps with and
without MCAP logging (side by side, collab and bin), and trials/s with 1 and 2 processes.

    python -m graspexp bench.trials [dataset=ycb] [mode=collab,bin] [trials=10] [objects=[a,b]] [--repeats 3]

``mode=`` takes several values, measured one after the other (default ``collab,bin``); ``trials=`` trials
per object (the job config's, 10); ``objects=[...]`` a subset (default every staged object).

The overhead ratio is (wall time of the whole trial: scene build, settling, planning, force-closure check,
execution, logging) / (time inside the physics steps of the same trial). Logged and unlogged runs of each
trial alternate, so both see the same machine load; each object's convex hulls and Foxglove scene are
built once, as the runner does. Figures are medians over trials (per-phase, ratios) and over repeats
(throughput); CPU time per thread is printed beside wall time.
"""

import statistics

from threadpoolctl import threadpool_limits

from graspexp.config.compose import compose_config
from graspexp.datasets import available_objects
from graspexp.run.bench.trials import bench_mode, report_mode, throughput
from graspexp.run.suites import PAPER_MODES
from graspexp.tools.cli import compose_checked, take_sweep, tool_parser


def main(argv: list[str] | None = None) -> None:
    ap = tool_parser("graspexp bench.trials", __doc__.splitlines()[0], overrides=True)
    ap.add_argument("--repeats", type=int, default=3, help="repeats of the throughput runs (0: skip them)")
    args = ap.parse_intermixed_args(argv)
    threadpool_limits(limits=1)
    modes, rest = take_sweep(args.overrides, "mode", PAPER_MODES)
    cfg = compose_checked([*rest, f"mode={modes[0]}"], ap.prog)
    names = list(cfg.objects) if cfg.objects else available_objects(cfg.dataset)
    trials = int(cfg.trials)
    print(
        f"trial benchmark: {cfg.dataset.name} rot={cfg.rot.name}, modes {modes}, {len(names)} objects x {trials}"
    )
    for mode in modes:
        overrides = [*rest, f"mode={mode}"]
        rows = bench_mode(overrides, names, trials)
        report_mode(mode, rows, float(compose_config(overrides).sim.log_rate_hz))
    if args.repeats > 0:
        overrides = [*rest, f"mode={modes[0]}"]
        tp = {
            w: statistics.median(throughput(overrides, names, trials, w) for _ in range(args.repeats))
            for w in (1, 2)
        }
        print(
            f"\nthroughput, {modes[0]}, logged (median of {args.repeats}): 1 process {tp[1]:.2f} trials/s, "
            f"2 processes {tp[2]:.2f} trials/s (x{tp[2] / tp[1]:.2f})"
        )


if __name__ == "__main__":
    main()
