"""Fetch a published network checkpoint and verify its SHA-256.

Usage::

    python -m graspexp download_checkpoint NAME [--dir DIR] [--url URL]    # e.g. vgn

NAME is one of graspexp's checkpoints or one that an installed learned planner's plugin names
(:attr:`graspexp.config.plugins.Learned.checkpoints`).

The file lands in ``DIR``, else ``$GRASPEXP_CHECKPOINTS`` (its first folder), else ``~/.cache/graspexp/checkpoints`` (where the
learned planners look for it, :mod:`graspexp.core.checkpoints`). It comes from its published address (a
fixed commit of the authors' repository; ``--url`` for a mirror) through the project's downloader (pooch)
and is kept only if its SHA-256 is the published one; a file already there with that hash is not fetched
again.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from pathlib import Path

from graspexp.config.plugins import learned_planners
from graspexp.core.checkpoints import (
    CHECKPOINTS,
    CHECKPOINTS_ENV,
    Checkpoint,
    checkpoint_dir,
    checkpoint_dirs,
    path_kind,
)
from graspexp.datasets.download import fetch
from graspexp.datasets.errors import DatasetError
from graspexp.tools.cli import tool_parser

PROG = "graspexp download_checkpoint"


def known_checkpoints() -> dict[str, Checkpoint]:
    """graspexp's checkpoints and those the installed learned planners name
    (:attr:`graspexp.config.plugins.Learned.checkpoints`), by name."""
    return {
        **CHECKPOINTS,
        **{c.name: c for learned in learned_planners().values() for c in learned.checkpoints},
    }


def main(argv: Sequence[str] | None = None) -> int:
    """CLI entry point; returns the exit status (2 with one line on stderr when the download fails)."""
    parser = tool_parser(PROG, "Download and verify a published network checkpoint.")
    known = known_checkpoints()
    parser.add_argument("name", choices=sorted(known), help="which checkpoint")
    parser.add_argument("--dir", type=Path, default=None, help=f"target folder (default: ${CHECKPOINTS_ENV})")
    parser.add_argument("--url", default=None, help="address of the file (a mirror; default: published)")
    parser.add_argument("--quiet", action="store_true", help="no progress bar")
    args = parser.parse_args(argv)
    ckpt = known[args.name]
    found = [d / ckpt.filename for d in checkpoint_dirs() if (d / ckpt.filename).is_file()]
    folder = (args.dir or (found[0].parent if found else checkpoint_dir())).expanduser()
    kind = path_kind(folder / ckpt.filename)
    if kind:  # a folder, /dev/zero: nothing to hash or overwrite there
        print(
            f"{PROG}: error: {folder / ckpt.filename} is {kind}, not a regular file: remove it",
            file=sys.stderr,
        )
        return 2
    try:
        path = fetch(args.url or ckpt.url, folder, ckpt.filename, ckpt.sha256, progress=not args.quiet)
    except DatasetError as err:
        print(f"{PROG}: error: {err}", file=sys.stderr)
        return 2
    print(f"{ckpt.filename} ready at {path} (SHA-256 {ckpt.sha256} verified)")
    print(f"weights: {ckpt.source}; licence: {ckpt.licence}")
    if args.dir is not None and folder.resolve() not in {d.resolve() for d in checkpoint_dirs()}:
        print(f"use it with {CHECKPOINTS_ENV}={folder}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
