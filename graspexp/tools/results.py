"""``python -m graspexp results [--check | --stamp-cpu] [--pages a,b | --learned-planners] [--out OUT] [--root DIR] [--n-jobs N] [key=value ...]``:
regenerate every results page (``docs/results/*.md`` and the README's results table) from runs of the
current code, or with ``--check`` list the pages whose fingerprint the current code does not reproduce.
A fingerprint holds bit for bit on one CPU class (``x86_64-v3-amd``: AVX2, AMD; ``x86_64-v4-intel``:
AVX-512, Intel): ``--check`` compares this machine's class's and skips, with a line, a page stamped on other
classes only;
``--stamp-cpu`` adds this class's fingerprints to the pages made on another (run it where they are current).

Each page's sweeps run as Hydra multiruns (joblib launcher) into ``OUT/runs/`` (default
``outputs/results/<commit>``); running the command again continues an interrupted regeneration.
``key=value`` overrides go to every sweep, e.g. ``hydra/launcher=submitit_slurm
hydra.launcher.partition=P`` (SLURM) or ``hydra.launcher.n_jobs=4``. The pages are
:func:`graspexp.run.result_pages.pages`; ``--learned-planners`` selects those that run a learned planner
(``nox -s learned`` checks them). Exit status: 0; 1 when a sweep failed or (``--check``) a page is
not current; 2 on a bad option or, before any sweep runs, a page file that is missing, lacks its generated
block or cannot be written (a read-only root), or an ``--out`` that cannot be made.
"""

import shlex
import sys
from pathlib import Path

from graspexp.report.pages import PageError
from graspexp.run.result_pages import pages as result_pages
from graspexp.run.results import ResultsError, check, commit_of, learned_pages, regenerate, stamp_cpu
from graspexp.tools.cli import fail, positive_int, tool_parser

PROG = "graspexp results"


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    every = result_pages()
    ap = tool_parser(PROG, __doc__.splitlines()[1], overrides=True)
    ap.add_argument(
        "--check", action="store_true", help="re-run the fingerprints; list the pages not current"
    )
    ap.add_argument(
        "--stamp-cpu",
        action="store_true",
        help="add this machine's CPU class's fingerprints to the pages made on another class (run it where "
        "those pages are current)",
    )
    ap.add_argument(
        "--pages", default="", help=f"comma-separated (default all: {', '.join(p.name for p in every)})"
    )
    ap.add_argument(
        "--learned-planners",
        action="store_true",
        help="only the pages that run a learned planner (with --pages: those of them)",
    )
    ap.add_argument("--out", type=Path, default=None, help="run folder (default outputs/results/<commit>)")
    ap.add_argument(
        "--root", type=Path, default=Path("."), help="repository root holding README.md and docs/"
    )
    ap.add_argument("--n-jobs", type=positive_int, default=2, help="processes for the fingerprint jobs")
    args = ap.parse_intermixed_args(argv)
    names = [n for n in args.pages.split(",") if n]
    unknown = [n for n in names if n not in {p.name for p in every}]
    if unknown:
        fail(f"unknown page(s) {unknown}; the pages are {', '.join(p.name for p in every)}", PROG)
    pages = [p for p in every if not names or p.name in names]
    if args.learned_planners:
        pages = learned_pages(pages)
    out = args.out if args.out is not None else Path("outputs/results") / commit_of(args.root)[0]
    command = shlex.join(["python", "-m", "graspexp", "results", *argv])
    try:
        if args.check and args.stamp_cpu:
            fail("--check and --stamp-cpu are two runs: check where the pages were made, stamp here", PROG)
        if args.stamp_cpu:
            problems = stamp_cpu(pages, args.root, args.n_jobs)
        elif args.check:
            problems = check(pages, args.root, args.n_jobs)
        else:
            problems = regenerate(pages, args.root, out, args.overrides, command, args.n_jobs)
    except (ResultsError, PageError) as exc:
        fail(str(exc), PROG)
    for line in problems:
        print(f"{PROG}: {line}", file=sys.stderr)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
