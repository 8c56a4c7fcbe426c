"""``report`` on a clutter run read as it is (issue 51, findings 7 and 8): the round logs of a run without
``rounds.csv`` (killed or timed out) give its rounds, and a ``record=false`` run's ``rounds.csv`` /
``attempts.csv`` are checked against their schema: a bad table is one line naming the file, the row and the
column (exit 1, as a bad results.csv), never a traceback and never a wrong table."""

import dataclasses
import re
import shutil
from pathlib import Path

import pytest

from graspexp.core.rounds import AttemptResult, RoundResult
from graspexp.report.round_csv import RoundTableError, rounds_from_csv
from graspexp.report.round_tables import attempts_frame, clutter_table, collect_rounds, rounds_frame
from graspexp.tools.report import main as report_main


def _attempt(r, i, slot, target, success, reason=None, executed=True):
    return AttemptResult(
        round=r, attempt=i, target=target, slot=slot, executed=executed, success=success, reason=reason,
        pick_order="lowest_cost", n_left=3, n_planned=3, plan_s=0.02, plan_cpu_s=0.01, grasp_cost=2.5,
        grasp_width_m=0.08, n_feasible=40, slip_m=1e-5, touched_neighbours=["object_2"] if i == 1 else [],
    )  # fmt: skip


def _rounds() -> list[RoundResult]:
    """Three rounds as the runner makes them: one ended by the planner (a failed attempt and the row that
    found no grasp), one cleared, one that raised."""
    stuck = RoundResult(
        "primitives", "pile", "optimal", 0, 11, ["can", "box", "box"], ["object_0", "object_1", "object_2"],
        ["object_1", "object_0"], "no_grasp",
        [_attempt(0, 0, 1, "box", True), _attempt(0, 1, 2, "box", False, "dropped"), _attempt(0, 2, 0, "can", True),
         _attempt(0, 3, 2, "box", False, "no_feasible_grasp", executed=False)],
        wall_s=0.3, cpu_s=0.25, sim_time_s=7.5,
    )  # fmt: skip
    cleared = RoundResult(
        "primitives", "pile", "optimal", 1, 12, ["box", "can", "can"], ["object_0", "object_2"],
        ["object_0", "object_2"], "cleared", [_attempt(1, 0, 0, "box", True), _attempt(1, 1, 2, "can", True)],
    )  # fmt: skip
    erred = RoundResult(
        "primitives",
        "pile",
        "optimal",
        2,
        13,
        ["can", "can", "box"],
        [],
        [],
        "error",
        error="RuntimeError: boom",
    )
    return [stuck, cleared, erred]


def _write_run(run: Path, rounds: list[RoundResult]) -> Path:
    """The tables of a ``record=false`` clutter run, written as the runner writes them."""
    run.mkdir(parents=True, exist_ok=True)
    (run / "rounds.csv").write_text(rounds_frame(rounds).to_csv(index=False))
    (run / "attempts.csv").write_text(attempts_frame(rounds).to_csv(index=False))
    return run


def _lines(path: Path) -> list[str]:
    return path.read_text().splitlines(keepends=True)


def _set(path: Path, row: int, column: str, value: str) -> None:
    """Put ``value`` in ``column`` of the file's ``row`` (the header is row 1)."""
    lines = _lines(path)
    header = lines[0].rstrip("\n").split(",")
    fields = lines[row - 1].rstrip("\n").split(",")
    fields[header.index(column)] = value
    lines[row - 1] = ",".join(fields) + "\n"
    path.write_text("".join(lines))


def _binary(path: Path) -> None:
    path.write_bytes(bytes(range(256)) * 4)


def _cut(path: Path) -> None:
    path.write_bytes(path.read_bytes()[:-25])


def _duplicate(path: Path, row: int) -> None:
    lines = _lines(path)
    path.write_text("".join([*lines, lines[row - 1]]))


def _drop(path: Path, row: int) -> None:
    lines = _lines(path)
    path.write_text("".join(lines[: row - 1] + lines[row:]))


