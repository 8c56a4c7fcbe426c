"""Is a mesh file whole? Checks against what the file itself declares and what its dataset publishes.

- OBJ: the element counts some exporters write in the header (``# Vertices: N`` / ``# Faces: N``, e.g.
  the Katamari encoder of the YCB google_16k meshes) against the ``v`` and ``f`` lines present.
- PLY: the header's ``element`` counts against the body, exactly (ASCII: one line per element; binary: the
  elements' bytes, list lengths read from the body).
- YCB google_16k: every model has :data:`graspexp.datasets.ycb_objects.GOOGLE_16K_FACES` faces
  (:func:`check_published_faces`), so a file cut together with its header is caught too; the staged
  models' extents are carried (:data:`graspexp.datasets.ycb_objects.GOOGLE_16K_EXTENTS_MM`) and checked
  like a BOP model's (:func:`check_published_size`): a file at another scale is refused.
- BOP: ``models_info.json`` beside the models publishes each model's size; the loaded extents must match
  it (:func:`check_published_size`); LINEMOD models without an entry there are checked against the sizes
  the library carries (:data:`graspexp.datasets.bop.LM_SIZES_MM`).
- Any dataset mesh: a sane size (:data:`MIN_EXTENT_M` ... :data:`MAX_EXTENT_M`). (The loader also
  requires a closed mesh to enclose a positive volume no larger than its convex hull's.) No dataset here
  publishes volumes or watertightness, so those are checked for consistency only.

Every failure is one :class:`ObjectError` naming the file and what is wrong with it.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from graspexp.datasets.errors import DatasetError, ObjectError

MIN_EXTENT_M, MAX_EXTENT_M = 0.005, 1.0
"""A graspable object's largest extent lies in this range, m (outside: wrong units or a broken file)."""
BOP_SIZE_TOLERANCE = 0.01
"""Relative tolerance of a model's extents against its published size (BOP ``models_info.json``, YCB
google_16k: :data:`graspexp.datasets.ycb_objects.GOOGLE_16K_EXTENTS_MM`), plus 0.5 mm."""
_OBJ_HEADER = re.compile(rb"^#\s*(vertices|faces)\s*:\s*(\d+)\s*$", re.IGNORECASE | re.MULTILINE)
_PLY_SIZES = {"char": 1, "uchar": 1, "int8": 1, "uint8": 1, "short": 2, "ushort": 2, "int16": 2, "uint16": 2,
              "int": 4, "uint": 4, "int32": 4, "uint32": 4, "float": 4, "float32": 4, "double": 8, "float64": 8}  # fmt: skip
_PLY_NUMPY = {"char": "i1", "uchar": "u1", "int8": "i1", "uint8": "u1", "short": "i2", "ushort": "u2",
              "int16": "i2", "uint16": "u2", "int": "i4", "uint": "u4", "int32": "i4", "uint32": "u4"}  # fmt: skip
"""numpy dtypes of the PLY integer types a list's length field may have."""


def _damaged(path: Path, what: str) -> ObjectError:
    return ObjectError(f"broken mesh {path}: {what} (a cut or damaged file?); download it again")


def obj_counts(data: bytes) -> tuple[int, int]:
    """(vertex lines, face lines) of an OBJ file's bytes."""
    lines = data.split(b"\n")
    return sum(ln.startswith(b"v ") for ln in lines), sum(ln.startswith(b"f ") for ln in lines)


def check_obj(path: Path, data: bytes) -> None:
    """Raise DatasetError if the OBJ's header counts disagree with its lines."""
    n_v, n_f = obj_counts(data)
    head = data[:4096]
    declared = {m.group(1).lower().decode(): int(m.group(2)) for m in _OBJ_HEADER.finditer(head)}
    if "vertices" in declared and declared["vertices"] != n_v:
        raise _damaged(path, f"its header declares {declared['vertices']} vertices, the file holds {n_v}")
    if "faces" in declared and declared["faces"] != n_f:
        raise _damaged(path, f"its header declares {declared['faces']} faces, the file holds {n_f}")


