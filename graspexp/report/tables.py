"""Build the report's tables (pandas) from collected results: the paper-layout success tables with Wilson
intervals and deltas, the failure-reason breakdown and the planner runtime table.

Percentages are in % (0-100); deltas are percentage points (ours - paper).
"""

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from graspexp.core.outcome import FailureReason
from graspexp.report.paper import (
    BASELINES,
    PAPER_TABLES,
    PLANNER_RUNTIME_S,
    SETTING_LABELS,
    SETTINGS,
    PaperTable,
)
from graspexp.report.stats import percentiles, success_pct

IN_AREA_COLUMN = "held_in_area"
"""Result column of the second criterion (:func:`graspexp.report.contact_area.held_in_area`): held with
every finger contact in the grasping area; True / False / None (cannot be told)."""
AVERAGE = "Average"
AVERAGE_SAME = "Paper avg., same objects"


@dataclass
class SuccessTable:
    """One success-rate table (one dataset and planner) in long form; formatting is done elsewhere."""

    dataset: str
    planner: str
    paper: PaperTable | None
    """The paper table this one reproduces, None for a dataset the paper does not report."""
    cells: pd.DataFrame
    """One row per (row label, setting): object (our id, or '' for average rows), label, mode, rot, n,
    successes, ours_pct, lo_pct, hi_pct (Wilson 95 %), in_area_pct (held with every finger contact in the
    grasping area, %; nan when unknown), top_reason / top_reason_n (the most frequent
    failure reason and its count; ties: the reason first in alphabetical order), paper_pct, delta_pp.
    n = 0 means no logs."""
    baselines: pd.DataFrame
    """Row label -> the paper's baseline columns (BASELINES), empty for tables without baselines."""
    rows: list[str]
    """Row labels in display order (paper order, extra objects, then the average rows)."""

    @property
    def name(self) -> str:
        prefix = f"table{self.paper.number}" if self.paper is not None else "table"
        return f"{prefix}_{self.dataset}_{self.planner}"


def _settings_for(df: pd.DataFrame) -> list[tuple[str, str]]:
    seen = list(dict.fromkeys(zip(df["mode"], df["rot"], strict=True)))
    return list(SETTINGS) + [s for s in seen if s not in SETTINGS]


def _in_area_pct(sub: pd.DataFrame) -> float:
    """% of the trials held with every finger contact in the grasping area; nan when any trial's value
    is unknown (or the column is absent)."""
    if IN_AREA_COLUMN not in sub or not len(sub) or sub[IN_AREA_COLUMN].isna().any():
        return math.nan
    return 100.0 * float(sub[IN_AREA_COLUMN].astype(bool).sum()) / len(sub)


def _cell(sub: pd.DataFrame) -> dict:
    n, k = len(sub), int(sub["success"].sum())
    pct, lo_pct, hi_pct = success_pct(k, n)
    reasons = sub.loc[~sub["success"], "reason"].fillna("(none)").value_counts().sort_index()
    reasons = reasons.sort_values(ascending=False, kind="stable")
    return {
        "n": n,
        "successes": k,
        "ours_pct": pct,
        "lo_pct": lo_pct,
        "hi_pct": hi_pct,
        "in_area_pct": _in_area_pct(sub),
        "top_reason": str(reasons.index[0]) if len(reasons) else "",
        "top_reason_n": int(reasons.iloc[0]) if len(reasons) else 0,
    }


