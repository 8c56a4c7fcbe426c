"""Read every trial log below a directory and compare planners on the same drops.

Rows come from :func:`graspexp.report.collect.collect`: each log's ``/result`` and the pose-noise level
of its run (``perception.noise.trans_mm``, mm, and ``perception.noise.rot_deg``, degrees; 0 when absent).

Outputs of :func:`write_comparison` (in ``OUT``):

- ``compare.csv``: one row per (dataset, mode, rot, trans_mm, rot_deg, planner): trials ``n``,
  ``successes``, ``success_pct`` and the Wilson 95 % interval ``ci_lo_pct``, ``ci_hi_pct``;
- ``compare.md``: the same as a table, one row per setting and one column per planner
  (``success % [lo, hi] (n)``), followed by the same-drops check and the list of unreadable logs;
- ``success_vs_noise.png``: success rate (with Wilson intervals) versus ``trans_mm`` and versus
  ``rot_deg``, one line per planner, pooled over datasets, modes, rots and objects; each panel uses
  the trials with the other noise term at 0 when there are any (else all trials).

Same drops: a trial's drop depends only on (global seed, dataset, object, trial index), so every
planner of one setting must show the same ``(trial, seed)`` pairs for each object. Differences are
listed as warnings (on stderr from the CLI, and in the Markdown).
"""

import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import pandas as pd  # noqa: E402

from graspexp.core.outcome import UNPLANNED  # noqa: E402
from graspexp.report.collect import NOISE_KEYS, collect  # noqa: E402
from graspexp.report.stats import success_pct  # noqa: E402

GROUP_KEYS: tuple[str, ...] = ("dataset", "mode", "rot", *NOISE_KEYS)
"""A comparison row: the task and the pose-noise level; one column per planner."""


def collect_trials(root: Path | str) -> tuple[pd.DataFrame, list[str]]:
    """One row per trial below ``root`` (:func:`graspexp.report.collect.collect`), and one warning per
    unreadable or duplicate log.

    Columns: dataset, mode, rot, trans_mm, rot_deg, planner, object, trial, seed, success, reason,
    fc_min_mu, path.
    """
    col = collect(root)
    warnings = [f"unreadable log skipped: {reason}" for _, reason in col.unreadable]
    warnings += [
        f"duplicate trial ignored (same planner, setting, noise, object, trial): {p}"
        for p, _ in col.duplicates
    ]
    cols = [*GROUP_KEYS, "planner", "object", "trial", "seed", "success", "reason", "fc_min_mu", "path"]
    df = col.results.reindex(columns=cols)
    df["fc_min_mu"] = pd.to_numeric(df["fc_min_mu"], errors="coerce")
    return df, warnings


def success_by_noise(df: pd.DataFrame) -> pd.DataFrame:
    """Success per (dataset, mode, rot, trans_mm, rot_deg, planner) with Wilson 95 % bounds, in %."""
    out = []
    for key, g in df.groupby([*GROUP_KEYS, "planner"], sort=True):
        n, k = len(g), int(g["success"].sum())
        pct, lo_pct, hi_pct = success_pct(k, n)
        out.append(
            {
                **dict(zip([*GROUP_KEYS, "planner"], key, strict=True)),
                "n": n,
                "successes": k,
                "success_pct": pct,
                "ci_lo_pct": lo_pct,
                "ci_hi_pct": hi_pct,
            }
        )
    cols = [*GROUP_KEYS, "planner", "n", "successes", "success_pct", "ci_lo_pct", "ci_hi_pct"]
    return pd.DataFrame(out, columns=cols)


FC_MU = 0.8
"""Friction at which "force-closure" is judged in the quality table: PhysX averages the object's 0.6 and
the pads' 1.0 static friction to 0.8 in these simulations."""


def quality_table(df: pd.DataFrame) -> pd.DataFrame:
    """Physics-free grasp quality beside the simulated outcome, per setting and planner: share of planned
    grasps that are force-closure at mu <= FC_MU, median smallest mu, and the simulated success rate of
    the force-closure grasps and of the others (%; NaN where a group is empty)."""
    out = []
    planned = df[~df["reason"].isin(UNPLANNED)]
    for key, g in planned.groupby([*GROUP_KEYS, "planner"], sort=True):
        fc = g["fc_min_mu"] <= FC_MU + 1e-9
        out.append(
            {
                **dict(zip([*GROUP_KEYS, "planner"], key, strict=True)),
                "planned": len(g),
                "fc_pct": 100.0 * fc.mean(),
                "median_mu": float(g["fc_min_mu"].median()),
                "success_if_fc_pct": 100.0 * g.loc[fc, "success"].mean() if fc.any() else float("nan"),
                "success_if_not_fc_pct": 100.0 * g.loc[~fc, "success"].mean()
                if (~fc).any()
                else float("nan"),
            }
        )
    return pd.DataFrame(out)


def check_same_drops(df: pd.DataFrame) -> list[str]:
    """Warnings where the planners of one setting did not run the same (trial, seed) pairs per object.

    Empty when every planner saw the same drops (or only one planner is present).
    """
    warnings = []
    for key, g in df.groupby([*GROUP_KEYS, "object"], sort=True):
        drops = {p: frozenset(zip(s["trial"], s["seed"], strict=True)) for p, s in g.groupby("planner")}
        if len(set(drops.values())) > 1:
            union = frozenset().union(*drops.values())
            detail = "; ".join(f"{p} lacks {len(union - d)}" for p, d in sorted(drops.items()) if union - d)
            setting = ", ".join(f"{k}={v}" for k, v in zip([*GROUP_KEYS, "object"], key, strict=True))
            warnings.append(f"different drops for {setting}: {detail} of {len(union)} (trial, seed) pairs")
    return warnings


