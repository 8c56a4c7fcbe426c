"""Hydra's submitit launchers (``hydra/launcher=submitit_slurm`` / ``submitit_local``): a task that ends
without a result (cancelled with ``scancel``, killed, out of time, node lost) or that raised stops the
submitting process with one line naming the task, its state and the fix, instead of submitit's multi-line
traceback. Its finished trials, and those of every other task, stay in the sweep directory; the same
command again resumes them.

Hydra only instantiates launchers from its ``hydra_plugins`` package and prints any exception a launcher
raises as a traceback; so :func:`submitit_guard` lets the exception through Hydra (``HYDRA_FULL_ERROR``)
for submitit sweeps only and turns it into the line.
"""

from __future__ import annotations

import os
import re
import sys
from collections.abc import Iterator, Sequence
from contextlib import contextmanager

from graspexp.run.jobs import release_sweep_locks

_JOB = re.compile(r"Job (\S+) \(task: \d+\)")
_STATE = re.compile(r"state: ([A-Z_]+)")


def task_failure(text: str, failed: bool) -> str:
    """The one line for a task that produced no result; ``text`` is submitit's message, ``failed`` whether
    the task raised (``FailedJobError``) rather than ended without output (``UncompletedJobError``)."""
    job = _JOB.search(text)
    where = f"task {job.group(1)}" if job else "a task"
    if failed:
        last = next((ln.strip() for ln in reversed(text.splitlines()) if ln.strip()), "an error")
        what = f"{where} failed ({last}); its log is under the sweep directory's .submitit/"
    else:
        state = _STATE.search(text)
        what = f"{where} ended without a result (state {state.group(1) if state else 'unknown'})"
    return (
        f"{what}. The sweep stopped waiting; the trials every task finished are kept: run the same command "
        "again to resume (finished trials are not run again)"
    )


@contextmanager
def submitit_guard(overrides: Sequence[str]) -> Iterator[None]:
    """Around a Hydra multirun: when ``overrides`` choose a submitit launcher, a task without a result ends
    the process with :func:`task_failure`'s line and exit status 2 (the sweep locks released)."""
    if not any(o.startswith("hydra/launcher=submitit") for o in overrides):
        yield
        return
    from submitit.core.utils import FailedJobError, UncompletedJobError

    os.environ.setdefault("HYDRA_FULL_ERROR", "1")  # Hydra re-raises instead of printing a traceback
    try:
        yield
    except UncompletedJobError as exc:
        release_sweep_locks()
        print(f"graspexp: error: {task_failure(str(exc), isinstance(exc, FailedJobError))}", file=sys.stderr)
        raise SystemExit(2) from None
