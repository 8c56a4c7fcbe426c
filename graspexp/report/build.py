"""Assemble the report from a run or multirun directory and write it as Markdown, CSV, LaTeX and PNG.

Output files (in ``<dir>/report/`` unless told otherwise)::

    report.md                        everything below, in one Markdown file (also printed)
    table<N>_<dataset>_<planner>.*   success table: .md / .tex (paper layout), .csv (numeric), .png
    failures.{md,csv,tex}            failure-reason counts per setting
    runtime.{md,csv,tex}             planner wall time p50 / p95 against the paper's 0.1 s
    strict.csv                       success by the paper's criterion, the stricter slip one and in the area
    agreement_<dataset>_<planner>.*  per object and setting: ours beside the paper, Fisher's exact test
                                     (.md / .csv / .png; agreement/*.png: a failure of each flagged cell)
    gallery.md, gallery/*.png        failure examples drawn from their logs (:mod:`.gallery`)
    unreadable.csv                   logs that could not be read (path, reason), if any
"""

from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from graspexp.core.rounds import RoundResult
from graspexp.record import CorruptLogError, read_trial
from graspexp.report.agreement import Agreement, agreement, agreement_chart, example_trials
from graspexp.report.charts import success_chart
from graspexp.report.citations import DETERMINISM
from graspexp.report.clutter_strips import write_clutter_strips
from graspexp.report.collect import FINGERPRINT_COLUMN, Collected, collect
from graspexp.report.contact_area import held_in_area
from graspexp.report.gallery import draw_trial, write_gallery
from graspexp.report.paper import PLANNER_RUNTIME_S
from graspexp.report.pose_error import success_by_pose_error
from graspexp.report.render import display_frame, fmt_pct, footnotes, latex, markdown
from graspexp.report.round_tables import clutter_markdown, clutter_table, collect_rounds
from graspexp.report.tables import (
    IN_AREA_COLUMN,
    STRICT_SLIP_M,
    SuccessTable,
    failure_breakdown,
    runtime_table,
    strict_table,
    success_tables,
    wide_numeric,
)


@dataclass
class Report:
    collected: Collected
    tables: list[SuccessTable]
    failures: pd.DataFrame
    runtime: pd.DataFrame
    strict: pd.DataFrame
    """Success by the paper's criterion beside the stricter slip criterion and in the area, per setting."""
    agreements: list[Agreement]
    """Per object agreement with the paper, one per table that reproduces a paper table."""
    rounds: list[RoundResult] = field(default_factory=list)
    """The clutter-removal rounds below the directory (``mode=pile``/``packed``)."""


def build_report(root: Path | str, progress: bool = True) -> Report:
    """Collect every trial log below ``root`` and build all tables (nothing is written); the held trials'
    logs are read again for the in-area criterion (``progress``: a progress bar on stderr). The clutter rounds
    come from their logs or their tables (:func:`graspexp.report.round_tables.collect_rounds`); a table refused
    by its schema is listed with the unreadable logs."""
    col = collect(root)
    df = col.results
    rounds, bad_rounds = collect_rounds(root)
    col.unreadable += bad_rounds
    if df.empty:
        return Report(col, [], pd.DataFrame(), pd.DataFrame(), pd.DataFrame(), [], rounds)
    df[IN_AREA_COLUMN] = held_in_area(df, progress)
    tables = success_tables(df)
    agreements = [a for a in map(agreement, tables) if a is not None]
    outcomes = pd.concat([df, col.not_run], ignore_index=True)  # counts: the not-run trials as `error`
    return Report(
        col, tables, failure_breakdown(outcomes), runtime_table(df), strict_table(df), agreements, rounds
    )


def _runtime_display(rt: pd.DataFrame) -> pd.DataFrame:
    out = rt.copy()
    for c in ("p50_ms", "p95_ms"):
        out[c] = [fmt_pct(v, 1) for v in out[c]]
    out["paper_ms"] = [fmt_pct(v, 0) for v in out["paper_ms"]]
    for c in ("p50_ratio", "p95_ratio"):
        out[c] = [fmt_pct(v, 2) + "×" if v == v else "n/a" for v in out[c]]
    return out.rename(
        columns={
            "p50_ms": "plan p50 (ms)",
            "p95_ms": "plan p95 (ms)",
            "paper_ms": "paper (ms)",
            "p50_ratio": "p50 / paper",
            "p95_ratio": "p95 / paper",
        }
    )


def _unreadable_section(col: Collected) -> list[str]:
    lines = [f"## Unreadable logs ({len(col.unreadable)})", ""]
    if not col.unreadable:
        return [*lines, "None: every trial log below the directory was read.", ""]
    lines.append(
        "These logs could not be read and are NOT counted in the tables above; re-run the same "
        "command into the same directory to redo those trials."
    )
    lines.append("")
    lines += [f"- `{p}`: {reason}" for p, reason in col.unreadable]
    return [*lines, ""]


