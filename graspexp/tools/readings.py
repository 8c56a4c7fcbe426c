"""``python -m graspexp readings [--out OUT] [--only a,b] [--report-only] [key=value ...]``.

Runs every reading of the paper (:data:`READINGS`: the literal one, this project's default, and each
single change from the default), every other planner (:data:`PLANNERS`, for a ceiling) and
``optimal_plus`` with each added term off on its own (:data:`ABLATIONS`) through the
paper's four settings on Table 1 (YCB) and Table 2 (LINEMOD), each into its own sweep directory
``OUT/<name>/`` (default OUT: ``outputs/readings``; ``key=value`` overrides go to every sweep, e.g.
``trials=5`` or ``dataset=ycb``; default ``dataset=ycb,linemod trials=10``), then writes the readings table
(:mod:`graspexp.report.readings`) to ``OUT/readings.md`` / ``.csv`` and prints it. Every sweep is a
Hydra multirun with the joblib launcher, resumable: running the command again skips finished trials.
A reading is one directory and one config, so no table row mixes configs.
"""

import subprocess
import sys
import time
from pathlib import Path

from graspexp.report.readings import readings_report
from graspexp.run.suites import ALL, reading_sweep
from graspexp.tools.cli import tool_parser


def main(argv: list[str] | None = None) -> int:
    ap = tool_parser("graspexp readings", __doc__.splitlines()[0], overrides=True)
    ap.add_argument("--out", type=Path, default=Path("outputs/readings"), help="output folder")
    ap.add_argument("--only", default="", help=f"comma-separated names (default: all of {', '.join(ALL)})")
    ap.add_argument("--report-only", action="store_true", help="write the table from what OUT holds")
    args = ap.parse_intermixed_args(argv)
    names = [n for n in args.only.split(",") if n] or list(ALL)
    unknown = [n for n in names if n not in ALL]
    if unknown:
        print(
            f"graspexp readings: error: unknown {unknown}; expected some of {', '.join(ALL)}", file=sys.stderr
        )
        return 2
    failed = []
    if not args.report_only:
        for i, name in enumerate(names, 1):
            start = time.perf_counter()
            print(f"[{i}/{len(names)}] {name}: {ALL[name].what}", file=sys.stderr, flush=True)
            rc = subprocess.call(reading_sweep(ALL[name], args.out, args.overrides))
            print(
                f"[{i}/{len(names)}] {name}: {time.perf_counter() - start:.0f} s, exit {rc}", file=sys.stderr
            )
            if rc != 0:
                failed.append(name)
    dirs = {n: args.out / n for n in names if (args.out / n).is_dir()}
    if not dirs:
        print(f"graspexp readings: error: no reading directories below {args.out}", file=sys.stderr)
        return 2
    md = readings_report({n: (d, ALL[n].what) for n, d in dirs.items()}, args.out)
    print(md)
    if failed:
        print(f"graspexp readings: error: sweeps that exited non-zero: {', '.join(failed)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
