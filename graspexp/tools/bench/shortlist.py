"""Shortlist study: every grasp ``optimal_plus`` shortlists, simulated one at a time on the same drop,
beside what the planner measured of it.

    python -m graspexp bench.shortlist [--out shortlist.csv] [--n-jobs 2] [trials=5] [mode=collab,bin]
        [rot=z,xyz] [dataset=ycb,linemod] [objects=[a,b]] [key=value ...]

For each dataset, setting, object and trial the planner runs once; each of its S shortlisted paths
(``details.shortlist``, graspexp/planning/optimal_plus.py) is then executed in a fresh trial on the
same drop by a planner that returns that grasp. One CSV row per simulated grasp: held or not, the failure
reason, the edge excess (how far the object reaches past a pad's contact plane by the finger edges, the
measure ``choose_by=edge_clearance`` minimises), the pad depth, whether it passed the noise check, and
which grasp each ``choose_by`` rule picks. Prints the share held per band of edge excess and how often each
rule's pick is held. ``key=value`` arguments are job overrides (``planner.*``, ``sim.*``, ...); ``dataset=``,
``mode=`` and ``rot=`` take several values (every combination runs; default the paper's), ``trials=`` is
the drops per object and setting (default 5), ``objects=[...]`` a subset (default every staged one).
"""

import sys
from pathlib import Path

from graspexp.config import ConfigError
from graspexp.run.bench.shortlist import study, summary
from graspexp.run.suites import PAPER_DATASETS, PAPER_MODES, PAPER_ROTS
from graspexp.tools.cli import fail, positive_int, take_sweep, tool_parser

PROG = "graspexp bench.shortlist"


def main(argv: list[str] | None = None) -> int:
    ap = tool_parser(PROG, __doc__, overrides=True)
    ap.add_argument(
        "--out", type=Path, default=Path("shortlist.csv"), help="CSV written (default shortlist.csv)"
    )
    ap.add_argument("--n-jobs", type=positive_int, default=2, help="processes (default 2)")
    args = ap.parse_intermixed_args(argv)
    if args.n_jobs < 1:
        fail(f"--n-jobs {args.n_jobs} is invalid: expected 1 or more processes", PROG)
    datasets, rest = take_sweep(args.overrides, "dataset", PAPER_DATASETS)
    modes, rest = take_sweep(rest, "mode", PAPER_MODES)
    rots, rest = take_sweep(rest, "rot", PAPER_ROTS)
    trials, rest = take_sweep(rest, "trials", ["5"])
    if len(trials) != 1 or not trials[0].isdigit() or int(trials[0]) < 1:
        fail(f"trials={','.join(trials)} is invalid: expected one positive integer", PROG)
    settings = [f"{m}/{r}" for m in modes for r in rots]
    try:
        df = study(rest, datasets, settings, int(trials[0]), args.n_jobs)
    except ConfigError as err:
        fail(str(err), PROG)
    if df.empty:
        fail("no grasp was planned: nothing to simulate", PROG)
    df.to_csv(args.out, index=False)
    print(summary(df))
    print(f"{PROG}: {len(df)} grasps in {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
