"""Grasping areas: which surface points the planner may grasp (the paper selects them in MeshLab).

A region spec file (``graspexp/datasets/regions/<dataset>.yaml``, named by ``dataset.regions``) maps
each object name to a list of operations on the object's point cloud, in the object frame, metres::

    025_mug:
      note: body only; a person holds the handle      # optional free text
      relative: false                                  # optional, default false
      ops:
        - keep_box: {min: [-0.07, -0.03, 0.01], max: [0.01, 0.07, 0.07]}
        - exclude_sphere: {center: [0.0, 0.0, 0.0], radius: 0.02}

An entry may also be just the list of operations. Operations, applied in order:

- ``keep_box: {min: [x, y, z], max: [x, y, z]}`` / ``exclude_box``: the closed axis-aligned box.
- ``keep_halfspace: {normal: [nx, ny, nz], offset: d}`` / ``exclude_halfspace``: points with n . p >= d
  (the normal is used as given, not normalised).
- ``keep_sphere: {center: [x, y, z], radius: r}`` / ``exclude_sphere``: the closed ball.
- ``keep_cylinder: {p0: [x, y, z], p1: [x, y, z], radius: r}`` / ``exclude_cylinder``: the closed
  finite cylinder of radius r around the segment p0 -> p1 (e.g. a mug's cavity).
- ``keep_all: {}``: every point.

``keep_*`` adds the selected points to the area, ``exclude_*`` removes them (MeshLab's select and
delete). The start set: all points when the first operation is an ``exclude_*``, none when it is a
``keep_*``; with ``meshlab_ply`` the start set is the imported area and the operations refine it.

``relative: true`` (for the whole entry, or inside one operation to override it) gives coordinates as
fractions of the object's axis-aligned mesh bounds: p_rel = (p - bounds_min) / extents, so 0..1 spans
the object on every axis. All of the operation is then evaluated in those coordinates (a relative
sphere is an axis-aligned ellipsoid in metres). Relative specs survive a translated frame (e.g. the
re-centred YCB-Video models), absolute ones do not.

``meshlab_ply: path`` imports an area saved from MeshLab (see :func:`import_meshlab_area`); the path
is relative to the spec file's folder or to the data root. Optional ``scale`` (file units -> metres,
e.g. 0.001 for a millimetre LINEMOD cloud) and ``tolerance_m``.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import trimesh
from sklearn.neighbors import KDTree

from graspexp.config.constraints import Interval
from graspexp.core.userinput import UserInputError, inside_folder, read_user_yaml, shown
from graspexp.datasets.errors import DatasetError, ObjectError

REGIONS_DIR = Path(__file__).parent / "regions"
"""Folder of the version-controlled region spec files."""
POSITIVE = Interval(0, None, "neither")
"""A finite positive number (``scale``, ``tolerance_m``)."""
MESHLAB_TOLERANCE_FACTOR = 1.5
"""Default import tolerance = this factor x the median nearest-neighbour spacing of the area cloud."""

_SHAPE_PARAMS = {
    "box": ("min", "max"),
    "halfspace": ("normal", "offset"),
    "sphere": ("center", "radius"),
    "cylinder": ("p0", "p1", "radius"),
}
_OP_NAMES = {f"{mode}_{shape}" for mode in ("keep", "exclude") for shape in _SHAPE_PARAMS} | {"keep_all"}
_ENTRY_KEYS = {"ops", "relative", "note", "meshlab_ply", "scale", "tolerance_m"}


@dataclass(frozen=True)
class RegionOp:
    """One operation: ``keep`` or ``exclude`` the points inside a shape (box, halfspace, sphere, cylinder, all)."""

    keep: bool
    shape: str
    params: dict[str, Any]
    relative: bool

    def inside(self, points: np.ndarray, bounds: np.ndarray) -> np.ndarray:
        """(n,) bool: which of ``points`` (n, 3), object frame, metres, the shape contains."""
        p = points
        if self.relative:
            extents = np.where(bounds[1] > bounds[0], bounds[1] - bounds[0], 1.0)
            p = (points - bounds[0]) / extents
        if self.shape == "all":
            return np.ones(len(p), dtype=bool)
        if self.shape == "box":
            lo, hi = np.asarray(self.params["min"], float), np.asarray(self.params["max"], float)
            return np.all((p >= lo) & (p <= hi), axis=1)
        if self.shape == "halfspace":
            return p @ np.asarray(self.params["normal"], float) >= float(self.params["offset"])
        if self.shape == "sphere":
            centre = np.asarray(self.params["center"], float)
            return np.linalg.norm(p - centre, axis=1) <= float(self.params["radius"])
        p0, p1 = np.asarray(self.params["p0"], float), np.asarray(self.params["p1"], float)
        axis = p1 - p0
        t = (p - p0) @ axis / float(axis @ axis)
        radial = np.linalg.norm(p - p0 - np.outer(t, axis), axis=1)
        return (t >= 0.0) & (t <= 1.0) & (radial <= float(self.params["radius"]))


@dataclass(frozen=True)
class RegionSpec:
    """The grasping-area recipe of one object, as read from a spec file."""

    name: str
    spec_file: Path
    ops: tuple[RegionOp, ...] = ()
    meshlab_ply: str | None = None
    scale: float = 1.0
    tolerance_m: float | None = None
    note: str = ""


def whole_surface(name: str) -> RegionSpec:
    """The area of an object that has no spec: its whole surface."""
    return RegionSpec(
        name=name,
        spec_file=Path("<no area spec>"),
        ops=(RegionOp(keep=True, shape="all", params={}, relative=False),),
        note="whole surface (no area given)",
    )


def regions_path(regions: str) -> Path:
    """The spec file named by ``dataset.regions``: an existing path as given, else under ``REGIONS_DIR``."""
    given = Path(regions).expanduser()
    if given.is_file():
        return given
    path = REGIONS_DIR / regions
    if not path.is_file():
        available = sorted(p.name for p in REGIONS_DIR.glob("*.yaml"))
        raise DatasetError(
            f"grasping-area spec file {regions!r} (dataset.regions) not found: neither {given.resolve()} "
            f"nor {path} exists; files in {REGIONS_DIR}: {', '.join(available)}"
        )
    return path


def load_region_specs(path: Path | str) -> dict[str, RegionSpec]:
    """All entries of one spec file, validated (re-read when the file changes)."""
    path = Path(path).resolve()
    return _load_specs_cached(path, path.stat().st_mtime_ns)


@functools.lru_cache(maxsize=16)
def _load_specs_cached(path: Path, _mtime_ns: int) -> dict[str, RegionSpec]:
    try:
        data = read_user_yaml(path, f"grasping-area spec file {path}") or {}
    except UserInputError as err:
        raise DatasetError(str(err)) from None
    if not isinstance(data, dict) or not all(isinstance(name, str | int) for name in data):
        raise DatasetError(f"grasping-area spec file {path} must map object names to region specs")
    return {str(name): parse_entry(str(name), entry, path) for name, entry in data.items()}


def parse_entry(name: str, entry: Any, path: Path) -> RegionSpec:
    """Object ``name``'s entry (a mapping or a list of operations) of spec file or sidecar ``path``, validated
    as strictly as a config (known keys, booleans, numbers); raises DatasetError naming the file and key."""
    where = f"{path}: object {name!r}"
    if isinstance(entry, list):
        entry = {"ops": entry}
    if not isinstance(entry, dict):
        raise DatasetError(f"{where}: expected a mapping or a list of operations, got {shown(entry)}")
    unknown = sorted(shown(k) for k in entry if k not in _ENTRY_KEYS)
    if unknown:
        raise DatasetError(f"{where}: unknown keys [{', '.join(unknown)}]; valid keys: {sorted(_ENTRY_KEYS)}")
    for key in ("note", "meshlab_ply"):
        if entry.get(key) is not None and not isinstance(entry[key], str):
            raise DatasetError(f"{where}: {key} must be text, got {type(entry[key]).__name__}")
    relative = _flag(entry.get("relative", False), f"{where}: relative")
    raw_ops = entry.get("ops") or []
    if not isinstance(raw_ops, list):
        raise DatasetError(f"{where}: 'ops' must be a list of operations")
    if not raw_ops and not entry.get("meshlab_ply"):
        raise DatasetError(f"{where}: needs at least one operation in 'ops' or a 'meshlab_ply' area")
    ops = tuple(_parse_op(op, relative, f"{where}, operation {i}") for i, op in enumerate(raw_ops))
    return RegionSpec(
        name=name,
        spec_file=path,
        ops=ops,
        meshlab_ply=entry.get("meshlab_ply"),
        scale=_positive(entry.get("scale", 1.0), f"{where}: scale"),
        tolerance_m=None
        if entry.get("tolerance_m") is None
        else _positive(entry["tolerance_m"], f"{where}: tolerance_m"),
        note=entry.get("note") or "",
    )


def _parse_op(op: Any, relative: bool, where: str) -> RegionOp:
    if not isinstance(op, dict) or len(op) != 1:
        raise DatasetError(
            f"{where}: an operation is a one-key mapping such as {{keep_box: {{...}}}}, got {shown(op)}"
        )
    ((kind, params),) = op.items()
    if kind not in _OP_NAMES:
        raise DatasetError(f"{where}: unknown operation {shown(kind)}; valid: {', '.join(sorted(_OP_NAMES))}")
    mode, shape = kind.split("_", 1)
    if params is None or params is True:
        params = {}
    if not isinstance(params, dict):
        raise DatasetError(f"{where}: parameters of {kind} must be a mapping, got {shown(params)}")
    params = dict(params)
    op_relative = _flag(params.pop("relative", relative), f"{where}: {kind}.relative")
    expected = _SHAPE_PARAMS.get(shape, ())
    if set(params) != set(expected):
        raise DatasetError(
            f"{where}: {kind} takes exactly {list(expected)}, got [{', '.join(sorted(map(shown, params)))}]"
        )
    for key, value in params.items():
        size = 1 if key in ("offset", "radius") else 3
        array = np.asarray(value, dtype=float) if _is_numeric(value) else None
        if array is None or array.size != size or not np.all(np.isfinite(array)):
            raise DatasetError(f"{where}: {kind}.{key} must be {size} finite number(s), got {shown(value)}")
    if shape == "halfspace" and not np.linalg.norm(np.asarray(params["normal"], float)) > 0:
        raise DatasetError(f"{where}: {kind}.normal must not be zero (it would select every point)")
    if shape == "box" and np.any(np.asarray(params["min"], float) > np.asarray(params["max"], float)):
        raise DatasetError(f"{where}: {kind} has min > max: {params['min']} vs {params['max']}")
    if shape == "cylinder" and np.allclose(params["p0"], params["p1"]):
        raise DatasetError(f"{where}: {kind} needs p0 != p1, got {params['p0']}")
    if "radius" in params and not float(params["radius"]) > 0:
        raise DatasetError(f"{where}: {kind}.radius must be > 0, got {params['radius']}")
    return RegionOp(keep=mode == "keep", shape=shape, params=params, relative=op_relative)


def _flag(value: Any, what: str) -> bool:
    """``value`` if it is a YAML boolean (``true``/``false``), else a DatasetError: ``"false"`` is not false."""
    if not isinstance(value, bool):
        raise DatasetError(f"{what} must be true or false (unquoted), got {shown(value)}")
    return value


def _positive(value: Any, what: str) -> float:
    """``value`` as a float if it is a finite positive number, else a DatasetError naming ``what``."""
    if not POSITIVE.accepts(value):
        raise DatasetError(f"{what} must be a positive number, got {shown(value)}")
    return float(value)


def _is_numeric(value: Any) -> bool:
    try:
        np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        return False
    return True


def apply_ops(
    ops: Sequence[RegionOp], points: np.ndarray, bounds: np.ndarray, start: np.ndarray | None = None
) -> np.ndarray:
    """(n,) bool area mask over ``points`` (n, 3), object frame, metres; ``bounds`` (2, 3) for relative ops.

    ``start`` is the initial mask; None means all points if the first op excludes, none if it keeps.
    """
    if start is not None:
        mask = np.asarray(start, dtype=bool).copy()
    else:
        mask = np.full(len(points), bool(ops) and not ops[0].keep, dtype=bool)
    for op in ops:
        inside = op.inside(points, bounds)
        mask = (mask | inside) if op.keep else (mask & ~inside)
    return mask


def import_meshlab_area(
    ply_path: Path | str, object_points: np.ndarray, *, scale: float = 1.0, tolerance_m: float | None = None
) -> np.ndarray:
    """Map a MeshLab-saved grasping area onto an object's point cloud.

    ply_path : PLY (point cloud or mesh; its vertices are used) in the object frame, file units.
    object_points : (N, 3) float, object frame, metres.
    scale : multiplies the file's coordinates to get metres (0.001 for millimetres).
    tolerance_m : a cloud point is in the area if its nearest area point is within this distance;
        default ``MESHLAB_TOLERANCE_FACTOR`` x the median nearest-neighbour spacing of the area cloud.
    Returns (N,) bool.
    """
    path = Path(ply_path)
    try:
        loaded = trimesh.load(path, process=False)
    except Exception as err:  # trimesh raises many types for unreadable files
        raise ObjectError(
            f"cannot read MeshLab area file {path}: {type(err).__name__}: {shown(str(err))}"
        ) from None
    area = np.asarray(getattr(loaded, "vertices", np.empty((0, 3))), dtype=float) * float(scale)
    if area.ndim != 2 or area.shape[1:] != (3,) or len(area) < 2 or not np.all(np.isfinite(area)):
        raise ObjectError(f"MeshLab area file {path} needs at least 2 finite points (3-D), has {len(area)}")
    tree = KDTree(area)
    if tolerance_m is None:
        spacing, _ = tree.query(area, k=2)
        tolerance_m = MESHLAB_TOLERANCE_FACTOR * float(np.median(spacing[:, 1]))
    distance, _ = tree.query(np.asarray(object_points, dtype=float).reshape(-1, 3), k=1)
    return distance[:, 0] <= tolerance_m


def area_mask(
    spec: RegionSpec, points: np.ndarray, bounds: np.ndarray, data_dirs: Sequence[Path] = ()
) -> np.ndarray:
    """(N,) bool grasping-area mask of ``points`` (N, 3), object frame, metres, per ``spec``.

    ``bounds`` (2, 3) are the mesh bounds used by relative operations; ``data_dirs`` are further folders
    (after the spec file's own) in which a relative ``meshlab_ply`` path is looked up.
    Raises :class:`DatasetError` naming the object and the spec file when the area is empty.
    """
    start = None
    if spec.meshlab_ply:
        ply = _find_meshlab_file(spec, data_dirs)
        start = import_meshlab_area(ply, points, scale=spec.scale, tolerance_m=spec.tolerance_m)
    mask = apply_ops(spec.ops, points, bounds, start)
    if not mask.any():
        raise ObjectError(
            f"empty grasping area for object {spec.name!r}: no point of its cloud passes the region spec "
            f"in {spec.spec_file}; fix the boxes/half-spaces there"
        )
    return mask


def _find_meshlab_file(spec: RegionSpec, data_dirs: Sequence[Path]) -> Path:
    """The file ``meshlab_ply`` names: relative to the spec file's folder or one of ``data_dirs``, inside
    that folder (an object's files never reach outside the folders it is read from)."""
    given = Path(str(spec.meshlab_ply))
    folders = (spec.spec_file.parent, *data_dirs)
    candidates = [d / given for d in folders if inside_folder(d / given, d)]
    if given.is_absolute() or str(given).startswith("~") or not candidates:
        raise ObjectError(
            f"meshlab_ply={shown(spec.meshlab_ply)} of object {spec.name!r} in {spec.spec_file} leaves its "
            "folder: give a path relative to that folder, inside it"
        )
    for candidate in candidates:
        if candidate.is_file():
            return candidate
    raise ObjectError(
        f"MeshLab area file for object {spec.name!r} (meshlab_ply in {spec.spec_file}) not found: "
        + " or ".join(str(c.resolve()) for c in candidates)
    )
