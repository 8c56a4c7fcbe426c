"""Success-rate bar charts: ours (with Wilson 95 % interval) beside the paper, per object and setting."""

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from graspexp.report.tables import AVERAGE, SuccessTable, setting_label  # noqa: E402

OURS_COLOUR = "#1f77b4"
PAPER_COLOUR = "#bbbbbb"


def success_chart(table: SuccessTable, path: Path) -> Path:
    """One panel per setting; per object (and Average) a bar for ours with its interval and one for the
    paper. Objects without logs get no 'ours' bar and an 'n/a' mark. Writes a PNG to ``path``."""
    rows = [r for r in table.rows if r in set(table.cells["label"]) and not r.startswith("Paper avg")]
    settings = list(dict.fromkeys(zip(table.cells["mode"], table.cells["rot"], strict=True)))
    ncols = 2 if len(settings) > 1 else 1
    nrows = int(np.ceil(len(settings) / ncols))
    fig, axes = plt.subplots(nrows, ncols, figsize=(6.5 * ncols, 3.2 * nrows), squeeze=False, sharey=True)
    x = np.arange(len(rows))
    has_paper = table.paper is not None
    width = 0.4 if has_paper else 0.7
    for ax, (mode, rot) in zip(axes.flat, settings, strict=False):
        sub = (
            table.cells[(table.cells["mode"] == mode) & (table.cells["rot"] == rot)]
            .set_index("label")
            .reindex(rows)
        )
        ours = sub["ours_pct"].to_numpy(dtype=float)
        err = np.vstack(
            [ours - sub["lo_pct"].to_numpy(dtype=float), sub["hi_pct"].to_numpy(dtype=float) - ours]
        )
        xo = x - width / 2 if has_paper else x
        ax.bar(xo, np.nan_to_num(ours), width, color=OURS_COLOUR, label="ours (95% Wilson CI)")
        ax.errorbar(xo, ours, yerr=np.nan_to_num(err), fmt="none", ecolor="black", capsize=2, lw=0.8)
        for xi, n in zip(xo, sub["n"].fillna(0), strict=True):
            if not n:
                ax.text(xi, 2, "n/a", ha="center", va="bottom", fontsize=7, rotation=90)
        if has_paper:
            ax.bar(
                x + width / 2,
                np.nan_to_num(sub["paper_pct"].to_numpy(dtype=float)),
                width,
                color=PAPER_COLOUR,
                label="paper",
            )
        ax.set_title(setting_label(mode, rot), fontsize=10)
        ax.set_xticks(x, rows, rotation=45, ha="right", fontsize=8)
        ax.set_ylim(0, 105)
        if AVERAGE in rows:  # separate the average from the objects
            ax.axvline(len(rows) - 1.5, color="grey", lw=0.5, ls=":")
        ax.grid(axis="y", alpha=0.3)
    for ax in axes.flat[len(settings) :]:
        ax.axis("off")
    for ax in axes[:, 0]:
        ax.set_ylabel("success rate (%)")
    handles, labels = axes.flat[0].get_legend_handles_labels()
    fig.legend(handles, labels, fontsize=8, loc="upper right", ncol=2, frameon=False)
    title = table.paper.title if table.paper else f"Grasping success rate on {table.dataset}"
    fig.suptitle(f"{title}, planner {table.planner}", fontsize=11, x=0.02, ha="left")
    fig.tight_layout(rect=(0, 0, 1, 0.97))
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path
