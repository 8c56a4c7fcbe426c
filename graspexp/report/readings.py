"""The readings table: each reading of the paper (and each other planner) x the paper's four settings,
per dataset, beside the paper's numbers; and per object the best success any of them reached here.

Each reading is read from its own directory (one config per directory, so no row mixes configs); a
directory whose logs hold two results for one trial, or more than one planner, is refused.
"""

from pathlib import Path

import pandas as pd

from graspexp.report.area_axes import area_axes_frame
from graspexp.report.collect import collect
from graspexp.report.contact_area import held_in_area
from graspexp.report.paper import PAPER_TABLES, SETTING_LABELS, SETTINGS
from graspexp.report.render import SHORT, fmt_ci, fmt_paper, fmt_pct, markdown
from graspexp.report.tables import AVERAGE, AVERAGE_SAME, IN_AREA_COLUMN, success_table

CEILING_KEYS = ("dataset", "object", "mode", "rot")


class MixedConfigError(ValueError):
    """A reading's directory holds results of more than one config."""


def _results(name: str, root: Path, in_area: bool = False) -> pd.DataFrame:
    """The reading's results (:func:`graspexp.report.collect.collect`); ``in_area``: with the second
    criterion read from the logs (none for rows without a log)."""
    col = collect(root)
    df = col.results
    if col.duplicates:
        raise MixedConfigError(
            f"reading {name!r}: {len(col.duplicates)} trials are recorded twice below {root} "
            f"(e.g. {col.duplicates[0][0]}): one directory must hold one config"
        )
    if not df.empty and df["planner"].nunique() > 1:
        raise MixedConfigError(
            f"reading {name!r}: {root} holds planners {sorted(df['planner'].unique())}: one directory per reading"
        )
    if in_area and not df.empty:
        logged = df["path"] != ""
        df[IN_AREA_COLUMN] = None
        if logged.any():
            df.loc[logged, IN_AREA_COLUMN] = held_in_area(df[logged])
    return df


def readings_frame(results: dict[str, tuple[pd.DataFrame, str]]) -> tuple[pd.DataFrame, pd.DataFrame]:
    """(averages, per-object) long tables from the reading directories.

    results : name -> (the reading's results, :func:`_results`, one-line description). averages: one row per (reading, dataset, mode,
    rot) with n, successes, ours_pct, lo_pct, hi_pct (Wilson 95 %, pooled trials), paper_pct (the
    paper's printed average), paper_same_pct (the paper's mean over the objects run) and in_area_pct
    (held with every finger contact in the grasping area, %; nan without logs).
    per-object: one row per (reading, dataset, object, mode, rot) with n and ours_pct.
    """
    avg_rows, obj_rows = [], []
    for name, (df, what) in results.items():
        if df.empty:
            continue
        planner = str(df["planner"].iloc[0])
        for dataset in dict.fromkeys(df["dataset"]):
            table = success_table(df, dataset, planner)
            cells = table.cells
            for _, r in cells[(cells["label"] == AVERAGE) & (cells["n"] > 0)].iterrows():
                same = cells[
                    (cells["label"] == AVERAGE_SAME)
                    & (cells["mode"] == r["mode"])
                    & (cells["rot"] == r["rot"])
                ]
                avg_rows.append(
                    {
                        "reading": name,
                        "what": what,
                        "dataset": dataset,
                        "mode": r["mode"],
                        "rot": r["rot"],
                        "n": int(r["n"]),
                        "successes": int(r["successes"]),
                        "ours_pct": r["ours_pct"],
                        "lo_pct": r["lo_pct"],
                        "hi_pct": r["hi_pct"],
                        "in_area_pct": r["in_area_pct"],
                        "paper_pct": r["paper_pct"],
                        "paper_same_pct": float(same["paper_pct"].iloc[0]) if len(same) else float("nan"),
                    }
                )
            per_obj = cells[(cells["object"] != "") & (cells["n"] > 0)]
            for _, r in per_obj.iterrows():
                obj_rows.append(
                    {"reading": name, "dataset": dataset, "object": r["object"], "label": r["label"]}
                    | {"mode": r["mode"], "rot": r["rot"], "n": int(r["n"]), "ours_pct": r["ours_pct"]}
                )
    return pd.DataFrame(avg_rows), pd.DataFrame(obj_rows)


