"""A clutter run's tables read back (:func:`rounds_from_csv`): ``rounds.csv`` and ``attempts.csv``, the only record
of a ``record=false`` run's rounds, every value checked against :class:`graspexp.core.rounds.RoundResult` and
:class:`graspexp.core.rounds.AttemptResult`. A table that breaks a rule is refused whole, in one line
(:class:`RoundTableError`) naming the file, the row (the file's line; the header is row 1) and the column: no round
of it is counted, as a bad ``results.csv`` (:func:`graspexp.report.collect.csv_result`).

The rules:

- A file is UTF-8 text without NUL bytes, not empty (graspexp writes a lone line break for a table without rows),
  ends with a line break (a cut file ends inside its last row), parses as CSV, and each row has the header's
  number of fields; no column is named twice.
- Every field of the dataclass without a default is a column (attempts.csv also needs ``dataset``, ``mode``
  and ``planner``, which tie an attempt to its round); a field with a default may be absent and takes it;
  other columns are ignored, except the counts of rounds.csv (``n_placed``, ``n_removed``, ``n_attempts``),
  which must agree with what they count.
- Values by the field's type: booleans ``True``/``False`` only, integers within 64 bits, numbers (empty:
  NaN), lists of names separated by spaces; ``end`` a :class:`graspexp.core.rounds.RoundEnd` value,
  ``reason`` empty or a :class:`graspexp.core.outcome.FailureReason` value; ``round``, ``attempt`` and
  ``slot`` not negative.
- A round: ``placed`` and ``removed`` name distinct bodies ``object_<slot>`` of its drawn slots, ``removed``
  a subset of ``placed``.
- An attempt: its (dataset, mode, planner, round) is a row of rounds.csv; ``slot`` is one of the round's drawn
  slots and ``target`` the object drawn there; successful only when executed; ``reason`` empty exactly when
  successful. A round's attempts are numbered 0, 1, ... without a gap, and its successful ones removed
  exactly its ``removed`` bodies.
- Keys: a round (dataset, mode, planner, round) is one row of rounds.csv, an attempt (..., attempt) one row of
  attempts.csv. A repeated key is refused, even an identical copy of its row: graspexp writes each table
  whole, so a repeated row comes from an edit or a bad merge, and a copy counted twice would change GSR and DR;
  the message names both rows, to delete one.
- attempts.csv may be missing only when no round has an attempt (``n_attempts`` 0 and nothing removed).
"""

import csv
import io
import typing
from dataclasses import MISSING, fields
from pathlib import Path

from graspexp.core.bodies import clutter_body
from graspexp.core.outcome import FailureReason
from graspexp.core.rounds import AttemptResult, RoundEnd, RoundResult
from graspexp.core.run_layout import ATTEMPTS_CSV, ROUNDS_CSV
from graspexp.core.userinput import shown
from graspexp.report.collect import csv_value

ROUND_LIST_FIELDS = ("drawn", "placed", "removed")
"""Fields of :class:`RoundResult` written as names separated by spaces."""
ATTEMPT_LIST_FIELDS = ("touched_neighbours", "moved_neighbours")
"""Fields of :class:`AttemptResult` written as names separated by spaces."""
ROUND_KEY = ("dataset", "mode", "planner", "round")
"""What names one round of a table; an attempt is named by it and ``attempt``."""
MAX_TABLE_BYTES = 2**30
"""A larger file is not read (a clutter run's tables are a few hundred bytes per attempt)."""
ROUND_COUNTS = ("n_placed", "n_removed", "n_attempts")
"""Columns of rounds.csv (:func:`graspexp.report.round_tables.rounds_frame`) that count the placed and removed
bodies and the executed attempts; not fields of :class:`RoundResult`, checked against what they count."""


class RoundTableError(ValueError):
    """A clutter run's table that cannot be read back; the message is one line naming the file, the row and the
    column (:attr:`path`: the file)."""

    def __init__(self, path: Path, message: str) -> None:
        super().__init__(message)
        self.path = path


