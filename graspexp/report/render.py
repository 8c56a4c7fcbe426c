"""Render the report's tables as display DataFrames, Markdown and LaTeX (no jinja2 needed)."""

import math

import pandas as pd

from graspexp.report.paper import TRIALS_PER_SETTING
from graspexp.report.tables import AVERAGE, AVERAGE_SAME, SuccessTable, setting_label

NA = "n/a"
SHORT = {
    ("collab", "z"): "Z-Collab",
    ("collab", "xyz"): "XYZ-Collab",
    ("bin", "z"): "Z-Bin",
    ("bin", "xyz"): "XYZ-Bin",
}
"""Column-name prefixes of the four paper settings (Ours-Z / Ours-XYZ, Collaborative / Bin picking)."""
BASELINE_SHORT = {
    "GPD [18]": "GPD [18]",
    "PointNetGPD 2-class [19]": "PNGPD 2-cl. [19]",
    "PointNetGPD 3-class [19]": "PNGPD 3-cl. [19]",
}


def fmt_pct(v: float, digits: int = 1) -> str:
    """A percentage without trailing zeros: 90, 92.2; n/a for nan."""
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return NA
    text = f"{v:.{digits}f}"
    if "." in text:
        text = text.rstrip("0").rstrip(".")
    return "0" if text == "-0" else text


def fmt_delta(v: float) -> str:
    if v is None or math.isnan(v):
        return NA
    text = fmt_pct(v)
    return text if text.startswith("-") or text == "0" else f"+{text}"


def fmt_paper(v: float) -> str:
    """A paper number as printed (integers without decimals, averages with two)."""
    if v is None or math.isnan(v):
        return "—"
    return f"{v:.0f}" if float(v).is_integer() else f"{v:.2f}"


def fmt_ci(pct: float, lo: float, hi: float) -> str:
    """A success rate with its interval, all in %: ``90 [59.6, 98.2]``."""
    return f"{fmt_pct(pct)} [{fmt_pct(lo)}, {fmt_pct(hi)}]"


def _ours(row: pd.Series) -> str:
    if not row["n"]:
        return NA
    text = fmt_ci(row["ours_pct"], row["lo_pct"], row["hi_pct"])
    if row["label"] in (AVERAGE, AVERAGE_SAME):
        return text
    if row["n"] != TRIALS_PER_SETTING:
        text = f"{text} (n={row['n']})"
    return f"{text} {row['top_reason']}×{row['top_reason_n']}" if row["top_reason_n"] else text


def display_frame(table: SuccessTable) -> pd.DataFrame:
    """Strings in the paper's layout: Object, [paper baselines], then per setting ours / paper / delta."""
    out = pd.DataFrame(index=table.rows)
    out.index.name = "Object"
    if not table.baselines.empty:
        for col in table.baselines.columns:
            out[f"{BASELINE_SHORT.get(col, col)}*"] = [
                fmt_paper(v) for v in table.baselines[col].reindex(table.rows)
            ]
    for (mode, rot), sub in table.cells.groupby(["mode", "rot"], sort=False):
        sub = sub.set_index("label").reindex(table.rows)
        name = SHORT.get((mode, rot), setting_label(mode, rot))
        out[f"{name} ours [95% CI]"] = [_ours(r) for _, r in sub.reset_index().iterrows()]
        out[f"{name} in area"] = [
            NA if not n else fmt_pct(v) for n, v in zip(sub["n"], sub["in_area_pct"], strict=True)
        ]
        if table.paper is not None:
            out[f"{name} paper"] = [fmt_paper(v) for v in sub["paper_pct"]]
            out[f"{name} Δ"] = [
                NA if not n else fmt_delta(d) for n, d in zip(sub["n"], sub["delta_pp"], strict=True)
            ]
    return out


