"""``python -m graspexp report DIR [--out OUT]``: tables and figures from the trial logs below DIR.

DIR is a run directory or a multirun (sweep) directory; every ``trials/<object>/<NNN>.mcap`` below it
is read, and a clutter run's rounds from its round logs (``trials/<mode>/NNN.mcap``), or without any from its
``rounds.csv``/``attempts.csv`` (checked against their schema). The report goes to ``DIR/report/`` (or OUT)
and its Markdown is printed. Exit status: 0; 1 when some logs or tables could not be read (each in one line: the
first few on stderr, all in the report); 2 when there is nothing to report, the directory mixes
two configs in one table cell, or the report cannot be written.
"""

import sys
from pathlib import Path

from graspexp.report.build import build_report, write_report
from graspexp.report.collect import MixedConfigError
from graspexp.tools.cli import tool_parser

SHOWN_UNREADABLE = 5
"""Unreadable logs and tables named on stderr, each in its line (all of them are in report.md)."""


def _error(message: str) -> int:
    print(f"graspexp report: error: {message}", file=sys.stderr)
    return 2


def main(argv: list[str] | None = None) -> int:
    parser = tool_parser("graspexp report", __doc__.splitlines()[0])
    parser.add_argument("dir", type=Path, help="run or multirun directory holding trials/**/*.mcap")
    parser.add_argument("--out", type=Path, default=None, help="output folder (default: DIR/report)")
    parser.add_argument(
        "--gallery", type=int, default=2, metavar="N", help="failures drawn per setting and reason (0: none)"
    )
    args = parser.parse_args(argv)
    if not args.dir.is_dir():
        return _error(f"{args.dir} is not a directory")
    try:
        report = build_report(args.dir)
    except MixedConfigError as exc:
        return _error(str(exc))
    col = report.collected
    if col.results.empty and not col.unreadable and col.not_run.empty and not report.rounds:
        return _error(f"no trial logs (trials/*/*.mcap) or clutter tables (rounds.csv) below {args.dir}")
    out = args.out if args.out is not None else args.dir / "report"
    try:
        print(write_report(report, out, gallery_per_reason=args.gallery))
    except OSError as exc:
        return _error(
            f"cannot write the report to {out}: {exc.strerror or exc}; choose another folder with --out"
        )
    print(f"\nreport written to {out}", file=sys.stderr)
    if report.collected.results.empty and not report.collected.not_run.empty and not report.rounds:
        print(
            f"graspexp report: no trial below {args.dir} ran to an outcome (every one is listed as not run)",
            file=sys.stderr,
        )
        return 1
    if report.collected.unreadable:
        n = len(report.collected.unreadable)
        for _, why in report.collected.unreadable[:SHOWN_UNREADABLE]:
            print(f"graspexp report: {why}", file=sys.stderr)
        print(
            f"graspexp report: {n} log(s) or table(s) could not be read and are in no table; they are listed "
            f"in {out / 'report.md'}",
            file=sys.stderr,
        )
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
