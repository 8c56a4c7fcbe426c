"""The run record, ``run.json``: what made the rows of a run directory's tables (``results.csv``,
``rounds.csv``, ``attempts.csv``) that no log backs. A ``record=false`` run leaves such rows; the record says
what made them as a log's metadata would: the job's resolved config, each object's mesh, collision shape and
grasping area (single-object modes) and the clutter pool with its meshes. Every run, logged or not, writes it
once accepted (before its first trial), and every re-run compares it, for those rows, as it compares each
log (:mod:`graspexp.run.resume`): rows of the same config are kept and merged, another config, mesh or pool
is refused. Tables whose rows neither a log nor a record backs (written before graspexp kept the record)
are refused rather than overwritten."""

import json
from pathlib import Path

import pandas as pd
from omegaconf import DictConfig, OmegaConf

from graspexp.core.files import write_atomic
from graspexp.core.outcome import TrialResult, result_from_dict
from graspexp.core.rounds import RoundResult
from graspexp.core.run_layout import (
    ROUNDS_CSV,
    LinkedRunPathError,
    check_not_linked,
    results_csv,
    round_log_path,
    run_record_path,
    trial_log_path,
)
from graspexp.core.userinput import UserInputError, shown
from graspexp.report.collect import csv_result
from graspexp.report.round_csv import rounds_from_csv
from graspexp.run.locks import RunError
from graspexp.run.objects import LoadedObject
from graspexp.run.provenance import object_metadata, pool_metadata, recorded_pool

SCHEMA = "graspexp.RunRecord@1"
"""The record's schema name and version."""
MAX_BYTES = 64 * 2**20
"""A larger ``run.json`` is not read (a record of a few thousand objects is a few MiB)."""


def read_run_record(run_dir: Path | str) -> dict | None:
    """The run record of ``run_dir`` (None when it has none): ``config_yaml`` (str), ``objects`` ({name:
    :func:`graspexp.run.provenance.object_metadata`}) and, for a clutter run, ``round_pool`` (the list of
    :func:`graspexp.run.provenance.pool_metadata`). RunError in one line for a record that is a link, too
    large, or not such a record."""
    path = run_record_path(run_dir)
    try:
        check_not_linked(path)
        if not path.exists():
            return None
        if path.stat().st_size > MAX_BYTES:
            raise ValueError(f"larger than {MAX_BYTES // 2**20} MiB")
        record = json.loads(path.read_bytes())
        if not isinstance(record, dict) or record.get("schema") != SCHEMA:
            raise ValueError(f"no {SCHEMA} schema")
        objects = record.get("objects", {})
        if not isinstance(record.get("config_yaml"), str) or not isinstance(objects, dict):
            raise ValueError("no config_yaml or objects")
        for name, meta in objects.items():
            if not isinstance(meta, dict) or not all(isinstance(v, str) for v in meta.values()):
                raise ValueError(f"the entry of object {shown(name)} is not a mapping of strings")
        recorded_pool(record)  # ValueError for a malformed pool
    except LinkedRunPathError as exc:
        raise RunError(str(exc)) from None
    except (OSError, ValueError, RecursionError) as exc:
        why = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        raise RunError(
            f"{path} is not a graspexp run record ({why}); it says what made the rows of the tables beside it: "
            "choose another output directory, or delete it with the tables it describes"
        ) from None
    return record


def write_run_record(
    cfg: DictConfig, run_dir: Path, models: dict[str, LoadedObject], pool: list[LoadedObject] | None
) -> None:
    """Write ``run_dir``'s record for an accepted run of ``cfg``: the objects of ``models`` (with those an
    earlier record holds that this run does not load and whose rows it keeps) and, for a clutter run,
    ``pool``. Called after the checks (:mod:`graspexp.run.resume`): an earlier record that speaks for rows
    is of the same config."""
    old = read_run_record(run_dir) or {}
    record: dict = {"schema": SCHEMA, "config_yaml": OmegaConf.to_yaml(cfg, resolve=True)}
    if pool is None:
        rows = {name for name, _ in table_results(run_dir)}
        kept = {n: m for n, m in old.get("objects", {}).items() if n in rows}
        record["objects"] = {**kept, **{n: object_metadata(o) for n, o in models.items()}}
    else:
        record["objects"] = {}
        record["round_pool"] = json.loads(pool_metadata(pool))
    data = (json.dumps(record, indent=1) + "\n").encode()
    path = run_record_path(run_dir)
    try:  # replaced whole, never written through a link planted in its place
        write_atomic(check_not_linked(path), lambda fh: fh.write(data))
    except OSError as exc:
        raise RunError(f"cannot write {path}: {exc.strerror or exc}") from None


def table_results(run_dir: Path | str) -> dict[tuple[str, int], TrialResult]:
    """{(object, trial): result} of ``results.csv``'s rows that no trial log backs (those of ``record=false``
    runs), each checked as strictly as a log's /result; {} without a table. RunError naming the file and row
    for one that cannot be read."""
    table = results_csv(run_dir)
    if not table.is_file():
        return {}
    try:
        records = pd.read_csv(table, dtype=str, keep_default_na=False).to_dict("records")
        out = {}
        for i, record in enumerate(records):
            if _has_log(run_dir, record):
                continue  # the log is the trial's result (results.csv is its cache)
            result = result_from_dict(csv_result(record, f"{table} row {i + 2}"))
            out[(result.object, result.trial)] = result
    except pd.errors.EmptyDataError:
        return {}
    except (OSError, UnicodeDecodeError, ValueError, UserInputError, pd.errors.ParserError) as exc:
        raise RunError(_unreadable(table, exc)) from None
    return out


def _has_log(run_dir: Path | str, record: dict[str, str]) -> bool:
    """Whether results.csv row ``record`` (text values) is a trial whose log ``run_dir`` holds."""
    try:
        return trial_log_path(run_dir, record.get("object", ""), int(record.get("trial", ""))).is_file()
    except ValueError:  # not a trial of a valid object name (UserInputError) or index: read as a row
        return False


def table_rounds(run_dir: Path | str) -> dict[int, RoundResult]:
    """{round: result} of ``rounds.csv``'s rows (with their attempts) that no round log backs; {} without a
    table. RunError naming the file for one that cannot be read."""
    table = Path(run_dir) / ROUNDS_CSV
    if not table.is_file():
        return {}
    try:
        rounds = rounds_from_csv(Path(run_dir))
        return {r.round: r for r in rounds if not round_log_path(run_dir, r.mode, r.round).is_file()}
    except pd.errors.EmptyDataError:
        return {}
    except Exception as exc:  # a hand-edited table: any reader error is one line
        raise RunError(_unreadable(table, exc)) from None


def _unreadable(table: Path, exc: BaseException) -> str:
    why = str(exc) if str(table) in str(exc) else f"{table}: {exc}"
    return (
        f"cannot keep the rows of {why}; resume keeps every finished row: repair it, or choose another output "
        "directory"
    )
