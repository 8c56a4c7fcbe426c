"""What a Hydra job of ``python -m graspexp`` reports beyond its table: its directory name, and why it
could not run.

- Job directory names (``hydra.sweep.subdir``): :func:`job_dir_name` of the job's overrides, short enough
  for any sweep (a long value becomes its head plus a hash), stable from run to run so resume finds them.
- A job that cannot run (missing data, unwritable or locked directory, logs of another config) prints one
  line and, in a multirun, leaves a record that :class:`SweepReport` turns into a one-line-per-job summary
  and a non-zero exit when the sweep ends; the other jobs run on. The same holds with the basic launcher
  (jobs in this process) and with joblib or submitit (jobs in other processes or on other hosts: the
  records live in the sweep directory, tagged with an id this sweep passes on in the environment).
"""

from __future__ import annotations

import hashlib
import os
import sys
import tempfile
import time
import uuid
from pathlib import Path
from typing import Any

from hydra.core.hydra_config import HydraConfig
from hydra.experimental.callback import Callback
from hydra.types import RunMode
from omegaconf import DictConfig, OmegaConf

from graspexp.core.run_layout import FAILED_DIR, SWEEP_LOCK_NAME
from graspexp.run.locks import DirectoryLock, RunError

SWEEP_ID_ENV = "GRASPEXP_SWEEP_ID"
"""Environment variable naming the running multirun (set by :class:`SweepReport`, inherited by jobs)."""
MAX_VALUE_CHARS = 32
"""An override value longer than this shows as its head plus a hash in the job directory name."""
MAX_NAME_CHARS = 120
"""A job directory name longer than this is cut and ends in a hash of the whole (file systems allow 255 bytes)."""
HASH_CHARS = 8


def _digest(text: str) -> str:
    return hashlib.sha256(text.encode()).hexdigest()[:HASH_CHARS]


def job_dir_name(overrides: list[str], exclude_keys: list[str]) -> str:
    """A short, readable, unique directory name for a job: its ``key=value`` overrides sorted and joined
    by commas, without ``exclude_keys``; a value over :data:`MAX_VALUE_CHARS` becomes ``head~hash``, a
    name over :data:`MAX_NAME_CHARS` ``head~hash``, and ``/`` becomes ``_`` (one directory level)."""
    items = []
    for item in sorted(str(o) for o in overrides):
        key, _, value = item.partition("=")
        if key.lstrip("+~") in exclude_keys:
            continue
        if len(value) > MAX_VALUE_CHARS:
            value = f"{value[: MAX_VALUE_CHARS - HASH_CHARS - 1]}~{_digest(value)}"
        items.append(f"{key}={value}".replace("/", "_"))
    name = ",".join(items) or "default"
    if len(name) > MAX_NAME_CHARS:
        name = f"{name[: MAX_NAME_CHARS - HASH_CHARS - 1]}~{_digest(name)}"
    return name


def register_resolvers() -> None:
    """``${graspexp.job_dir:${hydra.overrides.task},${...exclude_keys}}`` (see :func:`job_dir_name`) and
    ``${graspexp.g:${x}}`` (a number as Python's ``{:g}`` writes it, for directory names)."""
    OmegaConf.register_new_resolver(
        "graspexp.job_dir",
        lambda overrides, exclude: job_dir_name(list(overrides), list(exclude)),
        replace=True,
    )
    OmegaConf.register_new_resolver("graspexp.g", lambda x: f"{float(x):g}", replace=True)


register_resolvers()  # job processes of joblib/submitit import this module with the pickled callback


