"""``python -m graspexp benchmark [--option ...] planner=NAME [dataset=...] [key=value ...]``: the standard
suite for any installed planner, ranked beside the built-in planners and the paper's published numbers.

The standard suite: the paper's four settings (collab / bin x rotation z / xyz) on Table 1 (``ycb``) and
Table 2 (``linemod``), :data:`graspexp.report.paper.TRIALS_PER_SETTING` trials per object, at zero pose
noise and at each of :data:`graspexp.run.suites.NOISE_LEVELS`. Every planner runs the same drops (a drop depends only on the
seed, dataset, object and trial index).

``key=value`` arguments are job overrides, as for every tool: ``planner=NAME`` (required) is the planner
entered; ``dataset=`` one dataset or several (``dataset=ycb,linemod``, the default); ``trials=``;
``objects=[...]`` a subset; ``planner.*`` keys go to the entered planner only, the rest (``gripper=``,
``sim.*``, ...) to every planner. Options:

- ``mode=collab,bin`` / ``rot=z,xyz``: the settings, every combination of the values given (default the
  paper's four); ``mode=pile,packed``: clutter removal, ``trials=`` rounds per scene, the planners ranked
  by DR then GSR on the same heaps (``clutter_ranking.csv``; the drop rotation is not read there);
- ``--noise 10:0,0:10``: pose-noise levels ``trans_mm:rot_deg`` besides zero (``--noise ''``: none);
- ``--compare obb,random``: planners ranked beside it (default the built-in ones; they run too where
  their results are missing, once, and are reused by every later entrant);
- ``--out DIR`` (default ``outputs/benchmark``); ``--n-jobs N`` (default 2): jobs in parallel with Hydra's
  joblib launcher;
- ``--launcher submitit``: Hydra's submitit launcher, one SLURM array task per job (``--slurm-partition``,
  ``--timeout-min``; without a partition, local processes).

Jobs launch as every graspexp sweep does: one Hydra multirun per planner (``python -m graspexp -m ...``),
so a job that cannot run is named in that sweep's failure summary and the others run.

Output, one folder per planner, ``OUT/<planner>/``: ``runs/<dataset>/<mode>_<rot>_t<mm>_r<deg>/`` (the
runner's job directories: resumable, locked, one MCAP log per trial), ``summary.md`` (ranking and tables),
``ranking.csv``, ``trials.csv`` (per trial: outcome and in-area contact fraction), ``noise.csv``,
``failures.csv`` and ``reproduce.json`` (command, every job's composed
config, package versions, planner package and version). Re-running the same command resumes.
"""

import argparse
import sys
from pathlib import Path

import yaml
from omegaconf import OmegaConf

from graspexp.config import ConfigError, PluginError
from graspexp.config.plugins import get_plugin
from graspexp.run.benchmark import Benchmark, jobs, run_all, write_summary
from graspexp.run.job_config import clutter_modes
from graspexp.run.suites import PAPER_MODES, PAPER_ROTS
from graspexp.tools.cli import compose_checked, fail, positive_int, tool_parser

PROG = "graspexp benchmark"
SUITE_KEYS = ("planner", "dataset", "mode", "rot", "trials", "objects")
"""Job keys whose values choose the suite (the other overrides are passed on to every job)."""


def _names(text: str) -> list[str]:
    """``a,b`` or ``[a,b]`` -> ``["a", "b"]``."""
    return [t.strip() for t in text.strip().strip("[]").split(",") if t.strip()]


def _noise_levels(text: str) -> list[list[float]]:
    """``10:0,0:10`` -> ``[[10.0, 0.0], [0.0, 10.0]]``; ``''`` -> ``[]``."""
    try:
        return [[float(v) for v in level.split(":")] for level in _names(text)]
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"{text!r}: expected trans_mm:rot_deg levels, e.g. 10:0,0:10"
        ) from None


def arg_parser() -> argparse.ArgumentParser:
    """The benchmark's command line (module doc)."""
    parser = tool_parser(PROG, __doc__, overrides=True)
    parser.add_argument("--noise", type=_noise_levels, help="trans_mm:rot_deg levels besides zero")
    parser.add_argument(
        "--compare", type=_names, help="planners ranked beside it (default: the built-in ones)"
    )
    parser.add_argument("--out", default=Benchmark.out, help=f"output folder (default {Benchmark.out})")
    parser.add_argument(
        "--n-jobs", type=positive_int, default=Benchmark.n_jobs, help="jobs in parallel (joblib)"
    )
    parser.add_argument("--launcher", choices=("joblib", "submitit"), default=Benchmark.launcher)
    parser.add_argument("--slurm-partition", default=Benchmark.slurm_partition, help="with submitit")
    parser.add_argument("--timeout-min", type=int, default=Benchmark.timeout_min, help="with submitit")
    return parser


def parse_args(argv: list[str]) -> Benchmark:
    """The command line (module doc) -> :class:`Benchmark`."""
    args = arg_parser().parse_intermixed_args(argv)
    values: dict = {"overrides": []}
    for tok in args.overrides:
        key, sep, raw = tok.partition("=")
        if key not in SUITE_KEYS or not sep:
            values["overrides"].append(tok)
        elif key == "dataset":
            values["datasets"] = _names(raw)
        elif key in ("mode", "rot"):
            values[key] = _names(raw)
        else:
            values[key] = yaml.safe_load(raw) if key != "planner" else raw
    if "planner" not in values:
        raise ConfigError("planner is missing: python -m graspexp benchmark planner=NAME [dataset=...]")
    modes, rots = values.pop("mode", None), values.pop("rot", None)
    clutter = [m for m in modes or [] if m in clutter_modes()]
    if clutter and len(clutter) < len(modes):
        raise ConfigError(
            f"mode={','.join(modes)}: the clutter modes ({', '.join(clutter_modes())}) rank on rounds (DR, GSR), "
            "the others on trials; benchmark them in two commands"
        )
    if clutter:  # the drop rotation is not read by the clutter modes: one job per scene
        values["settings"] = [f"{m}/{PAPER_ROTS[0]}" for m in clutter]
    elif modes or rots:  # every combination of the given modes and rotations, in the paper's order
        values["settings"] = [f"{m}/{r}" for m in (modes or PAPER_MODES) for r in (rots or PAPER_ROTS)]
    options = ("noise", "compare", "out", "n_jobs", "launcher", "slurm_partition", "timeout_min")
    return Benchmark(**values, **{k: getattr(args, k) for k in options if getattr(args, k) is not None})


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    try:
        bench = parse_args(argv)
        get_plugin(bench.planner)
    except (ConfigError, PluginError) as exc:
        fail(str(exc), PROG)
    all_jobs = jobs(bench)
    # every job's config is checked before the first trial runs
    configs = [OmegaConf.to_container(compose_checked(j.overrides, PROG), resolve=True) for j in all_jobs]
    errors = run_all(bench, all_jobs)
    print(write_summary(bench, all_jobs, configs, errors, argv), end="")
    print(f"graspexp benchmark: results in {Path(bench.out) / bench.planner}", file=sys.stderr)
    for e in errors:
        print(f"graspexp benchmark: job failed: {e}", file=sys.stderr)
    return 1 if errors else 0


if __name__ == "__main__":
    sys.exit(main())