def _not_run_section(col: Collected) -> list[str]:
    """The trials that ended in ``error``, per object and setting: not run, so in no table or average."""
    if col.not_run.empty:
        return []
    lines = [
        f"## Not run ({len(col.not_run)} trials)",
        "",
        "These trials ended in an error (an object that could not be used, a trial that raised); they are "
        "in no success rate, average or paper comparison above (an object without a run trial shows n/a).",
        "",
    ]
    for key, group in col.not_run.groupby(["dataset", "planner", "mode", "rot", "object"], sort=False):
        why = str(group["error"].iloc[0]).splitlines()[0] if "error" in group else ""
        lines.append(f"- {'/'.join(key[:4])} {key[4]!r}: {len(group)} trial(s) not run: {why}")
    return [*lines, ""]


def _agreement_display(ag: Agreement, pictures: dict[tuple[str, str, str], str]) -> pd.DataFrame:
    c = ag.cells
    return pd.DataFrame(
        {
            "setting": c["setting"],
            "object": c["label"],
            "ours": [f"{k}/{n}" for k, n in zip(c["ours_k"], c["ours_n"], strict=True)],
            "paper": [f"{k}/{n}" for k, n in zip(c["paper_k"], c["paper_n"], strict=True)],
            "Δ (points)": [fmt_pct(v) for v in c["diff_pp"]],
            "Fisher p (ours < paper)": [f"{p:.3g}" for p in c["p_below"]],
            "below": ["**yes**" if f else "" for f in c["flagged"]],
            "failure (most frequent)": [
                r if f else "" for r, f in zip(c["top_reason"], c["flagged"], strict=True)
            ],
            "picture": [
                pictures.get((m, r, o), "") for m, r, o in zip(c["mode"], c["rot"], c["object"], strict=True)
            ],
        }
    )


def agreement_section(ag: Agreement, results: pd.DataFrame, out: Path) -> list[str]:
    """Write ``agreement_<dataset>_<planner>.{md,csv,png}`` and a picture of each flagged cell's failure;
    returns the report.md lines."""
    pictures = {}
    for key, row in example_trials(ag, results).items():
        mode, rot, obj = key
        name = f"{ag.dataset}_{ag.planner}_{mode}_{rot}_{obj}_{int(row['trial']):03d}"
        try:
            log = read_trial(row["path"])
        except (CorruptLogError, OSError):
            continue
        title = f"{obj} · {mode} {rot} · {ag.planner} · trial {int(row['trial'])}: {row['reason']}"
        draw_trial(log, out / "agreement" / f"{name}.png", title)
        pictures[key] = f"![{name}](agreement/{name}.png)"
    disp = _agreement_display(ag, pictures)
    (out / f"{ag.name}.md").write_text(ag.summary() + "\n\n" + markdown(disp, index=False) + "\n")
    ag.cells.to_csv(out / f"{ag.name}.csv", index=False)
    agreement_chart(ag, out / f"{ag.name}.png")
    flagged = disp[ag.cells["flagged"].to_numpy() | (ag.cells["object"] == "").to_numpy()]
    return [
        f"## Agreement with the paper: {ag.dataset}, planner {ag.planner}",
        "",
        ag.summary() + ".",
        "",
        "Cells significantly below the paper (one-sided Fisher's exact test, p < 0.05) and each setting's "
        f"pooled row; every cell in [{ag.name}.md]({ag.name}.md) / `.csv`. The paper's numbers are its "
        "10-trial rates as printed.",
        "",
        markdown(flagged, index=False),
        "",
        f"![{ag.name}]({ag.name}.png)",
        "",
    ]


def clutter_section(rounds: list[RoundResult], out: Path) -> list[str]:
    """Write ``clutter.md``/``clutter.csv`` (:func:`graspexp.report.round_tables.clutter_table`); the report's lines."""
    text = clutter_markdown(rounds)
    (out / "clutter.md").write_text(text + "\n")
    clutter_table(rounds).to_csv(out / "clutter.csv", index=False)
    return [
        "## Clutter removal (mode=pile, mode=packed)",
        "",
        f"{len(rounds)} rounds. GSR = successful / executed grasp attempts, DR = objects removed / objects "
        "placed (VGN, Breyer et al. CoRL 2020; GIGA, Jiang et al. RSS 2021), each with its Wilson 95 % "
        "interval; planning latency per scene (every plan of an attempt), CPU and wall.",
        "",
        text,
        "",
    ]


