"""What a finished job leaves besides its logs: ``results.csv`` (one row per trial), ``summary.md`` (the
per-object success table with what was assumed for each object) and the job's objective value."""

from pathlib import Path

import pandas as pd

from graspexp.core.outcome import TrialResult
from graspexp.core.run_layout import results_csv, summary_md
from graspexp.run.objects import LoadedObject

OBJECTIVES = {"success": pd.Series.mean, "worst_object": pd.Series.min}
"""How each ``objective`` (:data:`graspexp.config.job.OBJECTIVES`) reduces the per-object success rates."""


def summarize(df: pd.DataFrame) -> pd.DataFrame:
    """Per-object success rate (%) and failure counts, plus an Average row."""
    g = df.groupby("object", sort=False)
    table = pd.DataFrame({"trials": g.size(), "success_%": 100.0 * g["success"].mean()})
    reasons = df[~df["success"]].pivot_table(
        index="object", columns="reason", values="trial", aggfunc="count"
    )
    if not reasons.empty:  # objects without any failure count 0 of each reason, also in the Average row
        table = table.join(reasons).fillna(0)
        table[list(reasons.columns)] = table[list(reasons.columns)].astype(int)
    table.loc["Average"] = table.mean(numeric_only=True)
    return table


def object_notes(models: dict[str, LoadedObject], unusable: dict[str, str]) -> str:
    """The summary's lines on what was assumed for each object and why an object could not be used
    ("" when there is nothing to say)."""
    lines = [f"- {name}: {'; '.join(o.notes)}" for name, o in models.items() if o.notes]
    lines += [f"- {name}: NOT RUN, {why}" for name, why in unusable.items()]
    return "\n\nObjects:\n" + "\n".join(lines) if lines else ""


def objective_value(df: pd.DataFrame, objective: str) -> float:
    """The job's ``objective`` (see :class:`graspexp.config.JobConfig`) from its results table (one row per
    trial, columns ``object`` and ``success``): a fraction in [0, 1]."""
    return float(OBJECTIVES[objective](df.groupby("object", sort=False)["success"].mean()))


def write_summary(
    run_dir: Path, results: list[TrialResult], models: dict[str, LoadedObject], unusable: dict[str, str]
) -> tuple[pd.DataFrame, str]:
    """Write ``results.csv`` and ``summary.md`` of ``results`` into ``run_dir``; (the results table, the
    summary's text)."""
    df = pd.DataFrame([r.to_dict() for r in results])
    df.to_csv(results_csv(run_dir), index=False)
    text = summarize(df).to_markdown(floatfmt=".3g") + object_notes(models, unusable)
    summary_md(run_dir).write_text(text + "\n")
    return df, text
