"""``python -m graspexp tune SWEEP_DIR [--split test] [--trials 10] [--trial N] [--out OUT] [--preset FILE] [key=value ...]``:
score an Optuna study's best parameters (or trial N's) beside the paper's on held-out objects.

SWEEP_DIR is the directory of ``python -m graspexp -m hydra/sweeper=study ...`` (its ``multirun.yaml``
names the study's storage). The study's fixed overrides are kept; its ``dataset.split`` is replaced by
``--split``, its ``trials`` by ``--trials``; ``key=value`` overrides come last (e.g. ``record=true``).
Writes ``tuning.md`` (the study, the held-out table with Wilson 95 % intervals, a paired test),
``tuning_trials.csv`` (every trial of the study) and the study's plots to OUT (default
``SWEEP_DIR/score``), and with ``--preset`` a cost preset YAML holding the scored ``cost.*`` values. Exit
status 2 with one line when SWEEP_DIR holds no study, no trial completed, or an override is bad.
"""

import sys
from pathlib import Path

from graspexp.config import ConfigError
from graspexp.report.study import read_sweep_study, study_table
from graspexp.tools.cli import fail, tool_parser

PROG = "graspexp tune"


def _preset_yaml(params: dict[str, object], source: str) -> str:
    lines = [
        f"# Eq. (1)-(3) constants from an Optuna study ({source});",
        "# scored beside the paper's in docs/results/tuning.md. The paper's constants stay the default (cost=paper).",
        "defaults:",
        "  - /schema_cost@_here_",
    ]
    lines += [f"{k.removeprefix('cost.')}: {v!r}" for k, v in params.items() if k.startswith("cost.")]
    return "\n".join(lines) + "\n"


def main(argv: list[str] | None = None) -> int:
    ap = tool_parser(PROG, __doc__.splitlines()[1], overrides=True)
    ap.add_argument("sweep_dir", type=Path, help="the study's sweep directory (hydra.sweep.dir)")
    ap.add_argument("--split", default="test", help="object split to score on (dataset.split; default test)")
    ap.add_argument("--trials", type=int, default=10, help="trials per object (default 10)")
    ap.add_argument("--out", type=Path, default=None, help="output folder (default: SWEEP_DIR/score)")
    ap.add_argument(
        "--trial", type=int, default=None, help="score this trial of the study (default: the best)"
    )
    ap.add_argument(
        "--preset", type=Path, default=None, help="write the scored cost.* values as a cost preset"
    )
    args = ap.parse_intermixed_args(argv)
    try:
        sweep = read_sweep_study(args.sweep_dir)
    except ValueError as exc:
        fail(str(exc), PROG)
    done = [t.number for t in sweep.study.get_trials(deepcopy=False) if t.state.name == "COMPLETE"]
    if not done:
        fail(f"no trial of the study in {args.sweep_dir} completed", PROG)
    if len(sweep.study.directions) > 1:
        fail(
            f"the study in {args.sweep_dir} has several objectives; tune scores single-objective studies",
            PROG,
        )
    if args.trial is not None and args.trial not in done:
        fail(f"--trial {args.trial} is not a complete trial of the study (complete: {done})", PROG)
    from graspexp.datasets import DatasetError
    from graspexp.report.study import plot_study
    from graspexp.report.tuning import tuning_markdown
    from graspexp.run.locks import RunError
    from graspexp.run.score import score_study

    try:
        scored = score_study(sweep, args.sweep_dir, args.split, args.trials, args.overrides, args.trial)
    except (ConfigError, DatasetError, RunError) as exc:  # a bad override, missing data, a locked directory
        fail(str(exc), PROG)
    out = args.out if args.out is not None else args.sweep_dir / "score"
    out.mkdir(parents=True, exist_ok=True)
    study_table(sweep.study).to_csv(out / "tuning_trials.csv", index=False)
    pngs = [p.name for p in plot_study(sweep.study, out)]
    command = " ".join(["python -m graspexp tune", *(argv if argv is not None else sys.argv[2:])])
    (out / "tuning.md").write_text(tuning_markdown(sweep, scored, command, pngs))
    if args.preset is not None:
        trial, first = scored[-1].trial, sweep.study.trials[0]
        source = (
            f"{args.sweep_dir}, trial {trial}: objective {sweep.study.trials[trial].value:.4f} on the training "
            f"objects, trial 0 (the {scored[0].label}'s values) {first.value:.4f}"
        )
        args.preset.write_text(_preset_yaml(scored[-1].params, source))
    print((out / "tuning.md").read_text(), end="")
    print(f"\n{PROG}: written to {out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
