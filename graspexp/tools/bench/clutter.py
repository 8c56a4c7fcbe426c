"""Clutter-removal benchmark: per-attempt wall and CPU time in a round beside a single-object bin trial of
the same objects (both logged), and the planning latency per scene of optimal and optimal_plus.

    python -m graspexp bench.clutter [dataset=ycb] [mode=pile,packed] [trials=3] [objects=[a,b]] [--repeats 3]
        [--bin-trials 3]

``trials=`` rounds per mode (default 3); the rounds use ``planner=`` (default optimal); the latency is
measured on the scenes of every attempt, each planned by both planners (every object of the scene, as
``mode.pick_order=lowest_cost`` does), median over ``--repeats``; the bin reference is ``--bin-trials``
logged trials of each object drawn.
"""

from threadpoolctl import threadpool_limits

from graspexp.run.bench.round_latency import run_bench
from graspexp.run.job_config import clutter_modes
from graspexp.tools.cli import compose_checked, positive_int, take_sweep, tool_parser


def main(argv: list[str] | None = None) -> None:
    ap = tool_parser("graspexp bench.clutter", __doc__.splitlines()[0], overrides=True)
    ap.add_argument("--repeats", type=positive_int, default=3, help="repeats of each scene's planning")
    ap.add_argument(
        "--bin-trials", type=positive_int, default=3, help="logged bin trials per object of the reference"
    )
    args = ap.parse_intermixed_args(argv)
    threadpool_limits(limits=1)
    modes, rest = take_sweep(args.overrides, "mode", clutter_modes())
    trials = [o for o in rest if o.startswith("trials=")]
    rest = [o for o in rest if not o.startswith("trials=")]
    cfg = compose_checked([*rest, f"mode={modes[0]}", *(trials or ["trials=3"])], ap.prog)
    print(
        f"clutter benchmark: {cfg.dataset.name}, planner {cfg.planner.name}, modes {modes}, {cfg.trials} rounds each"
    )
    run_bench(rest, list(modes), int(cfg.trials), args.repeats, args.bin_trials)


if __name__ == "__main__":
    main()
