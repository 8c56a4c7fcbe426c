"""Clutter removal (``mode=pile``/``packed``) in tables: per planner and scene, the grasp success rate (GSR =
successful / executed attempts) and the declutter rate (DR = objects removed / objects placed), each with
its Wilson 95 % interval, attempts per round, how rounds ended, the failure reason of every failed attempt
and the planning latency per scene (p50/p95, CPU and wall). The metrics are VGN's (Breyer et al., CoRL
2020: "success rate" and "percent cleared") and GIGA's (Jiang et al., RSS 2021)."""

from collections.abc import Iterable
from pathlib import Path

import pandas as pd

from graspexp.core.rounds import RoundEnd, RoundResult
from graspexp.core.run_layout import ATTEMPTS_CSV, ROUNDS_CSV, TRIALS_DIR, round_log_path
from graspexp.record import CorruptLogError, iter_trial_logs, read_result, read_round
from graspexp.report.round_csv import ATTEMPT_LIST_FIELDS, ROUND_LIST_FIELDS, RoundTableError, rounds_from_csv
from graspexp.report.stats import percentiles, success_pct


def rounds_frame(rounds: Iterable[RoundResult]) -> pd.DataFrame:
    """One row per round: placed, removed, attempts, how it ended (without the attempts themselves)."""
    rows = []
    for r in rounds:
        d = r.to_dict()
        d.pop("attempts")
        d.update(n_placed=r.n_placed, n_removed=r.n_removed, n_attempts=sum(a.executed for a in r.attempts))
        for key in ROUND_LIST_FIELDS:
            d[key] = " ".join(d[key])
        rows.append(d)
    return pd.DataFrame(rows)


def attempts_frame(rounds: Iterable[RoundResult]) -> pd.DataFrame:
    """One row per attempt (and per round that found no grasp, ``executed`` False), with the round's
    dataset, mode and planner."""
    rows = []
    for r in rounds:
        for a in r.attempts:
            row = {"dataset": r.dataset, "mode": r.mode, "planner": r.planner, **a.to_dict()}
            for key in ATTEMPT_LIST_FIELDS:
                row[key] = " ".join(row[key])
            rows.append(row)
    return pd.DataFrame(rows)


def read_rounds(run_dir: Path | str) -> list[RoundResult]:
    """The rounds of a run directory, from its round logs (``trials/<mode>/NNN.mcap``), else from its
    ``rounds.csv`` / ``attempts.csv`` (a ``record=false`` run; :func:`rounds_from_csv`: RoundTableError for a
    table that breaks its schema). A damaged log is skipped."""
    rounds, _ = _logged_rounds(Path(run_dir))
    if rounds or not (Path(run_dir) / ROUNDS_CSV).is_file():
        return rounds
    return rounds_from_csv(run_dir)


def _logged_rounds(run_dir: Path) -> tuple[list[RoundResult], list[tuple[Path, str]]]:
    """The rounds of ``run_dir``'s finished round logs, and (path, reason) for each whose /round message is not
    a round result. A log that is not a round's, or not finished, or damaged, is left to
    :func:`graspexp.report.collect.collect`, which names it."""
    rounds, bad = [], []
    for path in iter_trial_logs(run_dir):
        try:
            message = read_round(path)
        except (CorruptLogError, OSError):
            continue
        try:
            rounds.append(RoundResult.from_dict(message))
        except ValueError as exc:
            bad.append((path, f"{path}: {exc}"))
    return rounds, bad


def _log_kind(path: Path) -> str:
    """``round`` for a finished round log, ``trial`` for a finished trial log, else ``""``."""
    for kind, read in (("round", read_round), ("trial", read_result)):
        try:
            read(path)
        except (CorruptLogError, OSError):
            continue
        return kind
    return ""


def round_log_dirs(root: Path | str) -> list[Path]:
    """The folders below ``root`` that hold a clutter job's round logs (``trials/<mode.name>/`` of a run
    directory), sorted. A folder holds one job's logs, of one kind: its first log that reads as a round's or a
    trial's tells (a killed run's damaged or unfinished logs are passed over, so its finished rounds count)."""
    out = []
    for folder in sorted({p.parent for p in Path(root).rglob(f"{TRIALS_DIR}/*/*.mcap")}):
        kinds = (_log_kind(p) for p in sorted(folder.glob("*.mcap")) if p.is_file())
        if next((k for k in kinds if k), "") == "round":
            out.append(folder)
    return out


def _round_runs(root: Path) -> list[Path]:
    """The run directories below ``root`` that hold a ``rounds.csv`` or round logs, sorted."""
    runs = {p.parent for p in root.rglob(ROUNDS_CSV)}
    runs |= {d.parent.parent for d in round_log_dirs(root)}
    return sorted(runs)