def success_table(df: pd.DataFrame, dataset: str, planner: str) -> SuccessTable:
    """The success table of one dataset and planner from the collected results ``df``.

    Rows: the paper's objects in the paper's order (those without logs get n = 0, shown as n/a), then
    objects we ran that the paper does not list, then Average (mean over the paper's objects we ran, or
    over every object we ran when none of the paper's did, e.g. a held-out split; with a Wilson interval
    over their pooled trials; paper = the Average as printed) and the paper's average over the same
    objects we ran.
    """
    sel = df[(df["dataset"] == dataset) & (df["planner"] == planner)]
    paper = PAPER_TABLES.get(dataset)
    paper_objects = list(paper.labels) if paper else []
    ran = list(dict.fromkeys(sel["object"]))
    extra = [o for o in ran if o not in paper_objects]
    objects = paper_objects + extra
    labels = {o: (paper.labels[o] if paper and o in paper.labels else o) for o in objects}
    in_avg = paper_objects if set(paper_objects) & set(ran) else objects  # held-out objects: their own mean
    records = []
    for si, (mode, rot) in enumerate(_settings_for(sel)):
        in_setting = sel[(sel["mode"] == mode) & (sel["rot"] == rot)]
        ran_here = []
        for obj in objects:
            cell = _cell(in_setting[in_setting["object"] == obj])
            paper_pct = (
                paper.ours[obj][si] if paper and obj in paper.ours and si < len(SETTINGS) else math.nan
            )
            if cell["n"] and obj in in_avg:
                ran_here.append((obj, cell, paper_pct))
            records.append(
                {
                    "object": obj,
                    "label": labels[obj],
                    "mode": mode,
                    "rot": rot,
                    **cell,
                    "paper_pct": paper_pct,
                }
            )
        pooled = _cell(in_setting[in_setting["object"].isin([o for o, _, _ in ran_here])])
        mean = float(np.mean([c["ours_pct"] for _, c, _ in ran_here])) if ran_here else math.nan
        in_area = [c["in_area_pct"] for _, c, _ in ran_here]
        avg = {**pooled, "ours_pct": mean, "in_area_pct": float(np.mean(in_area)) if in_area else math.nan}
        printed = paper.ours_average[si] if paper and si < len(SETTINGS) else math.nan
        same = [p for _, _, p in ran_here if not math.isnan(p)]
        records.append(
            {"object": "", "label": AVERAGE, "mode": mode, "rot": rot, **avg, "paper_pct": printed}
        )
        if paper:
            same_mean = float(np.mean(same)) if same else math.nan
            records.append(
                {"object": "", "label": AVERAGE_SAME, "mode": mode, "rot": rot, **avg, "paper_pct": same_mean}
            )
    cells = pd.DataFrame(records)
    cells["delta_pp"] = cells["ours_pct"] - cells["paper_pct"]
    rows = [labels[o] for o in objects] + [AVERAGE] + ([AVERAGE_SAME] if paper else [])
    baselines = pd.DataFrame()
    if paper and paper.baselines:
        base = {labels[o]: paper.baselines[o] for o in paper_objects}
        base[AVERAGE] = paper.baselines_average
        ran_any = [o for o in paper_objects if o in ran]
        base[AVERAGE_SAME] = tuple(
            float(np.mean([paper.baselines[o][j] for o in ran_any])) if ran_any else math.nan
            for j in range(len(BASELINES))
        )
        baselines = pd.DataFrame.from_dict(base, orient="index", columns=list(BASELINES))
    return SuccessTable(
        dataset=dataset, planner=planner, paper=paper, cells=cells, baselines=baselines, rows=rows
    )


def success_tables(df: pd.DataFrame) -> list[SuccessTable]:
    """One table per (dataset, planner) present: paper datasets first in paper order, then the rest."""
    if df.empty:
        return []
    pairs = list(dict.fromkeys(zip(df["dataset"], df["planner"], strict=True)))
    order = {d: i for i, d in enumerate(PAPER_TABLES)}
    pairs.sort(key=lambda p: (order.get(p[0], len(order)), p[0], p[1]))
    return [success_table(df, d, p) for d, p in pairs]


def setting_label(mode: str, rot: str) -> str:
    return SETTING_LABELS.get((mode, rot), f"{rot.upper()} {mode}")


