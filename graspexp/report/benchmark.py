"""The benchmark's result tables (``python -m graspexp benchmark``): per dataset a ranking of the planners
at zero pose noise beside the paper's printed Average, the entered planner beside the paper's tables,
every setting and noise level, and the failure reasons; written as Markdown and CSV files."""

import math
from pathlib import Path

import pandas as pd

from graspexp.core.outcome import UNPLANNED
from graspexp.core.rounds import RoundResult
from graspexp.report.compare import FC_MU, check_same_drops, render_markdown
from graspexp.report.compare import success_by_noise as noise_success_table
from graspexp.report.contact_area import IN_AREA_TOLERANCE_M
from graspexp.report.paper import PAPER_TABLES, SETTINGS
from graspexp.report.render import display_frame, footnotes, markdown
from graspexp.report.round_tables import clutter_table, table_markdown
from graspexp.report.stats import percentiles, success_pct
from graspexp.report.tables import failure_breakdown, success_table

TRIAL_COLUMNS = (
    "planner",
    "dataset",
    "mode",
    "rot",
    "trans_mm",
    "rot_deg",
    "object",
    "trial",
    "success",
    "reason",
    "contacts",
    "contacts_in_area",
    "fc_min_mu",
    "plan_ms",
)
"""Columns of ``trials.csv``: one row per trial, with its in-area contact fraction beside its outcome."""
IN_AREA_NOTE = (
    "In-area contact %: share of the finger-object contacts at the end of closing that lie within "
    f"{IN_AREA_TOLERANCE_M * 1000:g} mm of a grasping-area point of the object's reference cloud "
    "(graspexp/report/contact_area.py; from each log's /contacts and /tf), over the trials whose fingers "
    "touch the object then. Trials all in area %: share of those trials whose every contact is in the area. "
    "Success in area: successful trials whose every contact is in the area (the hand-over task's success)."
)


def _success(g: pd.DataFrame) -> str:
    n = len(g)
    rate, lo, hi = success_pct(int(g["success"].sum()), n)
    return f"{rate:.0f} [{lo:.0f}, {hi:.0f}] ({n})" if n else "n/a"


def ranking(df: pd.DataFrame, dataset: str, settings: list[str]) -> pd.DataFrame:
    """Zero-noise trials of one dataset: one row per planner, best success first, then the paper's
    printed Average of its own method (where the paper reports this dataset)."""
    rows = []
    zero = df[(df["dataset"] == dataset) & (df["trans_mm"] == 0) & (df["rot_deg"] == 0)]
    for planner, g in zero.groupby("planner", sort=True):
        row = {"planner": planner, "success % [95% CI] (n)": _success(g), "_rate": g["success"].mean()}
        for s in settings:
            mode, rot = s.split("/")
            row[s] = _success(g[(g["mode"] == mode) & (g["rot"] == rot)])
        planned = g[~g["reason"].isin(UNPLANNED)]
        touched = int(g["contacts"].sum())
        row["in-area contact %"] = f"{100 * g['contacts_in_area'].sum() / touched:.0f}" if touched else "n/a"
        held = g[g["contacts"] > 0]
        all_in = (held["contacts_in_area"] == held["contacts"]).mean() if len(held) else math.nan
        row["trials all in area %"] = f"{100 * all_in:.0f}" if len(held) else "n/a"
        in_area_success = g["success"] & (g["contacts"] > 0) & (g["contacts_in_area"] == g["contacts"])
        row["success in area % [95% CI]"] = _success(g.assign(success=in_area_success))
        row[f"force-closure % (mu<={FC_MU:g})"] = (
            f"{100 * (planned['fc_min_mu'] <= FC_MU + 1e-9).mean():.0f}" if len(planned) else "n/a"
        )
        mu = planned["fc_min_mu"].median() if len(planned) else math.nan
        row["median min mu"] = f"{mu:.2f}"
        p50, p95 = percentiles(g["plan_ms"])
        row["plan ms p50 / p95"] = f"{p50:.0f} / {p95:.0f}"
        reasons = g.loc[~g["success"], "reason"].fillna("(none)").value_counts()
        row["failures"] = ", ".join(f"{r} {c}" for r, c in reasons.head(3).items()) or "none"
        rows.append(row)
    table = pd.DataFrame(rows)
    if not table.empty:
        table = table.sort_values(["_rate", "planner"], ascending=[False, True]).drop(columns="_rate")
    paper = PAPER_TABLES.get(dataset)
    if paper is not None:
        printed = dict(zip([f"{m}/{r}" for m, r in SETTINGS], paper.ours_average, strict=True))
        shown = [printed[s] for s in settings if s in printed]
        row = {"planner": "paper (printed Average, its own method)"}
        row["success % [95% CI] (n)"] = f"{sum(shown) / len(shown):.0f}" if shown else "n/a"
        row.update({s: f"{printed[s]:.0f}" if s in printed else "n/a" for s in settings})
        table = pd.concat([table, pd.DataFrame([row])], ignore_index=True).fillna("")
    return table


