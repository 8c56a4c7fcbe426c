"""The names inside a job's run directory (Hydra's output dir) and a sweep directory: their one home.

Run directory::

    trials/<object>/<NNN>.mcap               one log per trial (the source of truth)
    trials/.quarantine/<object>/<name>.<UTC>  files resume moved aside (never deleted)
    results.csv                              one row per trial (rebuilt from the logs and its own rows)
    summary.md                               the per-object success table printed at the end
    run.json                                 what made the tables' rows: config, meshes, clutter pool
    .hydra/{config,hydra,overrides}.yaml     Hydra's record of the accepted run
    .graspexp.lock, .graspexp.lock.holder    the job's lock and who holds it

A sweep directory holds one run directory per job, its lock ``.graspexp-sweep.lock`` and
``.graspexp-failed/`` (one record per failed job).
"""

import errno
import os
from pathlib import Path

from graspexp.core.userinput import check_object_name

TRIALS_DIR = "trials"
"""The folder of a run directory that holds its trial logs, ``trials/<object>/<NNN>.mcap``."""
QUARANTINE_DIR = ".quarantine"
"""Folder of ``trials/`` where resume moves files that are not usable trial logs (never deleted)."""
RESULTS_CSV = "results.csv"
"""One row per trial of the run (:meth:`graspexp.core.outcome.TrialResult.to_dict`)."""
ROUNDS_CSV = "rounds.csv"
"""One row per clutter round of the run (:class:`graspexp.core.rounds.RoundResult`, ``mode=pile``/``packed``)."""
ATTEMPTS_CSV = "attempts.csv"
"""One row per grasp attempt of the run's clutter rounds (:class:`graspexp.core.rounds.AttemptResult`)."""
SUMMARY_MD = "summary.md"
"""The run's per-object success table (markdown)."""
RUN_RECORD = "run.json"
"""What made the rows of the run's tables (:mod:`graspexp.run.run_record`): the config, the meshes, the pool."""
HYDRA_DIR = ".hydra"
"""Hydra's record of an accepted run: ``config.yaml``, ``hydra.yaml``, ``overrides.yaml``."""
HYDRA_FILES = ("config.yaml", "hydra.yaml", "overrides.yaml")
"""The files of :data:`HYDRA_DIR`."""
LOCK_NAME = ".graspexp.lock"
"""Lock file of a run directory (held while a job writes into it)."""
SWEEP_LOCK_NAME = ".graspexp-sweep.lock"
"""Lock file of a sweep directory, held by the process that launches the sweep's jobs."""
FAILED_DIR = ".graspexp-failed"
"""Folder of a sweep directory holding one record per failed job, per sweep id."""


def trials_dir(run_dir: Path | str) -> Path:
    """The folder of the run's trial logs."""
    return Path(run_dir) / TRIALS_DIR


def trial_log_path(run_dir: Path | str, object_name: str, trial: int) -> Path:
    """Where trial ``trial`` of ``object_name`` is logged in ``run_dir``; :class:`UserInputError` for a
    name that is not a valid object name (``..``, ``.quarantine``, a path: it would leave ``trials/``)."""
    return trials_dir(run_dir) / check_object_name(object_name) / f"{trial:03d}.mcap"


def round_log_path(run_dir: Path | str, mode_name: str, round_index: int) -> Path:
    """Where round ``round_index`` of a clutter job is logged in ``run_dir``: ``trials/<mode.name>/NNN.mcap``
    (one folder per clutter mode, beside the objects' folders of single-object runs; :class:`UserInputError`
    for a name that would leave ``trials/``)."""
    return trials_dir(run_dir) / check_object_name(mode_name) / f"{round_index:03d}.mcap"


class LinkedRunPathError(OSError):
    """A folder or file of a run directory is a symbolic link (someone else's file would be written); the
    message is one line naming it."""


def real_folder(run_dir: Path | str, folder: Path) -> Path:
    """``folder`` (``run_dir`` or below it) created where missing, never through a symbolic link: each
    part below ``run_dir`` must be a real folder (``run_dir`` itself may be a link a user made). Raises
    :class:`LinkedRunPathError` naming the link (shared sweep directories are written by several people)."""
    current = Path(run_dir)
    current.mkdir(parents=True, exist_ok=True)
    for part in Path(folder).relative_to(current).parts:
        current = check_not_linked(current / part)
        if current.exists() and not current.is_dir():
            raise NotADirectoryError(errno.ENOTDIR, os.strerror(errno.ENOTDIR), str(current))
        current.mkdir(exist_ok=True)
    return Path(folder)


def check_not_linked(path: Path) -> Path:
    """``path`` if it is not a symbolic link, else :class:`LinkedRunPathError` (a run file about to be opened
    or replaced: replacing a link would be safe, writing through one is not)."""
    if path.is_symlink():
        raise LinkedRunPathError(
            f"{path} is a symbolic link; graspexp writes no run file through a link: remove it or choose "
            "another output directory"
        )
    return path


def quarantine_path(run_dir: Path | str, log: Path, stamp: str) -> Path:
    """Where resume moves the file ``log`` of ``trials/<object>/`` (``stamp``: a UTC time)."""
    return trials_dir(run_dir) / QUARANTINE_DIR / log.parent.name / f"{log.name}.{stamp}"


def results_csv(run_dir: Path | str) -> Path:
    """The run's results table."""
    return Path(run_dir) / RESULTS_CSV


def run_record_path(run_dir: Path | str) -> Path:
    """The run's record of what made its tables' rows (:data:`RUN_RECORD`)."""
    return Path(run_dir) / RUN_RECORD


def summary_md(run_dir: Path | str) -> Path:
    """The run's summary table."""
    return Path(run_dir) / SUMMARY_MD


def hydra_dir(run_dir: Path | str) -> Path:
    """The run's Hydra record folder."""
    return Path(run_dir) / HYDRA_DIR


def results_tables(root: Path | str) -> list[Path]:
    """Every run's ``results.csv`` below ``root`` (a run or a sweep directory), sorted."""
    return sorted(Path(root).rglob(RESULTS_CSV))
