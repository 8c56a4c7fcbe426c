"""``python -m graspexp compare DIR [--out OUT]``: compare planners on the trial logs below DIR.

Writes ``compare.md``, ``compare.csv`` and ``success_vs_noise.png`` to OUT (default ``DIR/compare``)
and prints the Markdown. Exit status 2 when DIR holds no readable trial log.
"""

import sys
from pathlib import Path

from graspexp.report.collect import MixedConfigError
from graspexp.report.compare import write_comparison
from graspexp.tools.cli import fail, tool_parser


def main(argv: list[str] | None = None) -> int:
    ap = tool_parser("graspexp compare", __doc__.splitlines()[0])
    ap.add_argument("dir", type=Path, help="run or multirun directory holding trials/<object>/<NNN>.mcap")
    ap.add_argument("--out", type=Path, default=None, help="output folder (default: DIR/compare)")
    args = ap.parse_args(argv)
    if not args.dir.is_dir():
        print(f"graspexp compare: error: {args.dir} is not a directory", file=sys.stderr)
        return 2
    try:
        md, table, _ = write_comparison(args.dir, args.out)
    except MixedConfigError as exc:
        fail(str(exc), "graspexp compare")
    except OSError as exc:
        fail(
            f"cannot write the comparison: {exc.strerror or exc}: {exc.filename}; choose --out",
            "graspexp compare",
        )
    print(md, end="")
    if table.empty:
        print(f"graspexp compare: error: no readable trial log below {args.dir}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