Row = tuple[int, dict[str, str]]
"""One row of a table: its line in the file and its text by column."""


def read_table(path: Path) -> tuple[list[str], list[Row]]:
    """The header and rows of a CSV table graspexp wrote, by the file rules of the module doc (no header and no
    row for a lone line break); RoundTableError otherwise."""
    try:
        if path.stat().st_size > MAX_TABLE_BYTES:
            raise RoundTableError(
                path, f"{path}: {path.stat().st_size} bytes, more than a table's {MAX_TABLE_BYTES}"
            )
        data = path.read_bytes()
    except OSError as exc:
        raise RoundTableError(path, f"{path}: cannot be read ({exc.strerror or exc})") from None
    if not data:
        raise RoundTableError(path, f"{path}: empty file (graspexp writes a line break even for no rows)")
    try:
        text = data.decode("utf-8")
        bad = data.find(b"\0")
    except UnicodeDecodeError as exc:
        bad = exc.start
    if bad >= 0:
        raise RoundTableError(path, f"{path}: not a text table (a binary file? byte {bad} is not text)")
    if not text.strip("\r\n"):
        return [], []
    if not text.endswith("\n"):
        raise RoundTableError(
            path,
            f"{path} row {text.count(chr(10)) + 1}: the file ends inside this row (no line break after it): "
            "a cut file? (graspexp ends every row with one)",
        )
    reader = csv.reader(io.StringIO(text, newline=""), strict=True)
    rows: list[Row] = []
    header: list[str] | None = None
    start = 1
    try:
        for fields_ in reader:
            if fields_ and header is None:
                header, start = fields_, reader.line_num + 1
                continue
            if fields_:
                if len(fields_) != len(header):
                    raise RoundTableError(
                        path,
                        f"{path} row {start}: {len(fields_)} fields where the header has {len(header)} "
                        "(a cut or hand-broken row?)",
                    )
                rows.append((start, dict(zip(header, fields_, strict=True))))
            start = reader.line_num + 1
    except csv.Error as exc:
        raise RoundTableError(path, f"{path} row {start}: not CSV ({exc}; a cut file?)") from None
    twice = sorted({c for c in header if header.count(c) > 1})
    if twice:
        raise RoundTableError(path, f"{path} row 1: column {twice[0]!r} is named twice")
    return header, rows


def _kind(tp: object) -> str:
    base = next((a for a in typing.get_args(tp) if a is not type(None)), tp)
    words = {bool: "True or False", int: "an integer (64 bits)", float: "a number", str: "text"}
    return words.get(base, str(tp))


def _typed(path: Path, line: int, record: dict[str, str], cls: type, lists: tuple[str, ...]) -> dict:
    """The dataclass ``cls``'s fields of one row, each converted by its type (module doc)."""
    hints = typing.get_type_hints(cls)
    out: dict = {}
    for f in fields(cls):
        if f.name not in record:
            continue
        text = record[f.name]
        if f.name in lists:
            out[f.name] = text.split()
            continue
        try:
            out[f.name] = csv_value(text, hints[f.name])
        except ValueError:
            raise RoundTableError(
                path, f"{path} row {line}: {f.name}={shown(text)} is not {_kind(hints[f.name])}"
            ) from None
    for name in ("round", "attempt", "slot"):
        if name in out and out[name] < 0:
            raise RoundTableError(path, f"{path} row {line}: {name}={out[name]} is negative")
    return out


def _check_header(path: Path, header: list[str], cls: type, also: tuple[str, ...] = ()) -> None:
    required = [f.name for f in fields(cls) if f.default is MISSING and f.default_factory is MISSING]
    missing = [c for c in [*also, *required] if c != "attempts" and c not in header]
    if missing:
        raise RoundTableError(path, f"{path} row 1: no column {missing[0]!r} (a {cls.__name__} field)")