def _averages_markdown(avg: pd.DataFrame, dataset: str) -> str:
    sub = avg[avg["dataset"] == dataset]
    settings = [s for s in SETTINGS if ((sub["mode"] == s[0]) & (sub["rot"] == s[1])).any()]
    rows = []
    first = sub.drop_duplicates("reading")
    paper = sub.drop_duplicates(["mode", "rot"]).set_index(["mode", "rot"])
    if dataset in PAPER_TABLES:
        rows.append(
            {"reading": "paper (printed average)", "what": ""}
            | {SHORT[s]: fmt_paper(paper.loc[s, "paper_pct"]) for s in settings}
        )
        rows.append(
            {"reading": "paper (same objects as ours)", "what": ""}
            | {SHORT[s]: fmt_paper(round(paper.loc[s, "paper_same_pct"], 2)) for s in settings}
        )
    for _, head in first.iterrows():
        mine = sub[sub["reading"] == head["reading"]].set_index(["mode", "rot"])
        row = {"reading": head["reading"], "what": head["what"]}
        for s in settings:
            row[SHORT[s]] = (
                f"{fmt_ci(*mine.loc[s, ['ours_pct', 'lo_pct', 'hi_pct']])} · {fmt_pct(mine.loc[s, 'in_area_pct'])}"
                if s in mine.index
                else "n/a"
            )
        row["mean of settings"] = (
            f"{fmt_pct(mine['ours_pct'].mean())} · {fmt_pct(mine['in_area_pct'].mean())}"
        )
        row["trials"] = str(int(mine["n"].sum()))  # fewer than the others: a reading still running
        rows.append(row)
    return markdown(pd.DataFrame(rows).fillna(""), index=False)


def ceiling_frame(per_obj: pd.DataFrame, default: str = "default") -> pd.DataFrame:
    """Per (dataset, object, setting): the default reading's success, the best any reading or planner
    reached, and which (ties: the first in the entries' order)."""
    rows = []
    for key, sub in per_obj.groupby(list(CEILING_KEYS), sort=False):
        best = sub.loc[sub["ours_pct"].idxmax()]
        mine = sub[sub["reading"] == default]["ours_pct"]
        rows.append(
            dict(zip(CEILING_KEYS, key, strict=True))
            | {
                "label": best["label"],
                "default_pct": float(mine.iloc[0]) if len(mine) else float("nan"),
                "best_pct": float(best["ours_pct"]),
                "best_by": best["reading"],
            }
        )
    return pd.DataFrame(rows)


def _ceiling_markdown(ceil: pd.DataFrame, dataset: str) -> str:
    sub = ceil[ceil["dataset"] == dataset]
    out = {}
    for (mode, rot), part in sub.groupby(["mode", "rot"], sort=False):
        out[SHORT[(mode, rot)]] = {
            r["label"]: f"{fmt_pct(r['default_pct'])} / {fmt_pct(r['best_pct'])} ({r['best_by']})"
            for _, r in part.iterrows()
        }
    frame = pd.DataFrame(out).reindex(list(dict.fromkeys(sub["label"])))
    frame.index.name = "Object"
    return markdown(frame[[SHORT[s] for s in SETTINGS if SHORT[s] in frame.columns]])