R, A = "rounds.csv", "attempts.csv"
CASES = {
    # tracebacks before
    "binary rounds.csv": (lambda d: _binary(d / R), R, r"rounds\.csv: not a text table \(a binary file\?"),
    "binary attempts.csv": (lambda d: _binary(d / A), A, r"attempts\.csv: not a text table \(a binary file\?"),
    "empty rounds.csv": (lambda d: (d / R).write_bytes(b""), R, r"rounds\.csv: empty file"),
    "empty attempts.csv": (lambda d: (d / A).write_bytes(b""), A, r"attempts\.csv: empty file"),
    "success=maybe": (
        lambda d: _set(d / A, 3, "success", "maybe"), A, r"attempts\.csv row 3: success='maybe' is not True or False"
    ),
    "round=abc in rounds.csv": (
        lambda d: _set(d / R, 2, "round", "abc"), R, r"rounds\.csv row 2: round='abc' is not an integer"
    ),
    "round=abc in attempts.csv": (
        lambda d: _set(d / A, 4, "round", "abc"), A, r"attempts\.csv row 4: round='abc' is not an integer"
    ),
    "executed=yes": (
        lambda d: _set(d / A, 2, "executed", "yes"), A, r"attempts\.csv row 2: executed='yes' is not True or False"
    ),
    "removed longer than placed": (
        lambda d: _set(d / R, 3, "removed", "object_0 object_1 object_2"), R,
        r"rounds\.csv row 3: removed='object_0 object_1 object_2' is not a subset of placed='object_0 object_2'",
    ),
    # a wrong table with exit 0 before
    "cut rounds.csv": (lambda d: _cut(d / R), R, r"rounds\.csv row 4: the file ends inside this row"),
    "cut attempts.csv": (lambda d: _cut(d / A), A, r"attempts\.csv row 7: the file ends inside this row"),
    "attempts.csv cut after a row": (
        lambda d: _drop(d / A, 7), R, r"rounds\.csv row 3: n_attempts='2' but \S*attempts\.csv holds 1 executed"
    ),
    "unknown end": (
        lambda d: _set(d / R, 2, "end", "exploded"), R,
        r"rounds\.csv row 2: end='exploded' is not one of cleared, no_grasp, .*failure_limit",
    ),
    "missing attempts.csv": (
        lambda d: (d / A).unlink(), R,
        r"rounds\.csv row 2: n_attempts='3' but there is no attempts\.csv beside it \(its attempts are missing\)",
    ),
    "duplicated round": (
        lambda d: _duplicate(d / R, 3), R,
        r"rounds\.csv row 5: round primitives/pile/optimal/1 again, an identical copy of row 3",
    ),
    "duplicated attempt": (
        lambda d: _duplicate(d / A, 2), A,
        r"attempts\.csv row 8: attempt primitives/pile/optimal/0/0 again, an identical copy of row 2",
    ),
    # the rest of the schema
    "unknown reason": (
        lambda d: _set(d / A, 3, "reason", "exploded"), A, r"attempts\.csv row 3: reason='exploded' is not a failure"
    ),
    "success with a reason": (
        lambda d: _set(d / A, 2, "reason", "dropped"), A, r"attempts\.csv row 2: reason='dropped' where a successful"
    ),
    "success without execution": (
        lambda d: _set(d / A, 5, "success", "True"), A, r"attempts\.csv row 5: success=True on an attempt with exec"
    ),
    "attempt of no round": (
        lambda d: _set(d / A, 7, "round", "7"), A, r"attempts\.csv row 7: round=7 of primitives/pile/optimal is not"
    ),
    "attempt deleted": (lambda d: _drop(d / A, 3), A, r"attempts\.csv row 3: attempt=2 of round 0 follows no attempt 1"),
    "slot not drawn": (lambda d: _set(d / A, 2, "slot", "5"), A, r"attempts\.csv row 2: slot=5 is not a slot of round 0"),
    "target not drawn there": (
        lambda d: _set(d / A, 2, "target", "can"), A, r"attempts\.csv row 2: target='can' is not the object drawn in"
    ),
    "n_removed disagrees": (
        lambda d: _set(d / R, 3, "removed", "object_0"), R, r"rounds\.csv row 3: n_removed='2' where removed names 1"
    ),
    "removed by no attempt": (
        lambda d: (_set(d / R, 3, "removed", "object_0"), _set(d / R, 3, "n_removed", "1")), R,
        r"rounds\.csv row 3: removed='object_0' but the successful attempts of round 1 in \S*attempts\.csv "
        r"removed 'object_0 object_2'",
    ),
    "placed an undrawn body": (
        lambda d: _set(d / R, 2, "placed", "object_0 object_1 object_9"), R,
        r"rounds\.csv row 2: placed='object_0 object_1 object_9' names 'object_9', not a body of the round's 3",
    ),
    "negative round": (lambda d: _set(d / R, 2, "round", "-1"), R, r"rounds\.csv row 2: round=-1 is negative"),
    "seed too large": (
        lambda d: _set(d / R, 2, "seed", str(10**30)), R, r"rounds\.csv row 2: seed='10{30}' is not an integer"
    ),
    "number that is not": (
        lambda d: _set(d / A, 2, "plan_s", "fast"), A, r"attempts\.csv row 2: plan_s='fast' is not a number"
    ),
    "a column missing": (
        lambda d: (d / R).write_text("".join(line.split(",", 1)[1] for line in _lines(d / R))), R,
        r"rounds\.csv row 1: no column 'dataset'",
    ),
    "a row short of fields": (
        lambda d: _set(d / A, 2, "slot", "1\n"), A, r"attempts\.csv row 2: 7 fields where the header has \d+",
    ),
}  # fmt: skip