def _count(path: Path, line: int, record: dict[str, str], key: str) -> int | None:
    """Column ``key`` of :data:`ROUND_COUNTS` as an integer; None where the table has no such column."""
    if key not in record:
        return None
    try:
        return int(csv_value(record[key], int))
    except ValueError:
        raise RoundTableError(
            path, f"{path} row {line}: {key}={shown(record[key])} is not {_kind(int)}"
        ) from None


def _bodies(path: Path, line: int, key: str, names: list[str], drawn: list[str]) -> None:
    slots = [clutter_body(i) for i in range(len(drawn))]
    bad = next((n for n in names if n not in slots), None)
    if bad is not None:
        raise RoundTableError(
            path,
            f"{path} row {line}: {key}={shown(' '.join(names))} names {shown(bad)}, not a body of the round's "
            f"{len(drawn)} drawn objects ({', '.join(slots) or 'none'})",
        )
    twice = next((n for n in names if names.count(n) > 1), None)
    if twice is not None:
        raise RoundTableError(path, f"{path} row {line}: {key}={shown(' '.join(names))} names {twice} twice")


def _round(path: Path, line: int, record: dict[str, str]) -> RoundResult:
    d = _typed(path, line, record, RoundResult, ROUND_LIST_FIELDS)
    ends = [e.value for e in RoundEnd]
    if d["end"] not in ends:
        raise RoundTableError(
            path, f"{path} row {line}: end={shown(d['end'])} is not one of {', '.join(ends)}"
        )
    _bodies(path, line, "placed", d["placed"], d["drawn"])
    _bodies(path, line, "removed", d["removed"], d["drawn"])
    extra = [n for n in d["removed"] if n not in d["placed"]]
    if extra:
        raise RoundTableError(
            path,
            f"{path} row {line}: removed={shown(' '.join(d['removed']))} is not a subset of "
            f"placed={shown(' '.join(d['placed']))} ({extra[0]} was never placed)",
        )
    for key, n in (("n_placed", len(d["placed"])), ("n_removed", len(d["removed"]))):
        if _count(path, line, record, key) not in (None, n):
            raise RoundTableError(
                path, f"{path} row {line}: {key}={shown(record[key])} where {key[2:]} names {n} bodies"
            )
    return RoundResult(**d)


def _attempt(path: Path, line: int, record: dict[str, str], owner: RoundResult) -> AttemptResult:
    d = _typed(path, line, record, AttemptResult, ATTEMPT_LIST_FIELDS)
    where = f"{path} row {line}"
    if d["slot"] >= len(owner.drawn):
        raise RoundTableError(
            path,
            f"{where}: slot={d['slot']} is not a slot of round {owner.round}'s {len(owner.drawn)} drawn objects",
        )
    if d["target"] != owner.drawn[d["slot"]]:
        raise RoundTableError(
            path,
            f"{where}: target={shown(d['target'])} is not the object drawn in slot {d['slot']} of round "
            f"{owner.round} ({shown(owner.drawn[d['slot']])})",
        )
    if d["success"] and not d["executed"]:
        raise RoundTableError(
            path, f"{where}: success=True on an attempt with executed=False (none was made)"
        )
    reasons = [r.value for r in FailureReason]
    if d["reason"] is not None and d["reason"] not in reasons:
        raise RoundTableError(
            path,
            f"{where}: reason={shown(d['reason'])} is not a failure reason (one of {', '.join(reasons)})",
        )
    if d["success"] == (d["reason"] is not None):
        what = "a successful attempt has none" if d["success"] else "a failed attempt has one"
        raise RoundTableError(path, f"{where}: reason={shown(record['reason'])} where {what}")
    return AttemptResult(**d)


def _unique(path: Path, rows: list[tuple[int, dict[str, str], tuple]], what: str) -> None:
    """Refuse a repeated key (module doc), naming both rows; ``rows``: (line, record, key)."""
    first: dict[tuple, tuple[int, dict[str, str]]] = {}
    for line, record, key in rows:
        if key in first:
            seen_line, seen = first[key]
            copy = "an identical copy of" if seen == record else "the same key as"
            raise RoundTableError(
                path,
                f"{path} row {line}: {what} {'/'.join(map(str, key))} again, {copy} row {seen_line} (a table "
                "holds each once: delete one)",
            )
        first[key] = (line, record)


