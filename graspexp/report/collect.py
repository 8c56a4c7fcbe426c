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

import math
import typing
from dataclasses import dataclass, field
from pathlib import Path

import pandas as pd

from graspexp.config.differences import result_config
from graspexp.core.outcome import FailureReason, TrialResult, result_from_dict
from graspexp.core.run_layout import TRIALS_DIR, hydra_dir, results_tables, trial_log_path, trials_dir
from graspexp.core.userinput import UserInputError, load_user_yaml, read_user_yaml, shown
from graspexp.record import CorruptLogError, read_result, read_round
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
SHAPES_COLUMN = "_shapes"
"""Working column of :func:`collect`: what each log recorded of its object's geometry (:data:`SHAPE_KEYS`)."""
SHAPE_KEYS = ("collision_key", "collision_sha256", "area_sha256")
"""Log metadata naming the collision shape a trial used (its cache key, from the mesh and the method's
parameters, and the SHA-256 of the shape itself) and its grasping area (the SHA-256 of the area mask)."""
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
    not_run: pd.DataFrame = field(default_factory=pd.DataFrame)
    """The trials that ended in ``error`` (an object that could not be used, a trial that raised), in
    :attr:`results`' columns: not run to an outcome, so never scored (no success rate, average, paper
    table or objective counts them); the report lists them as not run."""


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
            config = load_user_yaml(config_yaml, f"{path}: its recorded config")
            if not isinstance(config, dict):
                raise CorruptLogError(f"{path}: its recorded config is not a job config")
            result_from_dict(result)
        except (CorruptLogError, OSError, ValueError) as exc:
            if not is_round_log(path):  # a clutter round's log is read by graspexp.report.round_tables
                unreadable.append((path, str(exc) if str(path) in str(exc) else f"{path}: {exc}"))
            continue
        row = _row(result, path, noise_of(config))
        row[CONFIG_COLUMN] = result_config(config)
        row[SHAPES_COLUMN] = {k: meta[k] for k in SHAPE_KEYS if k in meta}
        row[FINGERPRINT_COLUMN] = fingerprint(meta)
        rows.append(row)
    return rows, unreadable


def is_round_log(path: Path) -> bool:
    """Whether ``path`` is a clutter round's complete log (a /round message in place of /result)."""
    try:
        read_round(path)
    except (CorruptLogError, OSError):
        return False
    return True


def _csv_rows(root: Path) -> tuple[list[dict], list[tuple[Path, str]]]:
    """Rows of every results.csv below ``root`` that no trial log of its run directory holds (a ``record=false``
    run's: the runner keeps them beside logged ones of the same config), each checked as strictly as a log's
    /result (:func:`csv_result`); a table with a bad row is unreadable as a whole (a run with logs: its table
    is their cache, and only rows without a log are read)."""
    rows, unreadable = [], []
    for table in results_tables(root):
        run_dir = table.parent
        logged = trials_dir(run_dir).is_dir() and bool(find_trial_logs(run_dir))
        hydra_cfg = hydra_dir(run_dir) / "config.yaml"
        try:
            config = read_user_yaml(hydra_cfg) if hydra_cfg.is_file() else None
            noise = noise_of(config if isinstance(config, dict) else None)
            records = pd.read_csv(table, dtype=str, keep_default_na=False).to_dict("records")
            results = [
                csv_result(r, f"{table} row {i + 2}")
                for i, r in enumerate(records)
                if not (logged and _has_log(run_dir, r))
            ]
        except (OSError, UnicodeDecodeError, ValueError, pd.errors.ParserError) as exc:
            if not logged:
                unreadable.append((table, str(exc) if str(table) in str(exc) else f"{table}: {exc}"))
            continue
        rows += [_row(result, "", noise) for result in results]
    return rows, unreadable


def _has_log(run_dir: Path, record: dict[str, str]) -> bool:
    """Whether results.csv row ``record`` (text values) is a trial whose log ``run_dir`` holds."""
    try:
        return trial_log_path(run_dir, record.get("object", ""), int(record.get("trial", ""))).is_file()
    except (UserInputError, ValueError):
        return False


def csv_result(record: dict[str, str], where: str) -> dict:
    """One results.csv row (every value the text pandas wrote) as a /result dict, each field converted by
    its type in :class:`TrialResult` (``True``/``False``, integers within 64 bits, numbers, flow-style
    lists and mappings; empty: None) and then checked by :func:`result_from_dict`. ValueError names
    ``where`` and the field."""
    hints = typing.get_type_hints(TrialResult)
    out: dict = {}
    for key, text in record.items():
        if key not in hints:
            continue
        tp = hints[key]
        try:
            out[key] = csv_value(text, tp)
        except ValueError:
            raise ValueError(f"{where}: {key}={shown(text)} is not {tp}") from None
    try:
        result_from_dict(out)
    except ValueError as exc:
        raise ValueError(f"{where}: {exc}") from None
    return out