def write_report(report: Report, out_dir: Path | str, gallery_per_reason: int = 2) -> str:
    """Write every file of the report into ``out_dir``; returns the Markdown of report.md.

    gallery_per_reason : example failures drawn per setting and failure reason (0: no gallery, and no
        strips of the clutter rounds' failed attempts, which are all drawn otherwise).
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    col = report.collected
    n_logs = len(col.results) + len(col.unreadable) + len(col.duplicates)
    rounds = f", {len(report.rounds)} clutter rounds read" if report.rounds else ""
    md = [
        f"# graspexp report: {col.root}",
        "",
        f"{n_logs + len(col.not_run)} trial logs found, {len(col.results)} results read{rounds}"
        + (f", {len(col.not_run)} trials not run (listed below)." if len(col.not_run) else "."),
        "",
    ]
    for table in report.tables:
        disp = display_frame(table)
        title = table.paper.title if table.paper else f"Grasping success rate on {table.dataset}"
        title = f"{title}, planner {table.planner}"
        (out / f"{table.name}.md").write_text(markdown(disp) + "\n")
        (out / f"{table.name}.tex").write_text(latex(disp, caption=title))
        wide_numeric(table).to_csv(out / f"{table.name}.csv")
        success_chart(table, out / f"{table.name}.png")
        md += [f"## {title}", "", markdown(disp), ""]
        md += [f"{i}. {note}" for i, note in enumerate(footnotes(table), 1)]
        md += ["", f"![{table.name}]({table.name}.png)", ""]
    for ag in report.agreements:
        md += agreement_section(ag, col.results, out)
    if report.rounds:
        md += clutter_section(report.rounds, out)
        if gallery_per_reason > 0 and write_clutter_strips(col.root, out):
            md += [
                "[clutter_failures.md](clutter_failures.md): every failed attempt drawn from its round log, "
                "when it was planned and when it ended (`clutter_failures/*.png`).",
                "",
            ]
    if not report.failures.empty:
        (out / "failures.md").write_text(markdown(report.failures, index=False) + "\n")
        (out / "failures.tex").write_text(latex(report.failures, "Failure reasons per setting", index=False))
        report.failures.to_csv(out / "failures.csv", index=False)
        md += [
            "## Failure reasons per setting (trial counts)",
            "",
            markdown(report.failures, index=False),
            "",
        ]
    by_error = success_by_pose_error(col.results)
    if not by_error.empty:
        by_error.to_csv(out / "pose_error.csv", index=False)
        md += [
            "## Success against the measured pose error (perception.source=depth)",
            "",
            markdown(by_error, index=False),
            "",
            "Trials whose pose was registered from the simulated depth camera, binned by ADD-S of the "
            "registered pose (mm); success rate with its Wilson 95 % interval.",
            "",
        ]
    if not report.strict.empty:
        disp = report.strict.assign(
            held_pct=[fmt_pct(v) for v in report.strict["held_pct"]],
            strict_pct=[fmt_pct(v) for v in report.strict["strict_pct"]],
            in_area_pct=[fmt_pct(v) for v in report.strict["in_area_pct"]],
        ).rename(
            columns={
                "held_pct": "held (paper) %",
                "strict_pct": f"held, slip ≤ {STRICT_SLIP_M * 1e3:g} mm %",
                "in_area_pct": "held, contacts in area %",
            }
        )
        report.strict.to_csv(out / "strict.csv", index=False)
        md += [
            "## Success criterion: the paper's and a stricter one",
            "",
            markdown(disp, index=False),
            "",
            "Paper IV-C: success = the object is still held after the support is removed (collab) or after "
            "the pull back (bin); the stricter column also needs the grasp point to have slid at most "
            f"{STRICT_SLIP_M * 1e3:g} mm over the object (each log's slip_m; `sim.slip_threshold_m` makes it "
            "the criterion of a run); the last also needs every finger contact at the end of closing in the "
            "grasping area.",
            "",
        ]
    if not report.runtime.empty:
        disp = _runtime_display(report.runtime)
        (out / "runtime.md").write_text(markdown(disp, index=False) + "\n")
        (out / "runtime.tex").write_text(latex(disp, "Planner wall time", index=False))
        report.runtime.to_csv(out / "runtime.csv", index=False)
        md += [
            "## Planner runtime",
            "",
            markdown(disp, index=False),
            "",
            f"Wall time of the planning phase per trial (TrialResult timings_s.plan) on this machine; the "
            f"paper (section IV-F) reports {PLANNER_RUNTIME_S:g} s for the grasping strategy on an i7-9700.",
            "",
        ]
    if gallery_per_reason > 0 and not col.results.empty:
        write_gallery(col.results, out, gallery_per_reason)
        md += [
            "## Failure gallery",
            "",
            f"[gallery.md](gallery.md): up to {gallery_per_reason} failed trials per setting and failure "
            "reason, drawn from their logs at the close and at the end (`gallery/*.png`).",
            "",
        ]
    md += _not_run_section(col)
    md += _unreadable_section(col)
    if col.unreadable:
        pd.DataFrame(col.unreadable, columns=["path", "reason"]).to_csv(out / "unreadable.csv", index=False)
    if FINGERPRINT_COLUMN in col.results:
        counts = col.results[FINGERPRINT_COLUMN].fillna("results.csv only (no log)").value_counts()
        md += ["## Machines and versions", ""]
        md += [
            f"Trial results may depend on the CPU and the libraries {DETERMINISM.cite()}; these logs were made on:",
            "",
        ]
        md += [f"- {n} trials: {name}" for name, n in counts.items()] + [""]
    if col.duplicates:
        md += [
            f"## Duplicate trials ({len(col.duplicates)})",
            "",
            "Logged twice below the directory; the first log is counted, these are not:",
            "",
        ]
        md += [f"- `{p}` (same trial as `{kept}`)" for p, kept in col.duplicates] + [""]
    text = "\n".join(md)
    (out / "report.md").write_text(text)
    return text