def rounds_from_csv(run_dir: Path | str) -> list[RoundResult]:
    """The rounds of ``run_dir``'s ``rounds.csv`` with their attempts from ``attempts.csv``, in the table's
    order, every value checked (module doc); :class:`RoundTableError` in one line for a table that breaks a
    rule."""
    run_dir = Path(run_dir)
    rpath, apath = run_dir / ROUNDS_CSV, run_dir / ATTEMPTS_CSV
    header, rows = read_table(rpath)
    if rows:
        _check_header(rpath, header, RoundResult)
    parsed = [(line, record, _round(rpath, line, record)) for line, record in rows]
    _unique(rpath, [(line, rec, _round_key(r)) for line, rec, r in parsed], "round")
    rounds = {_round_key(r): (line, record, r) for line, record, r in parsed}
    has_attempts = apath.is_file()
    a_header, a_rows = read_table(apath) if has_attempts else ([], [])
    if a_rows:
        _check_header(apath, a_header, AttemptResult, also=ROUND_KEY[:3])
    keyed = []
    for line, record in a_rows:
        d = _typed(apath, line, {k: record[k] for k in ("round", "attempt")}, AttemptResult, ())
        keyed.append((line, record, (*(record[k] for k in ROUND_KEY[:3]), d["round"], d["attempt"])))
    _unique(apath, keyed, "attempt")
    mine: dict[tuple, list[tuple[int, AttemptResult]]] = {k: [] for k in rounds}
    for line, record, key in keyed:
        if key[:4] not in rounds:
            raise RoundTableError(
                apath,
                f"{apath} row {line}: round={key[3]} of {'/'.join(key[:3])} is not a round of {rpath}",
            )
        owner = rounds[key[:4]][2]
        mine[key[:4]].append((line, _attempt(apath, line, record, owner)))
    out = []
    for key, (line, record, r) in rounds.items():
        r.attempts = _numbered(apath, r, mine[key])
        _agree(rpath, line, record, r, apath if has_attempts else None)
        out.append(r)
    return out


def _round_key(r: RoundResult) -> tuple:
    return r.dataset, r.mode, r.planner, r.round


def _numbered(path: Path, r: RoundResult, rows: list[tuple[int, AttemptResult]]) -> list[AttemptResult]:
    """The round's attempts by number, refused when a number is missing (a deleted row)."""
    rows = sorted(rows, key=lambda la: la[1].attempt)
    for k, (line, a) in enumerate(rows):
        if a.attempt != k:
            raise RoundTableError(
                path,
                f"{path} row {line}: attempt={a.attempt} of round {r.round} follows no attempt {k} (a round's "
                "attempts are numbered 0, 1, ... without a gap: a row deleted?)",
            )
    return [a for _, a in rows]


def _agree(path: Path, line: int, record: dict[str, str], r: RoundResult, attempts: Path | None) -> None:
    """The round's count of executed attempts and its removed bodies agree with its attempts (module doc)."""
    where = f"{path} row {line}"
    executed = sum(a.executed for a in r.attempts)
    if _count(path, line, record, "n_attempts") not in (None, executed):
        why = (
            f"{attempts} holds {executed} executed attempts of round {r.round}"
            if attempts is not None
            else f"there is no {ATTEMPTS_CSV} beside it (its attempts are missing)"
        )
        raise RoundTableError(path, f"{where}: n_attempts={shown(record['n_attempts'])} but {why}")
    removed = sorted(clutter_body(a.slot) for a in r.attempts if a.success)
    if removed != sorted(r.removed):
        why = (
            f"the successful attempts of round {r.round} in {attempts} removed {shown(' '.join(removed))}"
            if attempts is not None
            else f"there is no {ATTEMPTS_CSV} beside it (its attempts are missing)"
        )
        raise RoundTableError(path, f"{where}: removed={shown(' '.join(r.removed))} but {why}")