def csv_value(text: str, tp: object) -> object:
    """``text`` (a value pandas wrote) as type ``tp`` of a result dataclass: ``True``/``False`` only, integers
    within 64 bits, numbers (empty: NaN), text, ``X | None`` (empty: None), flow-style lists and mappings;
    ValueError for text that is not one."""
    optional = type(None) in typing.get_args(tp)  # ``X | None``: empty text is None
    if optional and text == "":
        return None
    base = next(a for a in typing.get_args(tp) if a is not type(None)) if optional else tp
    if base is bool:
        if text not in ("True", "False"):
            raise ValueError(text)
        return text == "True"
    if base is int:
        value = int(text) if len(text) <= 20 else None
        if value is None or not -(2**63) <= value < 2**63:
            raise ValueError(text)
        return value
    if base is float:  # pandas writes NaN as empty text
        if len(text) > 40:
            raise ValueError(text)
        return float(text) if text else math.nan
    if base is str:
        return text
    return load_user_yaml(text, "a results.csv field")  # lists and mappings, in flow style


def collect(root: Path | str) -> Collected:
    """Read every trial below ``root`` (a run directory or a multirun directory): logs first, results.csv
    where a run has none (module doc)."""
    root = Path(root)
    rows, unreadable = _log_rows(root)
    csv_rows, bad_tables = _csv_rows(root)
    rows += csv_rows
    unreadable += bad_tables
    df = pd.DataFrame(rows)
    duplicates: list[tuple[Path, Path]] = []
    not_run = pd.DataFrame()
    if not df.empty:
        df["trial"] = df["trial"].astype(int)
        if "at_rest" in df:  # logs from before not_at_rest existed planned on the moving object
            moving = df["at_rest"].eq(False) & df["reason"].ne(FailureReason.ERROR.value)
            df.loc[moving, ["success", "reason"]] = [False, FailureReason.NOT_AT_REST.value]
        if "registration_fitness" in df:  # logs from before registration_failed planned on a fit to nothing
            unfit = df["registration_fitness"].eq(0.0) & df["reason"].ne(FailureReason.ERROR.value)
            df.loc[unfit, ["success", "reason"]] = [False, FailureReason.REGISTRATION_FAILED.value]
            df.loc[unfit, ["pose_trans_err_mm", "pose_rot_err_deg", "pose_adds_mm"]] = math.nan
        dup = df.duplicated(list(TRIAL_KEYS), keep="first")
        if dup.any():
            first = df[~dup].set_index(list(TRIAL_KEYS))["path"]
            for _, r in df[dup].iterrows():
                duplicates.append((Path(r["path"]), Path(first.loc[tuple(r[k] for k in TRIAL_KEYS)])))
            df = df[~dup].reset_index(drop=True)
        check_one_config_per_cell(df)
        check_one_shape_per_object(df)
        df = df.drop(columns=[CONFIG_COLUMN, SHAPES_COLUMN], errors="ignore")
        scored = ran(df)
        not_run, df = df.drop(scored.index).reset_index(drop=True), scored.reset_index(drop=True)
    return Collected(root=root, results=df, unreadable=unreadable, duplicates=duplicates, not_run=not_run)


def ran(df: pd.DataFrame) -> pd.DataFrame:
    """The trials of a results table that ran to an outcome: all but those that ended in ``error`` (an
    object that could not be used, a trial that raised), which are never scored (no rate, average, paper
    table or objective counts them)."""
    return df[df["reason"] != FailureReason.ERROR.value]


def fingerprint(meta: dict[str, str]) -> str:
    """The machine and library versions a log records (CPU, its flags' hash, SAPIEN, numpy, graspexp), one
    string: results may depend on them, so a report says which it mixes ("unrecorded" for older logs)."""
    values = [meta.get(k) for k in FINGERPRINT_KEYS]
    if all(v is None for v in values):
        return "unrecorded"
    cpu, flags, sapien, numpy, graspexp = (v or "?" for v in values)
    return f"{cpu} (flags {flags}), sapien {sapien}, numpy {numpy}, graspexp {graspexp}"


def check_one_shape_per_object(df: pd.DataFrame) -> None:
    """Raise :class:`MixedConfigError` if two logs built from one cache key (same mesh, method, parameters
    and libraries) used different collision shapes (a cache entry rewritten between them: one of them was
    not what graspexp builds), or if trials of one object in one table cell used different grasping areas
    (an area spec edited between runs). Logs that record neither are not compared."""
    if SHAPES_COLUMN not in df:
        return
    logged = df[df[SHAPES_COLUMN].notna()]
    keys = pd.DataFrame(list(logged[SHAPES_COLUMN]), index=logged.index, columns=list(SHAPE_KEYS))
    checks = (
        (
            "collision_sha256",
            ["collision_key"],
            "collision shapes from one cache key (a rewritten cache entry?)",
        ),
        (
            "area_sha256",
            [*SETTING_KEYS, *NOISE_KEYS, "object"],
            "grasping areas (an area spec edited between runs?)",
        ),
    )
    for column, group_by, what in checks:
        table = pd.concat([logged[["object", "path", *SETTING_KEYS, *NOISE_KEYS]], keys], axis=1)
        table = table[table[column].notna() & table[group_by].notna().all(axis=1)]
        for _, group in table.groupby(group_by, sort=False):
            values = group.drop_duplicates(column)
            if len(values) > 1:
                a, b = values.iloc[0], values.iloc[1]
                raise MixedConfigError(
                    f"trials of {a['object']} used two {what}: {column} {a[column][:12]} in {a['path']}, "
                    f"{b[column][:12]} in {b['path']}; a table never merges them: rerun one of them into a new "
                    "directory with a private cache (GRASPEXP_CACHE)"
                )


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