def _run_rounds(run_dir: Path) -> tuple[list[RoundResult], list[tuple[Path, str]]]:
    """Every round of a run directory: its finished round logs, and the rows of its ``rounds.csv`` that no
    round log holds (a ``record=false`` run's, kept beside logged rounds of the same config by the runner),
    by round; (path, reason) for a log whose /round is not a round result (:func:`_logged_rounds`). Raises
    :class:`RoundTableError` for a table that breaks its schema, even beside logs (its rows without a log
    would be lost silently)."""
    rounds, bad = _logged_rounds(run_dir)
    if (run_dir / ROUNDS_CSV).is_file():
        rounds += [r for r in rounds_from_csv(run_dir) if not _logged(run_dir, r)]
    return sorted(rounds, key=lambda r: (r.dataset, r.mode, r.planner, r.round)), bad


def _logged(run_dir: Path, r: RoundResult) -> bool:
    """Whether round ``r``'s log file is in ``run_dir`` (even unfinished or damaged: then it is named)."""
    try:
        return round_log_path(run_dir, r.mode, r.round).exists()
    except ValueError:  # a mode name that cannot be a folder: no log of it
        return False


def find_rounds(root: Path | str) -> list[RoundResult]:
    """Every round below ``root`` (a run or a sweep directory): of each run directory that holds a
    ``rounds.csv`` or round logs (:func:`round_log_dirs`), its logged rounds and its table's rows without a log
    (RoundTableError for a table that breaks its schema)."""
    return [r for run in _round_runs(Path(root)) for r in _run_rounds(run)[0]]


def collect_rounds(root: Path | str) -> tuple[list[RoundResult], list[tuple[Path, str]]]:
    """As :func:`find_rounds`, never raising for what it cannot read: the rounds, and (path, one-line reason) for
    each table refused whole (:class:`RoundTableError`: none of its rows counts; a run's logged rounds still
    do), each round log whose /round is not a round result, and each ``attempts.csv`` without a ``rounds.csv``
    or round logs beside it (damaged logs are :func:`graspexp.report.collect.collect`'s to name)."""
    root = Path(root)
    rounds, bad = [], []
    runs = _round_runs(root)
    for run in runs:
        try:
            found, bad_logs = _run_rounds(run)
        except RoundTableError as exc:
            found, bad_logs = _logged_rounds(run)
            bad.append((exc.path, str(exc)))
        rounds += found
        bad += bad_logs
    for table in sorted(root.rglob(ATTEMPTS_CSV)):
        if table.parent not in runs:
            bad.append(
                (table, f"{table}: no {ROUNDS_CSV} or round log beside it: its attempts are in no table")
            )
    return rounds, bad


def clutter_table(rounds: list[RoundResult]) -> pd.DataFrame:
    """Per (planner, mode, dataset): rounds, GSR and DR in % with their Wilson 95 % bounds, attempts per
    round, how the rounds ended, planning latency per scene p50/p95 (ms, CPU and wall), and the count of
    each failure reason of the failed attempts (``no_feasible_grasp``: rounds whose planner found none)."""
    att, rnd = attempts_frame(rounds), rounds_frame(rounds)
    rows = []
    for (planner, mode, dataset), rg in rnd.groupby(["planner", "mode", "dataset"], sort=True):
        ag = (
            att[(att["planner"] == planner) & (att["mode"] == mode) & (att["dataset"] == dataset)]
            if len(att)
            else att
        )
        done = rg[~rg["end"].isin([RoundEnd.ERROR.value, RoundEnd.NOTHING_PLACED.value])]  # ran a planner
        executed = ag[ag["executed"]] if len(ag) else ag
        n_ok = int(executed["success"].sum()) if len(executed) else 0
        gsr = success_pct(n_ok, len(executed))
        dr = success_pct(int(done["n_removed"].sum()), int(done["n_placed"].sum()))
        cpu = percentiles(1e3 * ag["plan_cpu_s"]) if len(ag) else (float("nan"),) * 2
        wall = percentiles(1e3 * ag["plan_s"]) if len(ag) else (float("nan"),) * 2
        row = {
            "planner": planner, "mode": mode, "dataset": dataset, "rounds": len(done),
            "GSR_%": gsr[0], "GSR_lo": gsr[1], "GSR_hi": gsr[2],
            "DR_%": dr[0], "DR_lo": dr[1], "DR_hi": dr[2],
            "attempts": len(executed), "attempts/round": len(executed) / len(done) if len(done) else float("nan"),
            "placed": int(done["n_placed"].sum()), "removed": int(done["n_removed"].sum()),
            "plan_cpu_p50_ms": cpu[0], "plan_cpu_p95_ms": cpu[1], "plan_p50_ms": wall[0], "plan_p95_ms": wall[1],
        }  # fmt: skip
        for end in RoundEnd:
            row[f"end_{end.value}"] = int((rg["end"] == end.value).sum())
        if len(ag):
            for reason, n in ag[~ag["success"]]["reason"].value_counts().sort_index().items():
                row[f"fail_{reason}"] = int(n)
        rows.append(row)
    return pd.DataFrame(rows)


