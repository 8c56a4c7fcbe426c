"""Check that two sweeps gave the same trials: ``python -m graspexp bench.compare_runs BEFORE AFTER
[--planner OLD=NEW]``.

Every ``results.csv`` (single-object trials) and every clutter job's ``rounds.csv`` and ``attempts.csv``
under BEFORE is matched with the file at the same relative path under AFTER (with ``--planner OLD=NEW``: a
preset renamed between the runs, ``planner=OLD`` in the path and ``OLD`` in the ``planner`` column stand for
``NEW``), and every row (keyed by object and trial, by round, by round and attempt) is compared cell by cell
as text, so a float that changed in its last digit counts. Timing columns (:data:`IGNORED_PREFIXES`: wall
and CPU times) are ignored, and so is a column only one side has (a result field added between the runs;
named in the output). Exit status 0 when every row is identical, 1 otherwise (the differing cells are
printed).
"""

import csv
import sys
from pathlib import Path

from graspexp.tools.cli import tool_parser

IGNORED_PREFIXES = ("timings_s", "registration_cpu_s", "wall_s", "cpu_s", "plan_s", "plan_cpu_s", "execute_s")
"""Columns that measure time (wall, or CPU): they differ between runs of the same config."""
TABLES = {"results.csv": ("object", "trial"), "rounds.csv": ("round",), "attempts.csv": ("round", "attempt")}
"""The tables compared, each with the columns that key its rows."""


def _rows(path: Path) -> dict[tuple[str, ...], dict[str, str]]:
    """The rows of one table keyed by its key columns (:data:`TABLES`), timing columns dropped."""
    key = TABLES[path.name]
    with path.open(newline="") as f:
        return {
            tuple(row[k] for k in key): {k: v for k, v in row.items() if not k.startswith(IGNORED_PREFIXES)}
            for row in csv.DictReader(f)
        }


def _tables(root: Path) -> list[Path]:
    return sorted(p for name in TABLES for p in root.rglob(name))


def compare(
    before: Path, after: Path, rename: tuple[str, str] | None = None, one_sided: set[str] | None = None
) -> list[str]:
    """Differences between the sweeps under ``before`` and ``after``, one line each; [] when identical.
    ``rename``: (old, new) planner name (module doc). A column only one side has (a result field added
    between the runs) is not compared; its name goes into ``one_sided`` when given."""
    problems = []
    tables = sorted(p.relative_to(before) for p in _tables(before))
    if not tables:
        return [f"no results.csv, rounds.csv or attempts.csv under {before}"]
    for rel in tables:
        rel_after = (
            Path(str(rel).replace(f"planner={rename[0]},", f"planner={rename[1]},")) if rename else rel
        )
        if not (after / rel_after).is_file():
            problems.append(f"{rel_after}: missing under {after}")
            continue
        a, b = _rows(before / rel), _rows(after / rel_after)
        if rename:
            for row in a.values():
                if row.get("planner") == rename[0]:
                    row["planner"] = rename[1]
        for key in sorted(a.keys() | b.keys()):
            if key not in a or key not in b:
                problems.append(f"{rel} {key}: only under {before if key in a else after}")
                continue
            if one_sided is not None:
                one_sided |= a[key].keys() ^ b[key].keys()
            for col in sorted(a[key].keys() & b[key].keys()):
                if a[key][col] != b[key][col]:
                    problems.append(f"{rel} {key} {col}: {a[key].get(col)!r} != {b[key].get(col)!r}")
    return problems


def main(argv: list[str] | None = None) -> int:
    parser = tool_parser("graspexp bench.compare_runs", __doc__.splitlines()[0])
    parser.add_argument("before", type=Path, help="sweep directory of the reference run")
    parser.add_argument("after", type=Path, help="sweep directory of the run to check")
    parser.add_argument(
        "--planner", metavar="OLD=NEW", default=None, help="a planner preset renamed between the two runs"
    )
    args = parser.parse_args(argv)
    rename = None
    if args.planner:
        old, sep, new = args.planner.partition("=")
        if not sep or not old or not new:
            parser.error(f"--planner {args.planner!r}: expected OLD=NEW, e.g. optimal=optimal_in_area")
        rename = (old, new)
    one_sided: set[str] = set()
    problems = compare(args.before, args.after, rename, one_sided)
    n_tables = len(_tables(args.before))
    n_rows = sum(len(_rows(p)) for p in _tables(args.before))
    for line in problems:
        print(line)
    if one_sided:
        print(f"not compared (a column of one side only): {', '.join(sorted(one_sided))}")
    print(
        f"{n_tables} tables, {n_rows} rows: {'identical' if not problems else f'{len(problems)} differences'}"
    )
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
