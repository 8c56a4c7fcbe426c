"""Who writes into a directory: one job per job directory, one sweep per sweep directory.

The lock is flock(2) through ``filelock`` (the kernel drops it when the holder dies, kill -9 included;
Linux maps it to POSIX locks on NFS, so it holds across a cluster's nodes). Beside it a holder file names
the holding process, for the message a second writer gets; it is removed on release.
"""

from __future__ import annotations

import datetime
import os
import socket
import sys
from pathlib import Path

from filelock import FileLock, Timeout

from graspexp.core.files import write_atomic


class RunError(RuntimeError):
    """A job that cannot run as asked: a missing or unreadable input, an unwritable output folder, a
    directory held by another run or holding logs of another config. The message is one line."""


class DirectoryLock:
    """The exclusive lock of ``folder`` (file ``lock_name`` in it) for a ``what`` ("run", "sweep"); usable
    as a context manager or with :meth:`acquire` / :meth:`release`."""

    def __init__(self, folder: Path, lock_name: str, what: str):
        self.folder, self.what = Path(folder), what
        self.holder = self.folder / f"{lock_name}.holder"
        self._lock = FileLock(self.folder / lock_name, timeout=0)

    def acquire(self) -> None:
        """Take the lock; RunError naming the holder if another process has it, or the folder if it cannot
        be written."""
        for path in (Path(self._lock.lock_file), self.holder):
            if Path(path).is_symlink():  # the lock would truncate, the holder overwrite, its target
                raise RunError(
                    f"{path} is a symbolic link; graspexp writes no run file through a link: remove it or "
                    "choose another output directory"
                )
        try:
            self.folder.mkdir(parents=True, exist_ok=True)
            self._lock.acquire()
        except Timeout:
            try:
                who = self.holder.read_text().strip()
            except OSError:
                who = "unknown"
            raise RunError(
                f"{self.folder} is in use by another {self.what} ({who}); wait for it to finish or use another "
                "output directory (hydra.run.dir / hydra.sweep.dir)"
            ) from None
        except OSError as exc:
            raise RunError(
                f"cannot write to the output directory {self.folder}: {exc.strerror or exc}"
            ) from None
        now = datetime.datetime.now().astimezone().isoformat(timespec="seconds")
        text = f"pid {os.getpid()} on {socket.gethostname()} since {now}: {' '.join(sys.argv)}\n".encode()
        write_atomic(self.holder, lambda fh: fh.write(text))

    def release(self) -> None:
        """Drop the lock and its holder file."""
        self.holder.unlink(missing_ok=True)
        self._lock.release()

    def __enter__(self) -> DirectoryLock:
        self.acquire()
        return self

    def __exit__(self, *exc: object) -> None:
        self.release()