def summary_lines(
    df: pd.DataFrame, planner: str, planners: list[str], datasets: list[str], settings: list[str], out: Path
) -> list[str]:
    """The Markdown sections of the benchmark of ``planner`` ranked among ``planners`` on ``datasets`` and
    ``settings`` (``mode/rot``), from ``df`` (one row per trial with ``trans_mm``, ``rot_deg``,
    ``contacts`` and ``contacts_in_area``); writes ``ranking.csv``, ``trials.csv``, ``noise.csv`` and
    ``failures.csv`` into ``out``."""
    lines = []
    df = df[df["planner"].isin(planners)]
    rankings = []
    for dataset in datasets:
        table = ranking(df, dataset, settings)
        rankings.append(table.assign(dataset=dataset))
        lines += [f"## Ranking on `{dataset}` (zero pose noise)", "", markdown(table, index=False), ""]
    lines += [
        "Success: successes / trials with the Wilson 95 % score interval; plan time: wall time of the "
        f"plan call (ms); force-closure: share of planned grasps force-closure at mu <= {FC_MU:g}, and "
        "the median smallest such mu (NaN: none); failures: the three most frequent reasons.",
        IN_AREA_NOTE,
        "",
    ]
    pd.concat(rankings).to_csv(out / "ranking.csv", index=False)
    per_trial = df[[*TRIAL_COLUMNS]].assign(
        in_area_fraction=(df["contacts_in_area"] / df["contacts"].where(df["contacts"] > 0))
    )
    per_trial.to_csv(out / "trials.csv", index=False)
    zero = df[(df["trans_mm"] == 0) & (df["rot_deg"] == 0)]
    for dataset in datasets:
        if dataset in PAPER_TABLES and (zero["dataset"] == dataset).any():
            st = success_table(zero, dataset, planner)
            lines += [f"## `{planner}` beside the paper's Table {st.paper.number}", ""]
            lines += [markdown(display_frame(st)), "", *(f"- {n}" for n in footnotes(st)), ""]
    noise = noise_success_table(df)
    noise.to_csv(out / "noise.csv", index=False)
    lines += ["## Every setting and pose-noise level", ""]
    lines += render_markdown(noise, check_same_drops(df), []).splitlines()[2:]
    failures = failure_breakdown(zero)
    failures.to_csv(out / "failures.csv", index=False)
    lines += ["", "## Failure reasons (zero pose noise)", "", markdown(failures, index=False), ""]
    return lines


def same_rounds(rounds: list[RoundResult]) -> bool:
    """True when every planner ran the same rounds (round index, seed and objects drawn) in each dataset and
    scene: a ranking of planners on the same heaps."""
    drawn: dict[tuple[str, str], dict[str, set]] = {}
    for r in rounds:
        key = (r.dataset, r.mode)
        drawn.setdefault(key, {}).setdefault(r.planner, set()).add((r.round, r.seed, tuple(r.drawn)))
    return all(len({frozenset(v) for v in by_planner.values()}) == 1 for by_planner in drawn.values())


def clutter_lines(levels: dict[tuple[float, float], list[RoundResult]], out: Path) -> list[str]:
    """The Markdown sections of a benchmark in the clutter modes: per dataset and scene the planners ranked
    at zero pose noise by DR (objects cleared), then GSR; then every pose-noise level (``levels``: (mm,
    degrees) -> its rounds). Writes ``clutter_ranking.csv`` (every level) into ``out``."""
    lines, tables = [], []
    for (t, r), rounds in levels.items():
        table = clutter_table(rounds)
        if table.empty:
            continue
        table = table.sort_values(
            ["dataset", "mode", "DR_%", "GSR_%", "planner"], ascending=[True, True, False, False, True]
        )
        tables.append(table.assign(trans_mm=t, rot_deg=r))
        if (t, r) == (0.0, 0.0):
            for (dataset, mode), g in table.groupby(["dataset", "mode"], sort=True):
                lines += [f"## Ranking on `{dataset}`, clutter removal `{mode}` (zero pose noise)", ""]
                lines += [table_markdown(g), ""]
            lines += [
                "Ranked by DR (objects removed / objects placed), then GSR (successful / executed attempts), "
                "each with its Wilson 95 % interval; plan time: every plan of an attempt (ms).",
                "",
                "Same heaps: every planner ran the same rounds (seed and objects drawn) in each scene."
                if same_rounds(rounds)
                else "The planners did not all run the same rounds: compare with care.",
                "",
            ]
        else:
            lines += [f"## Clutter removal at pose noise {t:g} mm / {r:g} deg", "", table_markdown(table), ""]
    if tables:
        pd.concat(tables, ignore_index=True).to_csv(out / "clutter_ranking.csv", index=False)
    return lines