def clutter_markdown(rounds: list[RoundResult]) -> str:
    """The clutter table as markdown: one line per planner and scene, intervals in brackets."""
    return table_markdown(clutter_table(rounds))


def table_markdown(table: pd.DataFrame) -> str:
    """Rows of :func:`clutter_table` as markdown, in their order, intervals in brackets."""
    if table.empty:
        return "no clutter round finished"
    lines = [
        "| planner | scene | dataset | rounds | GSR % [95 % CI] | DR % [95 % CI] | attempts/round | plan CPU p50 / p95 ms "
        "| plan wall p50 / p95 ms | round ends | failed attempts |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for _, r in table.iterrows():
        ends = ", ".join(f"{c[4:]} {int(r[c])}" for c in table.columns if c.startswith("end_") and r[c] > 0)
        fails = ", ".join(
            f"{c[5:]} {int(r[c])}"
            for c in table.columns
            if c.startswith("fail_") and r[c] == r[c] and r[c] > 0
        )
        lines.append(
            f"| {r['planner']} | {r['mode']} | {r['dataset']} | {r['rounds']} "
            f"| {r['GSR_%']:.1f} [{r['GSR_lo']:.1f}, {r['GSR_hi']:.1f}] ({r['attempts']} attempts) "
            f"| {r['DR_%']:.1f} [{r['DR_lo']:.1f}, {r['DR_hi']:.1f}] ({r['removed']}/{r['placed']}) "
            f"| {r['attempts/round']:.2f} | {r['plan_cpu_p50_ms']:.1f} / {r['plan_cpu_p95_ms']:.1f} "
            f"| {r['plan_p50_ms']:.1f} / {r['plan_p95_ms']:.1f} | {ends} | {fails or '-'} |"
        )
    return "\n".join(lines)


def registration_markdown(rounds: list[RoundResult]) -> str:
    """Per planner and scene, the error of the pose registered from the camera for the target of every
    executed attempt (``perception.source=depth``): ADD-S p50/p95 (mm), translation and rotation error p50
    (mm, deg). Attempts without a registered pose (exact poses) are left out."""
    att = attempts_frame(rounds)
    if att.empty or "pose_adds_mm" not in att:
        return "no attempt with a registered pose"
    att = att[att["executed"].astype(bool) & pd.to_numeric(att["pose_adds_mm"], errors="coerce").notna()]
    if att.empty:
        return "no attempt with a registered pose"
    lines = [
        "| planner | scene | dataset | attempts | ADD-S p50 / p95 mm | translation p50 mm | rotation p50 deg |",
        "|---|---|---|---|---|---|---|",
    ]
    for (planner, mode, dataset), g in att.groupby(["planner", "mode", "dataset"], sort=True):
        adds = percentiles(g["pose_adds_mm"].astype(float))
        trans = percentiles(g["pose_trans_err_mm"].astype(float))[0]
        rot = percentiles(g["pose_rot_err_deg"].astype(float))[0]
        lines.append(
            f"| {planner} | {mode} | {dataset} | {len(g)} | {adds[0]:.1f} / {adds[1]:.1f} | {trans:.1f} | {rot:.1f} |"
        )
    return "\n".join(lines)


def side_by_side_markdown(exact: list[RoundResult], registered: list[RoundResult]) -> str:
    """GSR and DR of each planner and scene with exact poses beside the same with poses registered from the
    camera, over the rounds both ran (planner, scene, dataset and round index: the same heaps), Wilson 95 %
    intervals in brackets."""
    cols = ["planner", "mode", "dataset"]
    ran = {(r.planner, r.mode, r.dataset, r.round) for r in registered}
    exact = [r for r in exact if (r.planner, r.mode, r.dataset, r.round) in ran]
    if not exact:
        return "no planner and scene ran with both exact and registered poses"
    both = clutter_table(exact).merge(clutter_table(registered), on=cols, suffixes=("_exact", "_reg"))

    def cell(r: pd.Series, what: str, kind: str) -> str:
        return f"{r[f'{what}_%_{kind}']:.1f} [{r[f'{what}_lo_{kind}']:.1f}, {r[f'{what}_hi_{kind}']:.1f}]"

    lines = [
        "| planner | scene | dataset | rounds | GSR % exact | GSR % registered | DR % exact "
        "| DR % registered |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for _, r in both.iterrows():
        lines.append(
            f"| {r['planner']} | {r['mode']} | {r['dataset']} | {r['rounds_reg']} "
            f"| {cell(r, 'GSR', 'exact')} | {cell(r, 'GSR', 'reg')} | {cell(r, 'DR', 'exact')} "
            f"| {cell(r, 'DR', 'reg')} |"
        )
    return "\n".join(lines)
