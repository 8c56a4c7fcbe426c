"""The one results reader: every trial below a run or multirun directory, in one DataFrame.

The MCAP logs are the source of truth: every ``trials/<object>/<NNN>.mcap`` below the directory is read
with :func:`graspexp.record.read_result`, and its pose-noise level (``perception.noise.trans_mm``, mm,
``rot_deg``, degrees; 0 when absent) from the log's recorded config. ``results.csv`` is a cache: it is
read only for a run directory that holds no logs (a run with ``record=false``), with its noise level from
the run's ``.hydra/config.yaml``. A log that cannot be read (truncated, corrupt, an unfinished
``.partial`` file) is never dropped silently: it is returned in :attr:`Collected.unreadable` with the
reason, for the tools to name. The report, the planner comparison, the benchmark and the readings all
read their results here.
"""

from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd
import yaml

from graspexp.config.differences import result_config
from graspexp.core.outcome import result_from_dict
from graspexp.core.run_layout import TRIALS_DIR, hydra_dir, results_tables, trials_dir
from graspexp.record import CorruptLogError, read_result
from graspexp.record.reader import read_metadata
from graspexp.record.writer import PARTIAL_SUFFIX

SETTING_KEYS: tuple[str, ...] = ("dataset", "planner", "mode", "rot")
"""A setting (one table cell column group) is identified by these result fields."""
NOISE_KEYS: tuple[str, ...] = ("trans_mm", "rot_deg")
"""The pose-noise level of a trial's run (``perception.noise``): mm and degrees."""
TRIAL_KEYS: tuple[str, ...] = (*SETTING_KEYS, *NOISE_KEYS, "object", "trial")
"""One trial is identified by these fields."""
FINGERPRINT_COLUMN = "machine"
"""Column of :func:`collect`: where a log was made (:func:`fingerprint`); empty for results.csv rows."""
FINGERPRINT_KEYS = (
    "machine.cpu",
    "machine.cpu_flags_sha256",
    "version.sapien",
    "version.numpy",
    "version.graspexp",
)
CONFIG_COLUMN = "_config"
"""Working column of :func:`collect`: each log's result-affecting config, flattened (dropped before return)."""
"""The runner's per-run cache of its trials' results."""


@dataclass
class Collected:
    """The results read from every trial below a directory."""

    root: Path
    results: pd.DataFrame
    """One row per trial: TrialResult fields, ``plan_ms`` (timings_s.plan in ms), ``trans_mm``,
    ``rot_deg`` and ``path`` (its log; empty for a row read from results.csv)."""
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


def noise_of(config: dict | None) -> tuple[float, float]:
    """(trans_mm, rot_deg) of a job config as a plain dict; 0 for a key it lacks."""
    noise = ((config or {}).get("perception") or {}).get("noise") or {}
    return float(noise.get("trans_mm", 0.0)), float(noise.get("rot_deg", 0.0))


def _row(result: dict, path: Path | str, noise: tuple[float, float]) -> dict:
    row = {k: v for k, v in result.items() if k not in ("timings_s", "finger_force_n")}
    timings = result.get("timings_s") or {}
    plan_s = timings.get("plan")
    row["plan_ms"] = float("nan") if plan_s is None else 1e3 * float(plan_s)
    row["trans_mm"], row["rot_deg"] = noise
    row["path"] = str(path)
    return row


def _log_rows(root: Path) -> tuple[list[dict], list[tuple[Path, str]]]:
    rows, unreadable = [], []
    for path in find_trial_logs(root):
        try:
            result = read_result(path)  # checks the whole file first (magic, CRCs, truncation)
            meta = read_metadata(path) or {}
            config_yaml = meta.get("config_yaml")
            if config_yaml is None:
                raise CorruptLogError(f"{path}: not a graspexp trial log (no graspexp metadata)")
            config = yaml.safe_load(config_yaml)
            if not isinstance(config, dict):
                raise CorruptLogError(f"{path}: its recorded config is not a job config")
            result_from_dict(result)
        except (CorruptLogError, OSError, yaml.YAMLError, ValueError) as exc:
            unreadable.append((path, str(exc) if str(path) in str(exc) else f"{path}: {exc}"))
            continue
        row = _row(result, path, noise_of(config))
        row[CONFIG_COLUMN] = result_config(config)
        row[FINGERPRINT_COLUMN] = fingerprint(meta)
        rows.append(row)
    return rows, unreadable