def test_the_tables_the_runner_writes_read_back_as_they_were(tmp_path):
    run = _write_run(tmp_path / "run", _rounds())
    back = rounds_from_csv(run)
    assert rounds_frame(back).equals(rounds_frame(_rounds()))
    assert attempts_frame(back).equals(attempts_frame(_rounds()))
    (row,) = clutter_table(back).to_dict("records")
    assert (row["attempts"], row["removed"], row["placed"]) == (5, 4, 5)  # round 2 erred: not in DR


def test_a_run_whose_rounds_all_erred_has_an_attempts_table_without_rows(tmp_path):
    run = _write_run(tmp_path / "run", _rounds()[2:])
    assert (run / "attempts.csv").read_text() == "\n"  # what pandas writes for no rows
    assert [r.end for r in rounds_from_csv(run)] == ["error"]


@pytest.mark.parametrize("case", CASES, ids=list(CASES))
def test_a_bad_clutter_table_is_one_line_naming_file_row_and_column(tmp_path, capsys, case):
    """Finding 8: each hand-broken table of a record=false clutter run is refused whole by ``report`` in one
    line (exit 1, as a bad results.csv), never a traceback or a table with exit 0."""
    spoil, name, match = CASES[case]
    run = _write_run(tmp_path / "run", _rounds())
    spoil(run)
    with pytest.raises(RoundTableError) as caught:
        rounds_from_csv(run)
    assert caught.value.path == run / name and re.search(match, str(caught.value)), str(caught.value)
    assert "\n" not in str(caught.value) and str(run / name) in str(caught.value)
    rounds, bad = collect_rounds(tmp_path)
    assert rounds == [] and bad == [(run / name, str(caught.value))]
    assert report_main([str(run), "--gallery", "0"]) == 1
    out, err = capsys.readouterr()
    assert f"graspexp report: {caught.value}\n" in err and "Traceback" not in err
    assert "Clutter removal" not in out and f"- `{run / name}`: {caught.value}" in out


def test_the_report_cli_names_a_bad_attempts_csv_in_one_line(tmp_path):
    """Finding 8 as a user meets it: ``python -m graspexp report`` on a hand-edited attempts.csv."""
    from helpers.cli import graspexp

    run = _write_run(tmp_path / "run", _rounds())
    _set(run / "attempts.csv", 3, "success", "maybe")
    proc = graspexp("report", str(run), "--gallery", "0")
    assert proc.returncode == 1 and "Traceback" not in proc.stderr
    lines = [line for line in proc.stderr.splitlines() if "attempts.csv" in line]
    assert lines == [f"graspexp report: {run / 'attempts.csv'} row 3: success='maybe' is not True or False"]