def readings_report(entries: dict[str, tuple[Path, str]], out_dir: Path | str) -> str:
    """Write ``readings.md``, ``readings.csv`` and ``ceiling.csv`` into ``out_dir``; returns the Markdown."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    results = {n: (_results(n, root, in_area=True), what) for n, (root, what) in entries.items()}
    avg, per_obj = readings_frame(results)
    if avg.empty:
        text = "# Readings\n\nNo trial logs in the reading directories.\n"
        (out / "readings.md").write_text(text)
        return text
    avg.to_csv(out / "readings.csv", index=False)
    ceil = ceiling_frame(per_obj)
    ceil.to_csv(out / "ceiling.csv", index=False)
    md = [
        "# Readings of the paper, side by side",
        "",
        "Success rate (%) averaged over the paper's objects that were run, Wilson 95 % interval over the "
        "pooled trials in brackets, then after · the rate held with every finger contact in the grasping "
        "area (n/a without logs); one row per reading (one config, one directory each). Every reading is "
        "a single change from `default` unless it says otherwise; the last rows are other planners on the "
        "same drops.",
        "",
    ]
    for dataset in dict.fromkeys(avg["dataset"]):
        title = PAPER_TABLES[dataset].title if dataset in PAPER_TABLES else dataset
        md += [f"## {dataset}: {title}", "", _averages_markdown(avg, dataset), ""]
        md += [
            f"### {dataset}: per object, default / best of any reading or planner (which)",
            "",
            _ceiling_markdown(ceil, dataset),
            "",
        ]
    if "default" in results:
        md += _area_axes_section(results["default"][0], out)
    text = "\n".join(md)
    (out / "readings.md").write_text(text)
    return text


def _area_axes_section(df: pd.DataFrame, out: Path) -> list[str]:
    """Per object of the ``default`` reading's results ``df``: the area's elongation and the axis
    ``pose_axis`` took (``area_axes.csv``); nothing without logs."""
    frame = area_axes_frame(df[df["path"] != ""]) if not df.empty else pd.DataFrame()
    if frame.empty:
        return []
    frame.to_csv(out / "area_axes.csv", index=False)
    disp = frame.sort_values(["dataset", "elongation"])
    disp = disp.assign(
        elongation=[f"{v:.2f}" for v in disp["elongation"]],
        cos_area_object=[f"{v:.2f}" for v in disp["cos_area_object"]],
    )
    return [
        "## The grasp frame's X per object (`default`)",
        "",
        "Elongation of the grasping area (sqrt(l1 / l2) of its covariance), |cos| of the angle between the "
        "area's and the object's main axes, and the axis `planner.pose_axis` took.",
        "",
        markdown(disp, index=False),
        "",
    ]


def reading_averages(entries: dict[str, tuple[Path, str]]) -> pd.DataFrame:
    """The averages of :func:`readings_frame` of the reading directories ``entries`` (name -> (directory,
    description)), without the in-area criterion (no log is read twice)."""
    return readings_frame({n: (_results(n, root), what) for n, (root, what) in entries.items()})[0]


def beside_paper(avg: pd.DataFrame, reading: str, label: str) -> str:
    """A Markdown table, one row per paper setting: ``reading``'s success (%) on each dataset (columns
    named by ``label``) beside the paper's average over the same objects."""
    sub = avg[avg["reading"] == reading]
    order = list(PAPER_TABLES)
    datasets = sorted(
        dict.fromkeys(sub["dataset"]), key=lambda d: (order.index(d) if d in order else len(order), d)
    )
    rows = []
    for mode, rot in SETTINGS:
        row = {"setting": SETTING_LABELS[(mode, rot)]}
        for dataset in datasets:
            cell = sub[(sub["dataset"] == dataset) & (sub["mode"] == mode) & (sub["rot"] == rot)]
            name = {"ycb": "YCB", "linemod": "LINEMOD"}.get(dataset, dataset)
            row[f"{name} {label}"] = fmt_pct(cell["ours_pct"].iloc[0]) if len(cell) else "n/a"
            row[f"{name} paper"] = fmt_paper(cell["paper_same_pct"].iloc[0]) if len(cell) else "—"
        rows.append(row)
    return markdown(pd.DataFrame(rows), index=False)
