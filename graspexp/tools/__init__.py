"""Command-line tools, each a thin ``main(argv)`` over the library: ``python -m graspexp <tool> ...`` (or
``python -m graspexp.tools.<tool>``). ``python -m graspexp [key=value ...]`` itself runs a job."""

TOOLS: tuple[str, ...] = (
    "report",
    "compare",
    "replay",
    "plan",
    "figures",
    "readings",
    "benchmark",
    "download",
    "download_checkpoint",
    "prepare",
    "area",
    "config_reference",
    "tune",
    "results",
    "bench.trials",
    "bench.clutter",
    "bench.reproduce",
    "bench.plan_latency",
    "bench.collision_shapes",
    "bench.shortlist",
    "bench.compare_runs",
    "bench.plan_grasps",
    "bench.registration",
    "bench.learned",
)
"""Every tool: ``python -m graspexp NAME`` runs ``graspexp.tools.NAME.main``."""