def check_ply(path: Path, data: bytes) -> None:
    """Raise ObjectError unless a PLY body holds exactly what its header's element counts declare: ASCII one
    row per element, binary the elements' bytes (list lengths read from the body; a binary file whose face
    lengths vary is left to the loader)."""
    end = data.find(b"end_header")
    if not data.startswith(b"ply") or end < 0:
        raise _damaged(path, "no complete PLY header")
    header = data[:end].decode("ascii", "replace").splitlines()
    body = data[data.index(b"\n", end) + 1 :] if b"\n" in data[end:] else b""
    fmt = next((ln.split()[1] for ln in header if ln.startswith("format ")), "ascii")
    elements: list[tuple[str, int, list[tuple[str, ...]]]] = []  # name, count, property types
    for ln in header:
        parts = ln.split()
        if parts[:1] == ["element"] and len(parts) == 3:
            elements.append((parts[1], int(parts[2]), []))
        elif parts[:1] == ["property"] and elements:
            elements[-1][2].append(tuple(parts[2:4]) if parts[1] == "list" else (parts[1],))
    counts = ", ".join(f"{count} {name}" for name, count, _ in elements)
    if fmt == "ascii":
        rows = sum(1 for ln in body.split(b"\n") if ln.strip())
        needed = sum(count for _, count, _ in elements)
        if rows != needed:  # exact: rows beyond the declared counts are data the reader would drop
            raise _damaged(path, f"its header declares {counts} ({needed} rows), the file holds {rows} rows")
        return
    order = "<" if fmt == "binary_little_endian" else ">"
    offset = 0
    for _, count, props in elements:
        end = _binary_element_end(body, offset, count, props, order)
        if end is None:
            return
        offset = end
        if offset > len(body):
            break
    if offset != len(body):  # exact: bytes beyond the declared elements are data the reader would drop
        held = (
            f"the body ends early, after {len(body)} bytes"
            if offset > len(body)
            else f"the file holds {len(body) - offset} bytes more than those"
        )
        raise _damaged(path, f"its header declares {counts}; {held}")


def _binary_element_end(
    body: bytes, offset: int, count: int, props: list[tuple[str, ...]], order: str
) -> int | None:
    """The byte offset after ``count`` binary elements with properties ``props`` starting at ``offset`` (past
    the body's end if it is too short). Lists must have the first row's lengths in every row (triangle or
    quad meshes: one strided read); None if they vary (trimesh cannot read such a file and says so)."""
    if not any(len(p) == 2 for p in props):
        return offset + count * sum(_PLY_SIZES.get(p[0], 4) for p in props)
    if count == 0:
        return offset
    fields, pos = [], offset
    for p in props:  # the first row: where its length fields are, and their values
        if len(p) == 1:
            pos += _PLY_SIZES.get(p[0], 4)
            continue
        dtype = np.dtype(_PLY_NUMPY.get(p[0], "u1")).newbyteorder(order)
        if pos + dtype.itemsize > len(body):
            return len(body) + 1
        n = int(np.frombuffer(body, dtype, 1, pos)[0])
        fields.append((pos - offset, dtype, n))
        pos += dtype.itemsize + n * _PLY_SIZES.get(p[1], 4)
    stride = pos - offset
    end = offset + count * stride
    if end > len(body):
        return end
    rows = np.frombuffer(body, np.uint8, count * stride, offset).reshape(count, stride)
    same = all(np.all(rows[:, at : at + dt.itemsize].copy().view(dt).ravel() == n) for at, dt, n in fields)
    return end if same else None


def check_file(path: Path) -> None:
    """The declared-count checks of :func:`check_obj` / :func:`check_ply` for ``path`` (other formats: none)."""
    try:
        data = path.read_bytes()
    except OSError as err:
        raise DatasetError(f"cannot read mesh file {path}: {err.strerror}") from None
    suffix = path.suffix.lower()
    if suffix == ".obj":
        check_obj(path, data)
    elif suffix == ".ply":
        check_ply(path, data)