def footnotes(table: SuccessTable) -> list[str]:
    notes = [
        "Success rates in %; ours: successes / trials with the Wilson 95 % score interval in brackets, "
        "then the object's most frequent failure reason × its count (the gallery shows examples); "
        f"(n=...) marks a cell with other than {TRIALS_PER_SETTING} trials; n/a: no logs for that object "
        "and setting (e.g. a missing mesh).",
        "Two criteria side by side: 'ours' is the paper's (IV-C: the object is still held); 'in area' is "
        "held with every finger contact at the end of closing in the object's grasping area (within 5 mm "
        "of a point of its 20 000-point area reference cloud), the task a hand-over grasp serves; n/a "
        "where a log's contacts or the object's mesh could not be read.",
    ]
    if table.paper is not None:
        notes.append(
            f"'paper' columns are copied from the paper's Table {table.paper.number} as printed "
            "(graspexp/report/paper.py); Δ = ours − paper in percentage points."
        )
        if not table.baselines.empty:
            notes.append(
                "* GPD [18] and PointNetGPD (PNGPD) 2-class / 3-class [19]: numbers copied from the paper's "
                "Table 1 as printed, not re-run here."
            )
        notes.append(
            f"'{AVERAGE}' (ours) is the mean over the paper's objects we ran in that setting (interval: "
            f"Wilson over their pooled trials); its paper value is the paper's Average as printed. "
            f"'{AVERAGE_SAME}' compares with the paper's mean over the same objects we ran."
        )
        run = table.cells[(table.cells["object"] != "") & (table.cells["n"] > 0)]["object"]
        missing = [table.paper.labels[o] for o in table.paper.labels if o not in set(run)]
        if missing:
            notes.append(f"No logs for: {', '.join(missing)} (excluded from our averages).")
    else:
        notes.append(
            f"'{AVERAGE}' is the mean over the objects we ran (interval: Wilson over pooled trials)."
        )
    return notes


def markdown(df: pd.DataFrame, index: bool = True) -> str:
    return df.to_markdown(index=index, disable_numparse=True)


_LATEX_ESCAPES = {
    "\\": r"\textbackslash{}",
    "&": r"\&",
    "%": r"\%",
    "$": r"\$",
    "#": r"\#",
    "_": r"\_",
    "{": r"\{",
    "}": r"\}",
    "~": r"\textasciitilde{}",
    "^": r"\textasciicircum{}",
    "Δ": r"$\Delta$",
    "—": "---",
    "−": "-",
}


def latex_escape(text: object) -> str:
    return "".join(_LATEX_ESCAPES.get(ch, ch) for ch in str(text))


def latex(df: pd.DataFrame, caption: str = "", index: bool = True) -> str:
    """A booktabs ``tabular`` (inside a ``table`` with caption) for a frame of strings or numbers, scaled
    down to the text width when wider (``\\resizebox``; needs the booktabs and graphicx packages).

    Written here rather than with pandas ``Styler.to_latex``: that needs jinja2 (a further dependency) and
    leaves the caption unescaped, while planner names in captions carry ``_``."""
    frame = df.reset_index() if index else df
    cols = [latex_escape(c) for c in frame.columns]
    lines = [
        r"\begin{table}[ht]",
        r"\centering",
        rf"\caption{{{latex_escape(caption)}}}" if caption else "",
        r"\resizebox{\ifdim\width>\linewidth\linewidth\else\width\fi}{!}{%",
        r"\begin{tabular}{l" + "r" * (len(cols) - 1) + "}",
        r"\toprule",
        " & ".join(cols) + r" \\",
        r"\midrule",
    ]
    for _, row in frame.iterrows():
        cells = []
        for v in row:
            if isinstance(v, float):
                v = NA if math.isnan(v) else f"{v:.4g}"
            cells.append(latex_escape(v))
        lines.append(" & ".join(cells) + r" \\")
    lines += [r"\bottomrule", r"\end{tabular}}", r"\end{table}"]
    return "\n".join(ln for ln in lines if ln) + "\n"
