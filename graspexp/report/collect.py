"""Find the trial logs below a run or multirun directory and read their results into one DataFrame.

The MCAP logs are the source of truth (``results.csv`` in a run directory is only a cache): every
``trials/<object>/<NNN>.mcap`` below the directory is read with :func:`graspexp.record.read_result`.
A log that cannot be read (truncated, corrupt, an unfinished ``.partial`` file) is never dropped
silently: it is returned in :attr:`Collected.unreadable` with the reason, for the report to name.
"""

from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from graspexp.record import TRIALS_DIR, CorruptLogError, read_result
from graspexp.record.writer import PARTIAL_SUFFIX

SETTING_KEYS: tuple[str, ...] = ("dataset", "planner", "mode", "rot")
"""A setting (one table cell column group) is identified by these result fields."""
TRIAL_KEYS: tuple[str, ...] = (*SETTING_KEYS, "object", "trial")
"""One trial is identified by these result fields."""


@dataclass
class Collected:
    """The results read from every trial log below a directory."""

    root: Path
    results: pd.DataFrame
    """One row per readable log: TrialResult fields, ``plan_ms`` (timings_s.plan in ms) and ``path``."""
    unreadable: list[tuple[Path, str]] = field(default_factory=list)
    """(path, reason) for each log that could not be read."""
    duplicates: list[tuple[Path, Path]] = field(default_factory=list)
    """(ignored log, kept log) for trials logged twice below the root (same TRIAL_KEYS)."""


def find_trial_logs(root: Path | str) -> list[Path]:
    """Every ``*.mcap`` (and unfinished ``*.mcap.partial``) file in a ``trials`` folder below ``root``."""
    root = Path(root)
    found = set()
    for pattern in ("*.mcap", f"*.mcap{PARTIAL_SUFFIX}"):
        found.update(
            p for p in root.rglob(pattern) if p.is_file() and TRIALS_DIR in p.relative_to(root).parts[:-1]
        )
    return sorted(found)


def _row(result: dict, path: Path) -> dict:
    row = {k: v for k, v in result.items() if k not in ("timings_s", "finger_force_n")}
    timings = result.get("timings_s") or {}
    plan_s = timings.get("plan")
    row["plan_ms"] = float("nan") if plan_s is None else 1e3 * float(plan_s)
    row["path"] = str(path)
    return row


def collect(root: Path | str) -> Collected:
    """Read the result of every trial log below ``root`` (a run directory or a multirun directory)."""
    root = Path(root)
    rows, unreadable = [], []
    for path in find_trial_logs(root):
        try:
            result = read_result(path)
            missing = [k for k in (*TRIAL_KEYS, "success") if k not in result]
            if missing:
                raise CorruptLogError(f"{path}: /result lacks {missing}")
        except (CorruptLogError, OSError) as exc:
            unreadable.append((path, str(exc)))
            continue
        rows.append(_row(result, path))
    df = pd.DataFrame(rows)
    duplicates: list[tuple[Path, Path]] = []
    if not df.empty:
        df["success"] = df["success"].astype(bool)
        df["trial"] = df["trial"].astype(int)
        dup = df.duplicated(list(TRIAL_KEYS), keep="first")
        if dup.any():
            first = df[~dup].set_index(list(TRIAL_KEYS))["path"]
            for _, r in df[dup].iterrows():
                duplicates.append((Path(r["path"]), Path(first.loc[tuple(r[k] for k in TRIAL_KEYS)])))
            df = df[~dup].reset_index(drop=True)
    return Collected(root=root, results=df, unreadable=unreadable, duplicates=duplicates)