def declared_faces(path: Path) -> int | None:
    """The face count a mesh file declares or holds, read without parsing it (OBJ: its ``f`` lines; PLY: the
    header's ``element face``; binary STL: its count field); None for other formats or an unreadable file."""
    suffix = path.suffix.lower()
    try:
        with open(path, "rb") as fh:
            data = fh.read() if suffix == ".obj" else fh.read(1 << 16)
    except OSError:
        return None  # the loader names the problem
    if suffix == ".obj":
        return data.count(b"\nf ") + data.startswith(b"f ")
    if suffix == ".ply":
        words = data[: max(data.find(b"end_header"), 0)].decode("ascii", "replace").split()
        counts = [words[i + 2] for i in range(len(words) - 2) if words[i : i + 2] == ["element", "face"]]
        return int(counts[0]) if counts and counts[0].isdigit() else None
    if suffix == ".stl" and data[:5].lower() != b"solid" and len(data) >= 84:
        return int(np.frombuffer(data, "<u4", 1, 80)[0])
    return None


def check_face_count(what: str, n_faces: int, max_faces: int) -> None:
    """Raise ObjectError if a mesh of ``n_faces`` exceeds the cap ``dataset.max_faces``."""
    if n_faces > max_faces:
        raise ObjectError(
            f"mesh {what} has {n_faces:,} faces, more than dataset.max_faces={max_faces:,}: decimate it first "
            "(e.g. MeshLab's Quadric Edge Collapse Decimation) or raise dataset.max_faces"
        )


def check_published_faces(path: Path, n_faces: int, expected: int) -> None:
    """Raise ObjectError unless the mesh file ``path``, read with ``n_faces`` faces, holds the face count its
    dataset publishes (a file cut together with its header declares nothing itself)."""
    if n_faces != expected:
        raise _damaged(path, f"it holds {n_faces} faces, its dataset's models have {expected}")


def check_geometry(what: str, extents_m: np.ndarray, units_hint: str = "") -> None:
    """Raise ObjectError unless the largest extent is a graspable object's size; ``units_hint`` says where
    the user sets the file's units (then the message also proposes the units that would fit)."""
    size = float(np.max(extents_m))
    if MIN_EXTENT_M <= size <= MAX_EXTENT_M:
        return
    if units_hint:
        fits = [
            f"{name} ({size * factor:.3g} m)"
            for name, factor in (("mm", 1e-3), ("cm", 1e-2), ("m", 1.0), ("inches", 0.0254))
            if MIN_EXTENT_M <= size * factor <= MAX_EXTENT_M
        ]
        guess = f"; in {' or '.join(fits)} it would be" if fits else ""
        raise ObjectError(
            f"mesh {what}: its largest extent reads as {size:.4g} m (extents {np.round(extents_m, 4).tolist()} m), "
            f"outside a graspable object's [{MIN_EXTENT_M}, {MAX_EXTENT_M}] m{guess}: set its units with {units_hint}"
        )
    raise ObjectError(
        f"broken mesh {what}: largest extent {size:.4g} m is outside [{MIN_EXTENT_M}, {MAX_EXTENT_M}] m "
        "(wrong units, e.g. millimetres read as metres, or a broken file)"
    )


def check_published_size(path: Path, extents_mm: np.ndarray, published_mm: np.ndarray, where: str) -> None:
    """Compare a model's extents (mm) with the size its dataset publishes (mm; within
    :data:`BOP_SIZE_TOLERANCE` plus 0.5 mm); ``where`` names the publication in the message."""
    if np.any(np.abs(extents_mm - published_mm) > 0.5 + BOP_SIZE_TOLERANCE * published_mm):
        raise _damaged(
            path,
            f"its extents {np.round(extents_mm, 2).tolist()} mm differ from the published size "
            f"{np.round(published_mm, 2).tolist()} mm in {where}",
        )
