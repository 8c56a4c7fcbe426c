"""Published network checkpoints that learned planners load: where each comes from, its SHA-256, and where
it lies on this machine. Pure standard library: the config stage checks that a checkpoint is there, the
planner verifies it before loading, the ``download_checkpoint`` tool fetches it.

A checkpoint lies in ``$GRASPEXP_CHECKPOINTS`` (a folder, or several joined by ``os.pathsep`` and searched in
order: one per learned planner), else ``~/.cache/graspexp/checkpoints``.
"""

from __future__ import annotations

import hashlib
import os
import stat
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

GIGA_MODELS_URL = (
    "https://github.com/supersglzc/GIGA/raw/30efe5946cb2622c21f140b3e811f7fcce804c7b/data/models/"
)
"""Folder of the models of GIGA's release (Jiang et al., RSS 2021) at a fixed commit: supersglzc/GIGA, a fork of
UT-Austin-RPL/GIGA that commits the files of the authors' data.zip (added at 30efe594, 2023-08-23)."""
GIGA_LICENCE = "MIT, copyright 2021 UT Robot Perception and Learning Lab"
"""Licence of the models of GIGA's release (its ``LICENSE``)."""


def _vgn_single_view(scene: str, sha256: str) -> Checkpoint:
    """VGN as GIGA's authors retrained it on single noisy side views of ``scene`` (GIGA paper Sec. VI-B: the
    VGN rows of its Table I); the architecture and the 18 tensors of ``vgn_conv.pth``."""
    return Checkpoint(
        name=f"vgn_{scene}",
        filename=f"vgn_{scene}.pt",
        url=f"{GIGA_MODELS_URL}vgn_{scene}.pt",
        sha256=sha256,
        size_bytes=1_259_345,
        licence=GIGA_LICENCE,
        source=(
            f"VGN (Breyer et al., CoRL 2020) retrained on single side views of {scene} scenes by Jiang et al., "
            f"GIGA, RSS 2021 (arXiv:2104.01542); supersglzc/GIGA data/models/vgn_{scene}.pt at commit 30efe594"
        ),
    )


VGN_PILE = _vgn_single_view("pile", "c623ea8418d1f853de83ccf26e9faed58b3ab2870ea5e72d6de49466bc17c3a1")
VGN_PACKED = _vgn_single_view("packed", "c9d8f6d4b1afdab912b3299ddae14a4bc1c7daecb0b6e81a21f70bdcb36d218d")

CHECKPOINTS: dict[str, Checkpoint] = {c.name: c for c in (VGN, VGN_PILE, VGN_PACKED)}
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
    """Where ``ckpt`` lies: in the first folder of :func:`checkpoint_dirs` that holds its file (a regular
    file), else the first entry of that name that is something else (a folder, a device: what
    :func:`missing_reason` reports), else (not there) in the first folder."""
    paths = [d / ckpt.filename for d in checkpoint_dirs()]
    kinds = [path_kind(p) for p in paths]
    if "" in kinds:
        return paths[kinds.index("")]
    return next((p for p, k in zip(paths, kinds, strict=True) if k), paths[0])


def path_kind(path: Path) -> str | None:
    """What is at ``path``: '' a regular file, None nothing (or a folder above it cannot be searched), else
    what it is instead, in words."""
    try:
        mode = path.stat().st_mode
    except (FileNotFoundError, NotADirectoryError):
        return "a link to nothing" if path.is_symlink() else None
    except OSError as exc:  # a folder above that cannot be searched: nothing seen there
        if path.parent != path and path_kind(path.parent) is None:
            return None
        return f"unreadable ({exc.strerror})"
    if stat.S_ISREG(mode):
        return ""
    if stat.S_ISDIR(mode):
        return "a folder"
    kinds = {
        stat.S_ISCHR: "a character device",
        stat.S_ISBLK: "a block device",
        stat.S_ISFIFO: "a named pipe",
        stat.S_ISSOCK: "a socket",
    }
    return next((w for test, w in kinds.items() if test(mode)), "a special file")


def missing_reason(ckpt: Checkpoint) -> str:
    """'' when ``ckpt``'s file is in place (a regular file this process can read) with its published size,
    else one line saying what is there instead and naming the fix (the hash is checked when the file is
    read: :func:`read_verified`). Nothing is read here, and a path that is not a regular file (a folder,
    ``/dev/zero``, a pipe) is refused before anything reads it."""
    path = checkpoint_path(ckpt)
    fetch = f"run `{download_command(ckpt)}`"
    kind = path_kind(path)
    if kind is None:
        bad = [d for d in checkpoint_dirs() if path_kind(d) not in (None, "a folder")]
        where = f" (${CHECKPOINTS_ENV} names {bad[0]}, which is not a folder)" if bad else ""
        return (
            f"checkpoint {path} not found{where}: download it with `{download_command(ckpt)}` "
            f"(or point ${CHECKPOINTS_ENV} at the folder that holds {ckpt.filename})"
        )
    if kind.startswith("unreadable"):
        return f"checkpoint {path} is {kind}: make it readable or remove it and {fetch}"
    if kind:
        return f"checkpoint {path} is {kind}, not a regular file: remove it and {fetch}"
    if not os.access(path, os.R_OK):
        return f"checkpoint {path} is unreadable (permission denied): make it readable (chmod a+r) or {fetch}"
    size = path.stat().st_size
    if size != ckpt.size_bytes:
        return (
            f"checkpoint {path} has {size} bytes, not the published {ckpt.size_bytes}: delete it and {fetch}"
        )
    return ""


def read_verified(ckpt: Checkpoint) -> bytes:
    """The bytes of ``ckpt``'s file after checking their SHA-256 (the bytes checked are the bytes used);
    :class:`CheckpointError` (one line) if the file is missing or differs."""
    why = missing_reason(ckpt)
    if why:
        raise CheckpointError(why)
    path = checkpoint_path(ckpt)
    try:
        data = path.read_bytes()
    except OSError as exc:  # changed since it was checked
        raise CheckpointError(f"checkpoint {path} cannot be read ({exc.strerror or exc})") from None
    digest = hashlib.sha256(data).hexdigest()
    if digest != ckpt.sha256:
        raise CheckpointError(
            f"checkpoint {path} has SHA-256 {digest}, not the published {ckpt.sha256}: delete it and run "
            f"`{download_command(ckpt)}`"
        )
    return data
