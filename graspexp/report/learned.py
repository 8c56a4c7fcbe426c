"""A learned planner (``planner=vgn``) on Table 1's objects and settings, one run per gripper: success per
setting with Wilson intervals beside the paper's printed columns, per object, and the failures by reason.

Each run is a frame of Table 1's trials (:func:`graspexp.report.collect.collect` of one sweep) under a
label that names its gripper (``results.csv`` does not record the gripper; the results page labels its
sweeps). The paper's GPD and PointNetGPD columns are one number per object (no setting): their averages
over Table 1 are shown for every setting.
"""

from collections.abc import Mapping

import pandas as pd

from graspexp.report.paper import BASELINES, SETTING_LABELS, SETTINGS, TABLE1
from graspexp.report.render import markdown
from graspexp.report.stats import success_pct


def _rate(g: pd.DataFrame) -> str:
    """Success % of ``g``'s trials with the Wilson 95 % interval, e.g. ``73.3 [63.4, 81.4]``; ``-`` if none."""
    if g.empty:
        return "-"
    rate, lo, hi = success_pct(int(g["success"].sum()), len(g))
    return f"{rate:.1f} [{lo:.1f}, {hi:.1f}]"


def _table1(df: pd.DataFrame) -> pd.DataFrame:
    return df[df["object"].isin(list(TABLE1.labels))]


def setting_rates(runs: Mapping[str, pd.DataFrame]) -> pd.DataFrame:
    """One row per setting and one over all of them; a column per run (label -> its trials), then the
    paper's printed averages (GPD, PointNetGPD 2- and 3-class, its own planner for the setting)."""
    rows = []
    for k, (mode, rot) in enumerate(SETTINGS):
        row = {"setting": SETTING_LABELS[(mode, rot)]}
        for label, df in runs.items():
            df = _table1(df)
            row[label] = _rate(df[(df["mode"] == mode) & (df["rot"] == rot)])
        row |= {f"paper: {b}*": f"{v:g}" for b, v in zip(BASELINES, TABLE1.baselines_average, strict=True)}
        row["paper: its planner"] = f"{TABLE1.ours_average[k]:g}"
        rows.append(row)
    every = {"setting": "all settings"}
    for label, df in runs.items():
        every[label] = _rate(_table1(df)) + f" (n={len(_table1(df))})"
    rows.append(every | {f"paper: {b}*": "" for b in BASELINES} | {"paper: its planner": ""})
    return pd.DataFrame(rows)


def object_rates(results: pd.DataFrame) -> pd.DataFrame:
    """Success % per Table 1 object (rows) and setting (columns), beside the paper's GPD and PointNetGPD
    3-class numbers for the object."""
    df = _table1(results)
    rows = []
    for obj in TABLE1.labels:
        row = {"object": obj}
        for mode, rot in SETTINGS:
            g = df[(df["object"] == obj) & (df["mode"] == mode) & (df["rot"] == rot)]
            row[SETTING_LABELS[(mode, rot)]] = f"{100 * g['success'].mean():.0f}" if len(g) else "-"
        row[f"paper: {BASELINES[0]}*"] = f"{TABLE1.baselines[obj][0]:g}"
        row[f"paper: {BASELINES[2]}*"] = f"{TABLE1.baselines[obj][2]:g}"
        rows.append(row)
    return pd.DataFrame(rows)


def failure_counts(runs: Mapping[str, pd.DataFrame]) -> pd.DataFrame:
    """Trials per failure reason (rows, the most frequent first) and run (columns)."""
    counts = {
        label: _table1(df).loc[~_table1(df)["success"].astype(bool), "reason"].value_counts()
        for label, df in runs.items()
    }
    table = pd.DataFrame(counts).fillna(0).astype(int)
    table = table.loc[table.sum(axis=1).sort_values(ascending=False, kind="stable").index]
    return table.rename_axis("reason").reset_index()


def learned_markdown(runs: Mapping[str, pd.DataFrame]) -> str:
    """The Markdown of :func:`setting_rates`, :func:`object_rates` per run and :func:`failure_counts`."""
    md = [
        "### Success per setting",
        "",
        markdown(setting_rates(runs), index=False),
        "",
        "\\* one number per object in the paper (no setting), averaged over Table 1; measured by their "
        "authors on their robots, not here.",
        "",
    ]
    for label, df in runs.items():
        md += [f"### Per object: {label}", "", markdown(object_rates(df), index=False), ""]
    md += ["### Failures by reason", "", markdown(failure_counts(runs), index=False), ""]
    return "\n".join(md)
