"""Agreement with the paper, per object and setting: ours (k/n) beside the paper (k/10), Fisher's exact test.

Each cell of a paper table (object x setting) is a 2x2 table: our successes and failures against the
paper's (its printed rate x :data:`~graspexp.report.paper.TRIALS_PER_SETTING` trials). ``p_below`` is
Fisher's exact one-sided p-value for "ours succeeds less often than the paper" (scipy's
``fisher_exact(..., alternative="less")``); a cell is *flagged* when ``p_below < ALPHA``. One row per
setting pools the paper objects we ran (ours: every trial; the paper: its printed rates of the same
objects x 10). The paper's 10-trial numbers stay the comparison whatever our trial count.
"""

from dataclasses import dataclass
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
from scipy.stats import fisher_exact  # noqa: E402

from graspexp.report.paper import TRIALS_PER_SETTING  # noqa: E402
from graspexp.report.tables import AVERAGE, SuccessTable, setting_label  # noqa: E402

ALPHA = 0.05
"""One-sided significance level of a flag."""
POOLED = "All objects (pooled)"
"""Label of the per-setting pooled row."""


def p_below(ours_k: int, ours_n: int, paper_k: int, paper_n: int = TRIALS_PER_SETTING) -> float:
    """Fisher's exact one-sided p-value that our success rate ``ours_k / ours_n`` is below the paper's
    ``paper_k / paper_n``; 1.0 when either has no trials."""
    if ours_n <= 0 or paper_n <= 0:
        return 1.0
    table = [[ours_k, ours_n - ours_k], [paper_k, paper_n - paper_k]]
    return float(fisher_exact(table, alternative="less").pvalue)


@dataclass
class Agreement:
    """The agreement table of one paper table (dataset and planner) and its one-line summary."""

    dataset: str
    planner: str
    cells: pd.DataFrame
    """One row per (setting, object) with logs, then the setting's pooled row: setting, mode, rot,
    object, label, ours_k, ours_n, ours_pct, paper_k, paper_n, paper_pct, diff_pp (ours - paper),
    p_below, flagged, top_reason (the cell's most frequent failure reason)."""

    @property
    def objects(self) -> pd.DataFrame:
        return self.cells[self.cells["object"] != ""]

    @property
    def name(self) -> str:
        return f"agreement_{self.dataset}_{self.planner}"

    def summary(self) -> str:
        """One line: flagged cells / cells, mean absolute difference, flagged settings."""
        obj = self.objects
        pooled = self.cells[self.cells["object"] == ""]
        flagged_settings = ", ".join(pooled.loc[pooled["flagged"], "setting"]) or "none"
        return (
            f"{self.dataset} / {self.planner}: {int(obj['flagged'].sum())} of {len(obj)} object cells "
            f"significantly below the paper (one-sided Fisher p < {ALPHA:g}); mean |ours - paper| "
            f"{obj['diff_pp'].abs().mean():.1f} points; settings significantly below: {flagged_settings}"
        )


def agreement(table: SuccessTable) -> Agreement | None:
    """The agreement table of a success table that reproduces a paper table (None for other datasets)."""
    if table.paper is None:
        return None
    cells = table.cells
    rows = []
    for (mode, rot), sub in cells.groupby(["mode", "rot"], sort=False):
        setting = setting_label(mode, rot)
        ran = sub[(sub["object"] != "") & (sub["n"] > 0) & sub["paper_pct"].notna()]
        for _, c in ran.iterrows():
            paper_k = int(round(c["paper_pct"] / 100.0 * TRIALS_PER_SETTING))
            rows.append(
                _row(
                    setting,
                    mode,
                    rot,
                    c["object"],
                    c["label"],
                    int(c["successes"]),
                    int(c["n"]),
                    paper_k,
                    TRIALS_PER_SETTING,
                    c["top_reason"],
                )
            )
        if len(ran):
            paper_k = int(sum(round(p / 100.0 * TRIALS_PER_SETTING) for p in ran["paper_pct"]))
            avg = sub[sub["label"] == AVERAGE].iloc[0]
            rows.append(
                _row(
                    setting,
                    mode,
                    rot,
                    "",
                    POOLED,
                    int(ran["successes"].sum()),
                    int(ran["n"].sum()),
                    paper_k,
                    TRIALS_PER_SETTING * len(ran),
                    avg["top_reason"],
                )
            )
    return Agreement(table.dataset, table.planner, pd.DataFrame(rows))


def _row(setting, mode, rot, obj, label, k, n, paper_k, paper_n, reason) -> dict:
    p = p_below(k, n, paper_k, paper_n)
    return {
        "setting": setting,
        "mode": mode,
        "rot": rot,
        "object": obj,
        "label": label,
        "ours_k": k,
        "ours_n": n,
        "ours_pct": 100.0 * k / n,
        "paper_k": paper_k,
        "paper_n": paper_n,
        "paper_pct": 100.0 * paper_k / paper_n,
        "diff_pp": 100.0 * (k / n - paper_k / paper_n),
        "p_below": p,
        "flagged": p < ALPHA,
        "top_reason": reason if k < n else "",
    }


def example_trials(ag: Agreement, results: pd.DataFrame) -> dict[tuple[str, str, str], pd.Series]:
    """For each flagged object cell, the failed trial (lowest index) of its most frequent failure reason:
    ``(mode, rot, object) -> results row`` (``results`` as collected, with ``path``)."""
    out = {}
    for _, c in ag.objects[ag.objects["flagged"]].iterrows():
        sel = results[
            (results["dataset"] == ag.dataset)
            & (results["planner"] == ag.planner)
            & (results["mode"] == c["mode"])
            & (results["rot"] == c["rot"])
            & (results["object"] == c["object"])
            & ~results["success"].astype(bool)
            & (results["reason"].fillna("(none)") == c["top_reason"])
        ].sort_values("trial")
        if len(sel):
            out[(c["mode"], c["rot"], c["object"])] = sel.iloc[0]
    return out


def agreement_chart(ag: Agreement, path: Path) -> Path:
    """Ours against the paper per object cell (one marker per cell and setting; flagged cells in red,
    the pooled rows as squares), with the line of equality. Writes a PNG to ``path``."""
    fig, ax = plt.subplots(figsize=(5, 5))
    jitter = np.linspace(-1.5, 1.5, max(ag.cells["setting"].nunique(), 1))
    for j, (setting, sub) in enumerate(ag.cells.groupby("setting", sort=False)):
        obj = sub[sub["object"] != ""]
        pooled = sub[sub["object"] == ""]
        colours = np.where(obj["flagged"], "#d62728", "#1f77b4")
        ax.scatter(
            obj["paper_pct"] + jitter[j], obj["ours_pct"], c=colours, s=18, alpha=0.7, marker="o", label=None
        )
        ax.scatter(
            pooled["paper_pct"],
            pooled["ours_pct"],
            marker="s",
            s=40,
            edgecolors="k",
            label=f"{setting} (pooled)",
        )
    ax.plot([0, 100], [0, 100], color="#888888", linewidth=1)
    ax.set_xlim(-5, 105)
    ax.set_ylim(-5, 105)
    ax.set_xlabel("paper (%)")
    ax.set_ylabel("ours (%)")
    ax.set_title(f"{ag.dataset} / {ag.planner}: red = significantly below the paper", fontsize=9)
    ax.legend(fontsize=7, loc="lower right")
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path
