"""Published network checkpoints that learned planners load: where each comes from, its SHA-256, and where
it lies on this machine. Pure standard library: the config stage checks that a checkpoint is there, the
planner verifies it before loading, the ``download_checkpoint`` tool fetches it.

A checkpoint lies in ``$GRASPEXP_CHECKPOINTS`` (a folder, or several joined by ``os.pathsep`` and searched in
order: one per learned planner), else ``~/.cache/graspexp/checkpoints``.
"""

from __future__ import annotations

import hashlib
import os
from dataclasses import dataclass
from pathlib import Path

CHECKPOINTS_ENV = "GRASPEXP_CHECKPOINTS"
"""Environment variable naming the folder that holds the checkpoints (several: joined by ``os.pathsep``)."""


@dataclass(frozen=True)
class Checkpoint:
    """One published checkpoint file."""

    name: str
    """Registry key, as ``python -m graspexp download_checkpoint NAME`` spells it."""
    filename: str
    """File name inside the checkpoint folder."""
    url: str
    """Public address of the file (a fixed commit of the authors' repository)."""
    sha256: str
    """Hex SHA-256 of the file; a file that differs is refused."""
    size_bytes: int
    """Size of the file, bytes."""
    licence: str
    """Licence and copyright holder of the weights."""
    source: str
    """The paper and repository the weights come from."""


VGN = Checkpoint(
    name="vgn",
    filename="vgn_conv.pth",
    url="https://github.com/ethz-asl/vgn/raw/b47ab5321de9cb3cef6e9beef8141abb9e3ed6c1/assets/models/vgn_conv.pth",
    sha256="ba3391d0805e9c9b178cd18106866313cee808ff2b654f689663e92a814cec4b",
    size_bytes=1_255_822,
    licence="BSD 3-Clause, copyright 2020 ETHZ ASL",
    source=(
        "Breyer et al., Volumetric Grasping Network, CoRL 2020 (arXiv:2101.01132); ethz-asl/vgn "
        "assets/models/vgn_conv.pth at commit b47ab532 (2021-12-20)"
    ),
)

CHECKPOINTS: dict[str, Checkpoint] = {c.name: c for c in (VGN,)}
"""graspexp's own checkpoints by name (a learned planner's plugin names the ones it loads:
``graspexp.config.plugins.Learned.checkpoints``)."""


class CheckpointError(RuntimeError):
    """A checkpoint that is missing or differs from its published hash; one line naming the fix."""


def checkpoint_dirs() -> list[Path]:
    """The folders of ``$GRASPEXP_CHECKPOINTS`` (joined by ``os.pathsep``), in order, else
    ``~/.cache/graspexp/checkpoints``."""
    env = [d for d in os.environ.get(CHECKPOINTS_ENV, "").split(os.pathsep) if d]
    return [Path(d).expanduser() for d in env] or [Path.home() / ".cache" / "graspexp" / "checkpoints"]


def checkpoint_dir() -> Path:
    """The first folder of :func:`checkpoint_dirs`: where a checkpoint is downloaded to."""
    return checkpoint_dirs()[0]


def download_command(ckpt: Checkpoint) -> str:
    """The command that fetches ``ckpt`` into :func:`checkpoint_dir`."""
    return f"python -m graspexp download_checkpoint {ckpt.name}"


def checkpoint_path(ckpt: Checkpoint) -> Path:
    """Where ``ckpt`` lies: in the first folder of :func:`checkpoint_dirs` that holds its file, else (not
    there) in the first folder."""
    paths = [d / ckpt.filename for d in checkpoint_dirs()]
    return next((p for p in paths if p.is_file()), paths[0])


def missing_reason(ckpt: Checkpoint) -> str:
    """'' when ``ckpt``'s file is in place with its published size, else one line naming the fix (the hash is
    checked when the file is read: :func:`read_verified`)."""
    path = checkpoint_path(ckpt)
    if not path.is_file():
        return (
            f"checkpoint {path} not found: download it with `{download_command(ckpt)}` "
            f"(or point ${CHECKPOINTS_ENV} at the folder that holds {ckpt.filename})"
        )
    if path.stat().st_size != ckpt.size_bytes:
        return (
            f"checkpoint {path} has {path.stat().st_size} bytes, not the published {ckpt.size_bytes}: "
            f"delete it and run `{download_command(ckpt)}`"
        )
    return ""


def read_verified(ckpt: Checkpoint) -> bytes:
    """The bytes of ``ckpt``'s file after checking their SHA-256 (the bytes checked are the bytes used);
    :class:`CheckpointError` (one line) if the file is missing or differs."""
    why = missing_reason(ckpt)
    if why:
        raise CheckpointError(why)
    path = checkpoint_path(ckpt)
    data = path.read_bytes()
    digest = hashlib.sha256(data).hexdigest()
    if digest != ckpt.sha256:
        raise CheckpointError(
            f"checkpoint {path} has SHA-256 {digest}, not the published {ckpt.sha256}: delete it and run "
            f"`{download_command(ckpt)}`"
        )
    return data