def _cell(r: pd.Series) -> str:
    return f"{r.success_pct:.0f} [{r.ci_lo_pct:.0f}, {r.ci_hi_pct:.0f}] ({r.n})"


def render_markdown(table: pd.DataFrame, drop_warnings: list[str], other_warnings: list[str]) -> str:
    """Markdown: settings x planners (``success % [Wilson 95 % lo, hi] (trials)``) and the checks."""
    lines = ["# Planner comparison", ""]
    if table.empty:
        return "\n".join([*lines, "No readable trial logs.", ""])
    planners = sorted(table["planner"].unique())
    header = ["dataset", "mode", "rot", "noise trans mm", "noise rot deg", *planners]
    lines += ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    for key, g in table.groupby(list(GROUP_KEYS), sort=True):
        cells = {r.planner: _cell(r) for r in g.itertuples()}
        vals = [str(key[0]), str(key[1]), str(key[2]), f"{key[3]:g}", f"{key[4]:g}"]
        lines.append("| " + " | ".join([*vals, *(cells.get(p, "-") for p in planners)]) + " |")
    lines += ["", "Cells: success % [Wilson 95 % interval] (trials).", ""]
    if len(planners) < 2:
        lines.append("Same drops: only one planner present, nothing to compare.")
    elif drop_warnings:
        lines.append(
            f"**Warning: the planners did not all run on the same drops** ({len(drop_warnings)} groups):"
        )
        lines += [f"- {w}" for w in drop_warnings]
    else:
        lines.append(
            "Same drops: every planner ran the same (trial, seed) pairs for every object and setting."
        )
    if other_warnings:
        lines += ["", "Other warnings:", *(f"- {w}" for w in other_warnings)]
    return "\n".join(lines) + "\n"


def render_quality(quality: pd.DataFrame) -> str:
    """Markdown of :func:`quality_table`."""
    if quality.empty:
        return ""
    lines = [
        "",
        f"## Grasp quality without physics (force closure at mu <= {FC_MU:g}) beside the simulated outcome",
        "",
        "| dataset | mode | rot | noise trans mm | noise rot deg | planner | planned | force-closure % | "
        "median min mu | success % if FC | success % if not FC |",
        "|" + "---|" * 11,
    ]
    for r in quality.itertuples():
        lines.append(
            f"| {r.dataset} | {r.mode} | {r.rot} | {r.trans_mm:g} | {r.rot_deg:g} | {r.planner} | {r.planned} | "
            f"{r.fc_pct:.0f} | {r.median_mu:.2f} | {r.success_if_fc_pct:.0f} | {r.success_if_not_fc_pct:.0f} |"
        )
    lines += [
        "",
        "min mu: smallest of 0.2, 0.4, ..., 1.2 at which the two finger contacts are force-closure "
        "(NaN: none; excluded from the median).",
        "",
    ]
    return "\n".join(lines)


def _panel(ax, df: pd.DataFrame, key: str, other: str, unit: str) -> None:
    sub = df[df[other] == 0] if (df[other] == 0).any() else df
    for planner, g in sub.groupby("planner", sort=True):
        xs, ys, lo, hi = [], [], [], []
        for level, h in g.groupby(key, sort=True):
            pct, lo_pct, hi_pct = success_pct(int(h["success"].sum()), len(h))
            xs.append(level)
            ys.append(pct)
            lo.append(pct - lo_pct)
            hi.append(hi_pct - pct)
        ax.errorbar(xs, ys, yerr=[lo, hi], marker="o", capsize=3, label=planner)
    note = f"{other} = 0" if sub is not df else f"all {other}"
    ax.set(
        xlabel=f"pose noise {key} ({unit})", ylabel="success (%)", ylim=(-2, 102), title=f"vs {key} ({note})"
    )
    ax.grid(alpha=0.3)


def plot_success_vs_noise(df: pd.DataFrame, path: Path | str) -> None:
    """Two panels: success vs ``trans_mm`` and vs ``rot_deg`` per planner (module doc); PNG at ``path``."""
    fig, axes = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
    if not df.empty:
        _panel(axes[0], df, "trans_mm", "rot_deg", "mm std")
        _panel(axes[1], df, "rot_deg", "trans_mm", "deg std")
        axes[0].legend(fontsize="small")
    fig.savefig(path, dpi=120)
    plt.close(fig)


def write_comparison(root: Path | str, out: Path | str | None = None) -> tuple[str, pd.DataFrame, list[str]]:
    """Collect, tabulate, check and plot; write compare.md, compare.csv, success_vs_noise.png to ``out``
    (default ``<root>/compare``). Returns (markdown, table, same-drop warnings)."""
    root = Path(root)
    out = Path(out) if out is not None else root / "compare"
    df, warnings = collect_trials(root)
    table = success_by_noise(df)
    drops = check_same_drops(df)
    quality = quality_table(df)
    md = render_markdown(table, drops, warnings) + render_quality(quality)
    out.mkdir(parents=True, exist_ok=True)
    table.to_csv(out / "compare.csv", index=False)
    quality.to_csv(out / "quality.csv", index=False)
    (out / "compare.md").write_text(md)
    plot_success_vs_noise(df, out / "success_vs_noise.png")
    for w in [*drops, *warnings]:
        print(f"graspexp compare: warning: {w}", file=sys.stderr)
    return md, table, drops
