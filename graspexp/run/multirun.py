"""The one way graspexp starts a sweep of jobs: ``python -m graspexp -m LAUNCHER hydra.sweep.dir=DIR
OVERRIDES`` (Hydra's multirun; later overrides of a key win, so ``overrides`` can replace the defaults).

``python -m graspexp.run.multirun DIR [OVERRIDES...]`` runs one with ``progress=false`` and the joblib
launcher (the nox sessions use it) and exits with its status.
"""

import subprocess
import sys
from collections.abc import Sequence
from pathlib import Path

JOBLIB = ("hydra/launcher=joblib",)
"""Local worker processes (``hydra.launcher.n_jobs`` of them; default: one per core)."""


def multirun_command(
    sweep_dir: Path | str, overrides: Sequence[str], *, launcher: Sequence[str] = JOBLIB
) -> list[str]:
    """The argv of a multirun into ``sweep_dir`` (one job per combination of the comma-separated values in
    ``overrides``) with ``launcher`` (its overrides, e.g. ``hydra/launcher=submitit_slurm`` and keys), run
    by this interpreter."""
    return [sys.executable, "-m", "graspexp", "-m", *launcher, f"hydra.sweep.dir={sweep_dir}", *overrides]


def main(argv: list[str] | None = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    if not args or args[0].startswith("-"):
        print("usage: python -m graspexp.run.multirun SWEEP_DIR [OVERRIDES...]", file=sys.stderr)
        return 2
    return subprocess.run(multirun_command(args[0], ["progress=false", *args[1:]])).returncode


if __name__ == "__main__":
    raise SystemExit(main())
