"""``python -m graspexp report DIR [--out OUT]``: tables and figures from the trial logs below DIR.

DIR is a run directory or a multirun (sweep) directory; every ``trials/<object>/<NNN>.mcap`` below it
is read. The report goes to ``DIR/report/`` (or OUT) and its Markdown is printed.
"""

import sys
from pathlib import Path

from graspexp.report.build import build_report, write_report
from graspexp.tools.cli import tool_parser


def main(argv: list[str] | None = None) -> int:
    parser = tool_parser("graspexp report", __doc__.splitlines()[0])
    parser.add_argument("dir", type=Path, help="run or multirun directory holding trials/**/*.mcap")
    parser.add_argument("--out", type=Path, default=None, help="output folder (default: DIR/report)")
    parser.add_argument(
        "--gallery", type=int, default=2, metavar="N", help="failures drawn per setting and reason (0: none)"
    )
    args = parser.parse_args(argv)
    if not args.dir.is_dir():
        print(f"graspexp report: error: {args.dir} is not a directory", file=sys.stderr)
        return 2
    report = build_report(args.dir)
    if report.collected.results.empty and not report.collected.unreadable:
        print(f"graspexp report: error: no trial logs (trials/*/*.mcap) below {args.dir}", file=sys.stderr)
        return 2
    out = args.out if args.out is not None else args.dir / "report"
    print(write_report(report, out, gallery_per_reason=args.gallery))
    print(f"\nreport written to {out}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