def job_failed(message: str) -> None:
    """Report that this job cannot run. A single run prints ``graspexp: error: <message>`` and exits 2; a
    multirun job prints it with its directory, records it for the sweep summary and returns."""
    hc = HydraConfig.get()
    job_dir = Path(hc.runtime.output_dir)
    _remove_if_empty(job_dir)  # Hydra made it for this job; a refused job leaves nothing behind
    if hc.mode != RunMode.MULTIRUN:
        print(f"graspexp: error: {message}", file=sys.stderr)
        raise SystemExit(2)
    print(f"graspexp: error: job {job_dir.name}: {message}", file=sys.stderr)
    folder = job_dir.parent / FAILED_DIR / os.environ.get(SWEEP_ID_ENV, "unknown")
    try:
        folder.mkdir(parents=True, exist_ok=True)
        (folder / f"{hc.job.num:05d}.txt").write_text(f"{job_dir.name}: {message}\n")
    except OSError as exc:  # the summary will lack this job; its own line above says why
        print(f"graspexp: error: cannot record the failure of job {job_dir.name}: {exc}", file=sys.stderr)


def _remove_if_empty(folder: Path) -> None:
    try:
        folder.rmdir()  # only succeeds for an empty folder
    except OSError:
        pass


def writable_dir_problem(path: Path) -> str | None:
    """Why files cannot be created under ``path`` (tried in its nearest existing ancestor), or None."""
    probe = path.absolute()
    while not probe.exists():
        probe = probe.parent
    if not probe.is_dir():
        return f"{probe} is not a directory"
    try:
        with tempfile.TemporaryFile(dir=probe) as f:
            f.write(b"x")
            f.flush()
            os.fsync(f.fileno())
    except OSError as exc:
        return f"{probe} is not writable ({exc.strerror or exc})"
    return None


_SWEEP_LOCKS: dict[str, DirectoryLock] = {}
"""The sweep locks this process holds, by sweep directory (not on the callback: joblib pickles it)."""


def release_sweep_locks(sweep_dir: str | None = None) -> None:
    """Release this process's lock of ``sweep_dir`` (None: of every sweep it holds): the sweep ends."""
    for held in [str(sweep_dir)] if sweep_dir is not None else list(_SWEEP_LOCKS):
        lock = _SWEEP_LOCKS.pop(held, None)
        if lock is not None:
            lock.release()


class SweepReport(Callback):
    """Hydra callback (``hydra.callbacks`` in ``conf/config.yaml``): checks the output folder before Hydra
    writes into it, and ends a multirun with the summary of the jobs that could not run."""

    def _check_output(self, path: str) -> None:
        problem = writable_dir_problem(Path(path))
        if problem:
            print(f"graspexp: error: cannot write the output directory {path}: {problem}", file=sys.stderr)
            raise SystemExit(2)

    def on_run_start(self, config: DictConfig, **kwargs: Any) -> None:
        self._check_output(config.hydra.run.dir)

    def on_multirun_start(self, config: DictConfig, **kwargs: Any) -> None:
        self._check_output(config.hydra.sweep.dir)
        lock = DirectoryLock(Path(config.hydra.sweep.dir), SWEEP_LOCK_NAME, "sweep")
        try:  # the sweep owns its directory: a second sweep into it is refused before any job runs
            lock.acquire()
            _SWEEP_LOCKS[str(config.hydra.sweep.dir)] = lock
        except RunError as exc:
            print(f"graspexp: error: {exc}", file=sys.stderr)
            raise SystemExit(2) from None
        os.environ[SWEEP_ID_ENV] = uuid.uuid4().hex
        self._started = time.perf_counter()

    def on_multirun_end(self, config: DictConfig, **kwargs: Any) -> None:
        release_sweep_locks(config.hydra.sweep.dir)
        wall = time.perf_counter() - getattr(self, "_started", time.perf_counter())
        print(f"\ngraspexp: sweep {config.hydra.sweep.dir} done in {wall:.1f} s wall", file=sys.stderr)
        folder = Path(config.hydra.sweep.dir) / FAILED_DIR / os.environ.get(SWEEP_ID_ENV, "unknown")
        records = sorted(folder.glob("*.txt")) if folder.is_dir() else []
        lines = [r.read_text().strip() for r in records]
        for r in records:
            r.unlink()
        for empty in (folder, folder.parent):
            if empty.is_dir() and not any(empty.iterdir()):
                empty.rmdir()
        if lines:
            print(f"graspexp: {len(lines)} job(s) of the sweep failed:", file=sys.stderr)
            for line in lines:
                print(f"  {line}", file=sys.stderr)
            raise SystemExit(1)
