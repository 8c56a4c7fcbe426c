"""Table 1 with the camera in the loop: the paper's objects and settings, the same drops for every column
(the drops derive from the trial seed, not the planner), the measured columns beside the paper's printed
ones. Read from the ``results.csv`` files (or logs) of sweeps (:func:`graspexp.report.collect.collect`).

Columns (:data:`COLUMNS`): ``optimal`` with the exact pose (``perception.source=truth``, no pose noise),
``optimal`` and ``optimal_plus`` with the registered pose (``perception.source=depth`` from a prior:
:func:`_registered`), ``antipodal`` on the full model, ``antipodal_view`` on the camera's cloud only, and
every learned planner installed on the camera's views (:func:`learned_columns`, e.g. ``vgn``); then the
paper's GPD, PointNetGPD 2-class and 3-class (other papers' real robots, copied) and its own column for the
setting.
"""

from collections.abc import Sequence
from pathlib import Path

import numpy as np
import pandas as pd

from graspexp.config.plugins import learned_planners
from graspexp.core.outcome import FailureReason
from graspexp.report.collect import collect
from graspexp.report.paper import BASELINES, SETTING_LABELS, SETTINGS, TABLE1
from graspexp.report.pose_error import success_by_pose_error
from graspexp.report.render import markdown
from graspexp.report.stats import success_pct

COLUMNS = (
    ("optimal", False, "optimal, exact pose"),
    ("optimal", True, "optimal, registered pose"),
    ("optimal_plus", True, "optimal_plus, registered pose"),
    ("antipodal", False, "antipodal, full model"),
    ("antipodal_view", False, "antipodal_view, camera cloud"),
)
"""(planner, registered pose, column label) of the measured columns."""
Column = tuple[str, bool, str]


def learned_columns() -> tuple[Column, ...]:
    """The learned planners' columns, one per installed planner whose plugin declares itself learned
    (:func:`graspexp.config.plugins.learned_planners`), labelled by it
    (:meth:`graspexp.config.plugins.Learned.column_label`). ``results.csv`` does not record the gripper: the
    label states how the results page runs them (the gripper each was trained for, e.g. ``vgn, gripper=panda,
    camera views``)."""
    return tuple((name, False, learned.column_label(name)) for name, learned in learned_planners().items())


def _cell(g: pd.DataFrame) -> str:
    if g.empty:
        return "-"
    rate, lo, hi = success_pct(int(g["success"].sum()), len(g))
    return f"{rate:.0f} ({lo:.0f}-{hi:.0f})" if len(g) > 10 else f"{rate:.0f}"


def _registered(df: pd.DataFrame) -> pd.Series:
    """Trials of the registered columns: a registered pose (finite ``pose_adds_mm``), a registration that
    failed (``registration_failed``: a failure of that column, never of the exact pose's), or a run with a
    prior (``perception.noise`` non-zero: the sweep runs the exact-pose columns without noise), which counts a
    trial whose object fell off the support before any registration too."""
    adds = df["pose_adds_mm"].astype(float) if "pose_adds_mm" in df else pd.Series(np.nan, index=df.index)
    prior = (df.get("trans_mm", 0.0) != 0) | (df.get("rot_deg", 0.0) != 0)
    failed = df["reason"].eq(FailureReason.REGISTRATION_FAILED.value) if "reason" in df else False
    return np.isfinite(adds) | prior | failed


def setting_table(
    results: pd.DataFrame, mode: str, rot: str, columns: Sequence[Column] = COLUMNS
) -> pd.DataFrame:
    """Success % per Table 1 object (rows, the paper's order, and an Average row with the Wilson 95 %
    interval over all its trials) and column of ``columns``, for one setting."""
    df = results[(results["mode"] == mode) & (results["rot"] == rot)]
    registered = _registered(df)
    setting = SETTINGS.index((mode, rot))
    rows = []
    for obj, label in [*TABLE1.labels.items(), ("", "Average")]:
        row = {"object": label}
        on = df if obj == "" else df[df["object"] == obj]
        reg = registered if obj == "" else registered[df["object"] == obj]
        for planner, is_reg, col in columns:
            g = on[(on["planner"] == planner) & (reg == is_reg)]
            row[col] = _cell(g) if obj else _cell(g) + f" n={len(g)}"
        base = TABLE1.baselines_average if obj == "" else TABLE1.baselines[obj]
        ours = TABLE1.ours_average[setting] if obj == "" else TABLE1.ours[obj][setting]
        row.update({f"paper: {b}": f"{v:g}" for b, v in zip(BASELINES, base, strict=True)})
        row["paper: ours"] = f"{ours:g}"
        rows.append(row)
    return pd.DataFrame(rows)


def pose_summary(results: pd.DataFrame) -> pd.DataFrame:
    """Per object (rows) and setting (columns), the registered trials' median ADD-S (mm) and share under
    1 cm."""
    if "pose_adds_mm" not in results:
        return pd.DataFrame()
    df = results[np.isfinite(results["pose_adds_mm"].astype(float))]
    rows = []
    for obj in [*TABLE1.labels, *sorted(set(df["object"]) - set(TABLE1.labels))]:
        row: dict[str, object] = {"object": TABLE1.labels.get(obj, obj)}
        for mode, rot in SETTINGS:
            a = df[(df["object"] == obj) & (df["mode"] == mode) & (df["rot"] == rot)]["pose_adds_mm"].astype(
                float
            )
            label = SETTING_LABELS[(mode, rot)]
            row[label] = (
                f"{a.median():.1f} mm, {100 * (a < 10.0).mean():.0f} % (n={len(a)})" if len(a) else "-"
            )
        rows.append(row)
    return pd.DataFrame(rows)


def pooled_table(results: pd.DataFrame, columns: Sequence[Column] = COLUMNS) -> pd.DataFrame:
    """Per column of ``columns`` (rows): success % over every Table 1 trial of the four settings, its Wilson
    95 % interval and the trial count."""
    df = results[results["object"].isin(list(TABLE1.labels))]
    registered = _registered(df)
    rows = []
    for planner, is_reg, col in columns:
        g = df[(df["planner"] == planner) & (registered == is_reg)]
        rate, lo, hi = success_pct(int(g["success"].sum()), len(g))
        rows.append({"column": col, "trials": len(g), "success %": f"{rate:.1f} ({lo:.1f}-{hi:.1f})"})
    return pd.DataFrame(rows)


def camera_markdown(results: pd.DataFrame, columns: Sequence[Column] = COLUMNS) -> str:
    """The Markdown of the comparison of ``results`` (Table 1's YCB trials of every column): the pooled
    success per column, one table per setting found, the registered pose errors and success against the
    measured pose error."""
    md = [
        "### Pooled over the four settings",
        "",
        markdown(pooled_table(results, columns), index=False),
        "",
    ]
    for mode, rot in SETTINGS:
        if ((results["mode"] == mode) & (results["rot"] == rot)).any():
            md += [
                f"### {SETTING_LABELS[(mode, rot)]}",
                "",
                markdown(setting_table(results, mode, rot, columns), index=False),
                "",
            ]
    summary = pose_summary(results)
    if not summary.empty:
        md += [
            "### Registered pose errors (median ADD-S, share under 1 cm)",
            "",
            markdown(summary, index=False),
            "",
        ]
        md += [
            "### Success against the measured pose error",
            "",
            markdown(success_by_pose_error(results), index=False),
            "",
        ]
    return "\n".join(md)


def camera_comparison(root: Path | str, columns: Sequence[Column] = COLUMNS) -> str:
    """:func:`camera_markdown` of every trial below ``root``."""
    return camera_markdown(collect(root).results, columns)