def test_an_attempts_csv_without_rounds_is_named(tmp_path, capsys):
    run = _write_run(tmp_path / "run", _rounds())
    (run / "rounds.csv").unlink()
    assert collect_rounds(tmp_path) == (
        [],
        [(run / "attempts.csv", f"{run / 'attempts.csv'}: no rounds.csv or round log beside it: its attempts "
                                "are in no table")],
    )  # fmt: skip


@pytest.fixture(scope="module")
def logged_run(tmp_path_factory) -> Path:
    """A logged pile run of two rounds (``trials/pile/000.mcap``, ``001.mcap``)."""
    from helpers.config import compose_cfg

    from graspexp.run.runner import run_in_dir

    run = tmp_path_factory.mktemp("logged") / "run"
    cfg = compose_cfg(
        "mode=pile", "dataset=primitives", "objects=[can,box]", "mode.objects_per_round=2", "trials=2",
        "progress=false",
    )  # fmt: skip
    run_in_dir(cfg, run)
    return run


def _killed(logged_run: Path, tmp_path: Path) -> Path:
    """The logged run as a killed job leaves it: its round logs, no rounds.csv, attempts.csv or summary."""
    run = tmp_path / "killed"
    shutil.copytree(logged_run, run)
    for name in ("rounds.csv", "attempts.csv", "summary.md"):
        (run / name).unlink()
    return run


@pytest.mark.slow
def test_round_logs_without_rounds_csv_are_reported(logged_run, tmp_path, capsys):
    """Finding 7: a clutter run killed before its tables were written: its finished rounds are in the report."""
    run = _killed(logged_run, tmp_path)
    assert report_main([str(run), "--gallery", "0"]) == 0
    out = capsys.readouterr().out
    assert "2 clutter rounds read" in out and "| optimal | pile | primitives | 2 |" in out


@pytest.mark.slow
def test_a_killed_runs_finished_rounds_count_beside_its_damaged_first_log(logged_run, tmp_path, capsys):
    """Finding 7: the first round log damaged (cut) and the last one unfinished, as a killed job leaves them:
    the finished round is reported and the others named, never "no trial logs" or no round at all."""
    run = _killed(logged_run, tmp_path)
    first = run / "trials" / "pile" / "000.mcap"
    first.write_bytes(first.read_bytes()[:2000])
    (run / "trials" / "pile" / "002.mcap.partial").write_bytes(b"\x89MCAP0\r\n")
    assert report_main([str(run), "--gallery", "0"]) == 1
    out, err = capsys.readouterr()
    assert "1 clutter rounds read" in out and "| optimal | pile | primitives | 1 |" in out
    assert f"graspexp report: {first}: truncated" in err and "002.mcap.partial" in err


@pytest.mark.slow
def test_table_rows_without_a_log_count_beside_the_logged_rounds(logged_run, tmp_path, capsys):
    """A ``record=false`` round kept in rounds.csv beside logged ones (the runner merges them): the report
    counts the logged rounds from their logs and the other from its row; a broken table is named, and the
    logged rounds still count."""
    run = tmp_path / "mixed"
    shutil.copytree(logged_run, run)
    extra = dataclasses.replace(
        _rounds()[1], round=2, attempts=[dataclasses.replace(a, round=2) for a in _rounds()[1].attempts]
    )
    _write_run(run, [*rounds_from_csv(run), extra])
    rounds, bad = collect_rounds(run)
    assert [r.round for r in rounds] == [0, 1, 2] and bad == []
    assert rounds[2].drawn == extra.drawn and rounds[0].drawn != extra.drawn  # round 2 from its row
    _set(run / "attempts.csv", 2, "success", "maybe")
    rounds, bad = collect_rounds(run)
    assert [r.round for r in rounds] == [0, 1] and [p for p, _ in bad] == [run / "attempts.csv"]
