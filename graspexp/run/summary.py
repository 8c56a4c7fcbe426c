"""What a finished job leaves besides its logs: ``results.csv`` (one row per trial), ``summary.md`` (the
per-object success table with what was assumed for each object) and the job's objective value."""

from pathlib import Path

import pandas as pd

from graspexp.core.files import write_atomic
from graspexp.core.outcome import FailureReason, TrialResult
from graspexp.core.run_layout import check_not_linked, results_csv, summary_md
from graspexp.report.collect import ran
from graspexp.run.locks import RunError
from graspexp.run.objects import LoadedObject

OBJECTIVES = {"success": pd.Series.mean, "worst_object": pd.Series.min}
"""How each ``objective`` (:data:`graspexp.config.job.OBJECTIVES`) reduces the per-object success rates."""


NOT_RUN = "not run"
"""How the summary shows the success rate of an object none of whose trials ran to an outcome."""


def summarize(df: pd.DataFrame) -> pd.DataFrame:
    """Per-object trials run, success rate (%) and failure counts (``not_at_rest`` among them), plus an
    Average row over the objects that ran; trials that ended in ``error`` are counted in a ``not_run`` column
    and scored nowhere (an object with none run has success NaN, shown as :data:`NOT_RUN`)."""
    scored = ran(df)
    objects = list(dict.fromkeys(df["object"]))
    g = scored.groupby("object", sort=False)
    table = pd.DataFrame({"trials": g.size(), "success_%": 100.0 * g["success"].mean()}).reindex(objects)
    table["trials"] = table["trials"].fillna(0).astype(int)
    reasons = scored[~scored["success"]].pivot_table(
        index="object", columns="reason", values="trial", aggfunc="count"
    )
    if not reasons.empty:  # objects without any failure count 0 of each reason, also in the Average row
        table = table.join(reasons)
        table[list(reasons.columns)] = table[list(reasons.columns)].fillna(0).astype(int)
    not_run = df.groupby("object", sort=False)["reason"].apply(
        lambda r: int((r == FailureReason.ERROR.value).sum())
    )
    if not_run.any():
        table["not_run"] = not_run.reindex(objects).astype(int)
    table.loc["Average"] = table[table["trials"] > 0].mean(numeric_only=True)
    return table


def summary_markdown(table: pd.DataFrame) -> str:
    """The summary table as markdown, an object none of whose trials ran showing :data:`NOT_RUN`."""
    shown = table.astype(object)
    shown["success_%"] = [NOT_RUN if v != v else f"{v:.3g}" for v in table["success_%"]]
    return shown.to_markdown(floatfmt=".3g")


def object_notes(
    models: dict[str, LoadedObject], unusable: dict[str, str], df: pd.DataFrame | None = None
) -> str:
    """The summary's lines on what was assumed for each object and why an object could not be used, with
    how many of its finished trials (rows of the results table ``df``) were kept ("" when there is nothing
    to say)."""
    lines = [f"- {name}: {'; '.join(o.notes)}" for name, o in models.items() if o.notes]
    for name, why in unusable.items():
        n = 0 if df is None else len(ran(df[df["object"] == name]))
        kept = f" (its {n} finished trial(s) from an earlier run are kept)" if n else ""
        lines.append(f"- {name}: NOT RUN, {why}{kept}")
    return "\n\nObjects:\n" + "\n".join(lines) if lines else ""


def objective_value(df: pd.DataFrame, objective: str) -> float:
    """The job's ``objective`` (see :class:`graspexp.config.JobConfig`) from its results table (one row per
    trial, columns ``object``, ``success`` and ``reason``): a fraction in [0, 1] over the objects that ran
    (:func:`ran`); RunError when none did (no score is made up)."""
    scored = ran(df)
    if scored.empty:
        raise RunError(nothing_ran(df))
    return float(OBJECTIVES[objective](scored.groupby("object", sort=False)["success"].mean()))


def nothing_ran(df: pd.DataFrame) -> str:
    """The one line of a job none of whose trials ran to an outcome: how many, and the first reason."""
    first = df.iloc[0] if len(df) else None
    why = f" (first: {first['object']}: {str(first['error']).splitlines()[0]})" if first is not None else ""
    return (
        f"no trial ran: every one of the {len(df)} trials ended in an error{why}; the objects are listed "
        "as NOT RUN in summary.md"
    )


def write_summary(
    run_dir: Path, results: list[TrialResult], models: dict[str, LoadedObject], unusable: dict[str, str]
) -> tuple[pd.DataFrame, str]:
    """Write ``results.csv`` and ``summary.md`` of ``results`` into ``run_dir``; (the results table, the
    summary's text)."""
    df = pd.DataFrame([r.to_dict() for r in results])
    csv = df.to_csv(index=False).encode()
    text = summary_markdown(summarize(df)) + object_notes(models, unusable, df)
    for path, data in ((results_csv(run_dir), csv), (summary_md(run_dir), (text + "\n").encode())):
        try:  # replaced whole, never written through a link planted in its place
            write_atomic(check_not_linked(path), lambda fh, data=data: fh.write(data))
        except OSError as exc:
            raise RunError(f"cannot write {path}: {exc.strerror or exc}") from None
    return df, text