def _csv_rows(root: Path) -> list[dict]:
    """Rows of every results.csv below ``root`` whose run directory holds no trial log."""
    rows = []
    for table in results_tables(root):
        run_dir = table.parent
        if trials_dir(run_dir).is_dir() and find_trial_logs(run_dir):
            continue
        hydra_cfg = hydra_dir(run_dir) / "config.yaml"
        noise = noise_of(yaml.safe_load(hydra_cfg.read_text())) if hydra_cfg.is_file() else (0.0, 0.0)
        for result in pd.read_csv(table).to_dict("records"):
            timings = result.get("timings_s")
            result["timings_s"] = yaml.safe_load(timings) if isinstance(timings, str) else None
            rows.append(_row(result, "", noise))
    return rows


def collect(root: Path | str) -> Collected:
    """Read every trial below ``root`` (a run directory or a multirun directory): logs first, results.csv
    where a run has none (module doc)."""
    root = Path(root)
    rows, unreadable = _log_rows(root)
    rows += _csv_rows(root)
    df = pd.DataFrame(rows)
    duplicates: list[tuple[Path, Path]] = []
    if not df.empty:
        df["success"] = df["success"].astype(str).str.lower().isin(("true", "1", "1.0"))  # csv rows: text
        df["trial"] = df["trial"].astype(int)
        dup = df.duplicated(list(TRIAL_KEYS), keep="first")
        if dup.any():
            first = df[~dup].set_index(list(TRIAL_KEYS))["path"]
            for _, r in df[dup].iterrows():
                duplicates.append((Path(r["path"]), Path(first.loc[tuple(r[k] for k in TRIAL_KEYS)])))
            df = df[~dup].reset_index(drop=True)
        check_one_config_per_cell(df)
        df = df.drop(columns=CONFIG_COLUMN, errors="ignore")
    return Collected(root=root, results=df, unreadable=unreadable, duplicates=duplicates)


def fingerprint(meta: dict[str, str]) -> str:
    """The machine and library versions a log records (CPU, its flags' hash, SAPIEN, numpy, graspexp), one
    string: results may depend on them, so a report says which it mixes ("unrecorded" for older logs)."""
    values = [meta.get(k) for k in FINGERPRINT_KEYS]
    if all(v is None for v in values):
        return "unrecorded"
    cpu, flags, sapien, numpy, graspexp = (v or "?" for v in values)
    return f"{cpu} (flags {flags}), sapien {sapien}, numpy {numpy}, graspexp {graspexp}"


class MixedConfigError(ValueError):
    """Trials of one table cell were made with two configs (the message is one line naming the keys)."""


def check_one_config_per_cell(df: pd.DataFrame) -> None:
    """Raise :class:`MixedConfigError` if two logs of one cell (:data:`SETTING_KEYS` and
    :data:`NOISE_KEYS`) recorded configs that differ on a key that can change a result and that both
    record (a key only one records came with a newer graspexp: resume already compared it)."""
    if CONFIG_COLUMN not in df:
        return
    logged = df[df[CONFIG_COLUMN].notna()]
    for cell, group in logged.groupby(list(SETTING_KEYS + NOISE_KEYS), sort=False):
        first, first_path = group[CONFIG_COLUMN].iloc[0], group["path"].iloc[0]
        for config, path in zip(group[CONFIG_COLUMN].iloc[1:], group["path"].iloc[1:], strict=True):
            keys = sorted(k for k in first.keys() & config.keys() if first[k] != config[k])
            if keys:
                raise MixedConfigError(
                    f"{'/'.join(map(str, cell))} holds trials of two configs (differing keys: "
                    f"{', '.join(keys[:6])}; {first_path} vs {path}); a table never merges configs: "
                    "report their directories separately"
                )
