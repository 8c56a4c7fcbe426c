"""Success against the measured pose error of trials whose pose was registered from the depth camera
(``perception.source=depth``): the trials binned by ADD-S, per planner, with Wilson intervals."""

import numpy as np
import pandas as pd

from graspexp.report.stats import success_pct

ADDS_BINS_MM = (0.0, 2.0, 5.0, 10.0, 20.0, np.inf)
"""Edges of the ADD-S bins, mm (1 cm: the usual YCB-Video threshold of a correct pose)."""


def success_by_pose_error(results: pd.DataFrame) -> pd.DataFrame:
    """One row per planner and ADD-S bin with trials: ``planner``, ``ADD-S mm`` (the bin), ``trials``,
    ``success %`` and its Wilson 95 % interval ``lo %`` / ``hi %``, the bin's median translation (mm) and
    rotation (deg) errors. Empty when no trial registered a pose (or the column is absent: older logs)."""
    if "pose_adds_mm" not in results or not np.isfinite(results["pose_adds_mm"].astype(float)).any():
        return pd.DataFrame()
    df = results[np.isfinite(results["pose_adds_mm"].astype(float))]
    edges = list(ADDS_BINS_MM)
    labels = [
        f"{a:g}-{b:g}" if np.isfinite(b) else f">= {a:g}" for a, b in zip(edges, edges[1:], strict=False)
    ]
    binned = pd.cut(df["pose_adds_mm"].astype(float), edges, right=False, labels=labels)
    rows = []
    for (planner, label), g in df.groupby([df["planner"], binned], observed=True):
        rate, lo, hi = success_pct(int(g["success"].sum()), len(g))
        rows.append(
            {
                "planner": planner,
                "ADD-S mm": label,
                "trials": len(g),
                "success %": round(rate, 1),
                "lo %": round(lo, 1),
                "hi %": round(hi, 1),
                "trans mm (median)": round(float(g["pose_trans_err_mm"].median()), 1),
                "rot deg (median)": round(float(g["pose_rot_err_deg"].median()), 1),
            }
        )
    return pd.DataFrame(rows)
