"""``python -m graspexp config_reference [--out FILE]``: the configuration reference, from the schemas
(:func:`graspexp.config.reference.render`; the documentation site builds its page from the same function)."""

import sys
from pathlib import Path

from graspexp.config.reference import render
from graspexp.tools.cli import tool_parser


def main(argv: list[str] | None = None) -> int:
    ap = tool_parser("graspexp config_reference", __doc__.splitlines()[0])
    ap.add_argument("--out", type=Path, default=None, help="write the Markdown here (default: print it)")
    args = ap.parse_args(argv)
    text = render()
    if args.out is None:
        print(text, end="")
    else:
        args.out.write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