def wide_numeric(table: SuccessTable) -> pd.DataFrame:
    """The table in the paper's layout with numeric columns (for CSV): one row per row label."""
    cols = ["n", "successes", "ours_pct", "lo_pct", "hi_pct", "in_area_pct", "paper_pct", "delta_pp"]
    parts = []
    for (mode, rot), sub in table.cells.groupby(["mode", "rot"], sort=False):
        part = sub.set_index("label")[cols]
        part.columns = [f"{mode}_{rot}_{c}" for c in cols]
        parts.append(part)
    wide = pd.concat(parts, axis=1).reindex(table.rows)
    obj = table.cells.drop_duplicates("label").set_index("label")["object"]
    wide.insert(0, "object", obj.reindex(table.rows))
    if not table.baselines.empty:
        base = table.baselines.add_suffix(" (paper)")
        wide = pd.concat([wide.iloc[:, :1], base.reindex(table.rows), wide.iloc[:, 1:]], axis=1)
    wide.index.name = "label"
    return wide


def failure_breakdown(df: pd.DataFrame) -> pd.DataFrame:
    """Per setting (dataset, planner, mode, rot): trials, successes, then a count per FailureReason value
    (every value, zeros included; a reason outside the enum gets its own column)."""
    keys = ["dataset", "planner", "mode", "rot"]
    reasons = [r.value for r in FailureReason]
    failed = df[~df["success"]]
    unknown = sorted(set(failed["reason"].fillna("(none)")) - set(reasons))
    out = df.groupby(keys, sort=False).agg(trials=("success", "size"), success=("success", "sum"))
    counts = failed.assign(reason=failed["reason"].fillna("(none)")).pivot_table(
        index=keys, columns="reason", values="trial", aggfunc="count"
    )
    out = (
        out.join(counts.reindex(columns=reasons + unknown))
        if not counts.empty
        else out.reindex(columns=[*out.columns, *reasons, *unknown])
    )
    out = out.fillna(0).astype(int)
    return out.sort_index(level=[0, 1]).reset_index()


STRICT_SLIP_M = 0.02
"""Default slip limit of the report's stricter criterion, m (the earlier default of sim.slip_threshold_m)."""


def strict_table(df: pd.DataFrame, slip_m: float = STRICT_SLIP_M) -> pd.DataFrame:
    """Per setting (dataset, planner, mode, rot): success % by the paper's criterion (still held), by the
    stricter one that also needs the logged slip (``slip_m`` of each trial, m) to be at most ``slip_m``, and
    held with every finger contact in the grasping area (``in_area_pct``, nan when unknown)."""
    keys = ["dataset", "planner", "mode", "rot"]
    slip = pd.to_numeric(df["slip_m"], errors="coerce") if "slip_m" in df else pd.Series(math.nan, df.index)
    strict = df["success"] & (slip <= slip_m)
    groups = df.assign(strict=strict).groupby(keys, sort=False)
    out = groups.agg(trials=("success", "size"), held_pct=("success", "mean"), strict_pct=("strict", "mean"))
    out[["held_pct", "strict_pct"]] *= 100.0
    out["in_area_pct"] = groups.apply(_in_area_pct, include_groups=False)
    return out.sort_index(level=[0, 1]).reset_index()


def runtime_table(df: pd.DataFrame) -> pd.DataFrame:
    """Planner wall time (timings_s.plan) per dataset and overall: p50 / p95 in ms and their ratio to the
    paper's 0.1 s (section IV-F). Trials without a plan timing (e.g. errors before planning) are left out."""
    paper_ms = 1e3 * PLANNER_RUNTIME_S
    rows = []
    groups = [(d, sub) for d, sub in df.groupby("dataset", sort=False)] + [("all", df)]
    for name, sub in groups:
        times = sub["plan_ms"].to_numpy(dtype=float)
        times = times[np.isfinite(times)]
        p50, p95 = percentiles(times)
        rows.append(
            {
                "dataset": name,
                "trials": int(times.size),
                "p50_ms": p50,
                "p95_ms": p95,
                "paper_ms": paper_ms,
                "p50_ratio": p50 / paper_ms,
                "p95_ratio": p95 / paper_ms,
            }
        )
    return pd.DataFrame(rows)
