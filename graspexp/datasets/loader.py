"""Loading an :class:`ObjectModel`: mesh (cached in-process), seeded surface cloud, grasping area, mass."""

from __future__ import annotations

import functools
import logging
import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import trimesh

from graspexp.config.dataset import DatasetConfig
from graspexp.core.seeding import cloud_seed
from graspexp.datasets.catalog import (
    available_objects,
    catalogue,
    dataset_dir,
    dataset_objects,
    object_source,
    resolve_root,
)
from graspexp.datasets.errors import DatasetError, ObjectError
from graspexp.datasets.meshcheck import (
    check_face_count,
    check_file,
    check_geometry,
    check_published_faces,
    check_published_size,
    declared_faces,
)
from graspexp.datasets.model import ObjectModel
from graspexp.datasets.primitives import PRIMITIVES
from graspexp.datasets.regions import RegionSpec, area_mask, load_region_specs, regions_path, whole_surface
from graspexp.datasets.source import ObjectSource

log = logging.getLogger(__name__)

MIN_VOLUME_M3 = 1e-9
"""A mesh whose convex hull encloses less than this (1 mm^3) is degenerate (flat or a point)."""
MESH_CACHE_SIZE = 64
"""Meshes kept in the in-process cache (a google_16k mesh is about 1 MB)."""


@dataclass(frozen=True)
class MeshEntry:
    """A validated mesh and the facts derived from it once (the cached value)."""

    mesh: trimesh.Trimesh
    """Object frame, metres, vertices merged by position. Never mutated: callers get copies."""
    volume_m3: float
    """Enclosed volume if the mesh is watertight, else the convex-hull volume (an upper bound)."""
    watertight: bool
    file_faces: int
    """Faces as read from the file(s), before merging and cleaning (what a dataset's published count means)."""


def load_mesh(path: Path | str, scale: float | tuple[float, float, float] = 1.0) -> MeshEntry:
    """The validated mesh of ``path`` with coordinates multiplied by ``scale`` (file units -> metres; one
    factor or one per axis).

    Cached on (resolved path, modification time, scale): repeated trials do not reload. Textures and
    materials are never decoded. Raises :class:`ObjectError` for an unreadable file, element counts
    that disagree with the file's header (:mod:`graspexp.datasets.meshcheck`), no faces, non-finite
    vertices, zero volume, or a closed mesh whose volume exceeds its convex hull's.
    """
    resolved = Path(path).resolve()
    try:
        mtime_ns = resolved.stat().st_mtime_ns
    except OSError as err:
        raise DatasetError(f"cannot read mesh file {resolved}: {err.strerror}") from None
    return _load_mesh_cached(resolved, mtime_ns, scale if isinstance(scale, tuple) else float(scale))


@functools.lru_cache(maxsize=MESH_CACHE_SIZE)
def _load_mesh_cached(path: Path, _mtime_ns: int, scale: float | tuple[float, float, float]) -> MeshEntry:
    vertices, faces = _read_mesh_file(path)
    mesh = trimesh.Trimesh(vertices * np.asarray(scale), faces, process=True)
    return _validated(mesh, str(path), file_faces=len(faces))


def _read_mesh_file(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """(vertices (V, 3) float64 in file units, faces (F, 3) int64) of a mesh file, its declared counts checked."""
    check_file(path)
    try:
        with warnings.catch_warnings():
            # Some google_16k OBJ files hold a `vn nan nan nan` line; vertex normals are recomputed anyway.
            warnings.simplefilter("ignore", RuntimeWarning)
            loaded = trimesh.load(path, force="mesh", skip_materials=True, process=False)
    except Exception as err:  # trimesh raises many types for malformed files
        raise ObjectError(f"broken mesh {path}: cannot be loaded ({type(err).__name__}: {err})") from None
    vertices = np.asarray(getattr(loaded, "vertices", np.empty((0, 3))), dtype=float)
    faces = np.asarray(getattr(loaded, "faces", np.empty((0, 3))), dtype=np.int64)
    if not np.all(np.isfinite(vertices)):  # check before merging: processing would drop them silently
        raise ObjectError(f"broken mesh {path}: it has non-finite vertex coordinates")
    return vertices, faces


def _primitive_part(kind: str, dims: tuple[float, ...]) -> trimesh.Trimesh:
    """A URDF primitive centred on its origin (a cylinder along Z), metres."""
    if kind == "box":
        return trimesh.creation.box(extents=dims)
    if kind == "cylinder":
        return trimesh.creation.cylinder(radius=dims[0], height=dims[1], sections=64)
    return trimesh.creation.icosphere(subdivisions=3, radius=dims[0])


def _assembled(source: ObjectSource) -> MeshEntry:
    """The validated mesh of a multi-part or placed source (a URDF object): each part scaled, placed by its
    origin, then joined; the object frame is the URDF link's."""
    pieces = []
    for part in source.parts:
        if part.file is not None:
            vertices, faces = _read_mesh_file(part.file.resolve())
            piece = trimesh.Trimesh(vertices * np.asarray(part.scale), faces, process=False)
        else:
            piece = _primitive_part(*part.primitive)
        if part.origin is not None:
            piece.apply_transform(np.asarray(part.origin))
        pieces.append(piece)
    joined = trimesh.util.concatenate(pieces)
    return _validated(trimesh.Trimesh(joined.vertices, joined.faces, process=True), source.source)


@functools.lru_cache(maxsize=len(PRIMITIVES))
def _primitive_entry(name: str) -> MeshEntry:
    return _validated(PRIMITIVES[name](), f"primitive {name!r}")


def _validated(mesh: trimesh.Trimesh, what: str, file_faces: int | None = None) -> MeshEntry:
    if len(mesh.faces) == 0:
        raise ObjectError(f"broken mesh {what}: it has no faces")
    if not np.all(np.isfinite(mesh.vertices)):
        raise ObjectError(f"broken mesh {what}: it has non-finite vertex coordinates")
    try:
        with np.errstate(divide="ignore", invalid="ignore"):  # trimesh divides by a zero volume
            hull_volume = float(mesh.convex_hull.volume)
    except Exception:  # qhull fails on flat or collinear input
        hull_volume = 0.0
    if not hull_volume > MIN_VOLUME_M3:
        raise ObjectError(f"broken mesh {what}: it encloses zero volume (flat or degenerate)")
    watertight = bool(mesh.is_watertight)
    if watertight and mesh.volume < 0:
        mesh.invert()  # inside-out winding: make face normals point outwards
    volume = float(mesh.volume) if watertight else hull_volume
    if watertight and not 0 < volume <= hull_volume * (1 + 1e-6):
        raise ObjectError(
            f"broken mesh {what}: it is closed but encloses {volume:.3g} m^3 against a convex hull of "
            f"{hull_volume:.3g} m^3 (self-intersecting or inconsistently wound faces)"
        )
    mesh.vertices.flags.writeable = False
    mesh.faces.flags.writeable = False
    n_read = len(mesh.faces) if file_faces is None else file_faces
    return MeshEntry(mesh=mesh, volume_m3=volume, watertight=watertight, file_faces=n_read)


def object_mesh(cfg: Any, name: str) -> tuple[MeshEntry, str]:
    """The cached mesh entry of object ``name`` and its source file ("" for primitives)."""
    entry, source = _object_mesh(cfg, name)
    return entry, source.source


def _object_mesh(cfg: Any, name: str) -> tuple[MeshEntry, ObjectSource]:
    source = object_source(cfg, name)
    if not source.parts:
        return _primitive_entry(name), source
    single = source.parts[0]
    max_faces = int(getattr(cfg, "max_faces", DatasetConfig.max_faces))  # a plain object: the default
    declared = [declared_faces(p.file) for p in source.parts if p.file is not None]
    check_face_count(source.source, sum(n for n in declared if n is not None), max_faces)  # before reading
    if len(source.parts) == 1 and single.file is not None and single.origin is None:
        entry = load_mesh(single.file, single.scale)
    else:
        entry = _assembled(source)
    check_face_count(source.source, len(entry.mesh.faces), max_faces)
    if source.published_faces is not None:
        check_published_faces(single.file, entry.file_faces, source.published_faces)
    if source.published_size is not None:
        check_published_size(
            Path(source.source),
            entry.mesh.extents * 1e3,  # m -> mm
            np.asarray(source.published_size),
            source.published_where,
        )
    check_geometry(source.source, entry.mesh.extents, source.units_hint)
    return entry, source


def object_mass_kg(cfg: Any, source: ObjectSource, entry: MeshEntry) -> float:
    """The published, URDF or sidecar mass; else volume x density (the sidecar's, else ``cfg.density_kg_m3``)."""
    if source.mass_kg is not None:
        return float(source.mass_kg)
    density = float(source.density_kg_m3 or cfg.density_kg_m3)
    if not density > 0:
        raise DatasetError(f"dataset.density_kg_m3 must be > 0, got {density}")
    return entry.volume_m3 * density


def object_area(cfg: Any, source: ObjectSource) -> tuple[RegionSpec, str]:
    """The grasping-area spec of an object and where it came from: its sidecar's, else its entry in the
    spec file ``cfg.regions``, else its whole surface."""
    if source.area is not None:
        return source.area, f"area: {source.area.spec_file.name}"
    if getattr(cfg, "regions", None):
        specs_file = regions_path(cfg.regions)
        spec = load_region_specs(specs_file).get(source.name)
        if spec is not None:
            return spec, ""
        return whole_surface(source.name), f"area: whole surface (no entry in {specs_file.name})"
    return whole_surface(source.name), "area: whole surface (no area given)"


def load_object(cfg: Any, name: str, n_points: int, seed: int) -> ObjectModel:
    """Load object ``name`` of dataset ``cfg`` (a DatasetConfig or its DictConfig).

    n_points : number of surface samples (>= 1).
    seed : seeds ``trimesh.sample.sample_surface`` (the same seed gives the same cloud; the global
        ``np.random`` is never used). Derive it with :func:`graspexp.core.seeding.derive_seed`.
    The grasping area: the object's sidecar, else its entry in ``cfg.regions``
    (:mod:`graspexp.datasets.regions`), else the whole surface (said in ``ObjectModel.notes``).
    """
    if isinstance(n_points, bool) or not isinstance(n_points, int | np.integer) or n_points < 1:
        raise DatasetError(f"n_points must be a positive integer, got {n_points!r}")
    if isinstance(seed, bool) or not isinstance(seed, int | np.integer):
        raise DatasetError(f"seed must be an integer, got {seed!r}")
    entry, source = _object_mesh(cfg, name)
    spec, area_note = object_area(cfg, source)

    # Sample on the cached mesh (its face areas and normals are computed once); hand out a copy.
    points, face_index = trimesh.sample.sample_surface(entry.mesh, int(n_points), seed=int(seed))
    normals = entry.mesh.face_normals[face_index]
    data_dirs = (dataset_dir(cfg), resolve_root(cfg))
    mask = area_mask(spec, points, entry.mesh.bounds, data_dirs=data_dirs)
    return ObjectModel(
        name=name,
        dataset=cfg.name,
        mesh=entry.mesh.copy(include_cache=False),
        points=np.asarray(points, dtype=np.float64),
        normals=np.asarray(normals, dtype=np.float64),
        area_mask=mask,
        mass_kg=object_mass_kg(cfg, source, entry),
        source=source.source,
        friction=source.friction,
        notes=tuple(n for n in (*source.notes, area_note) if n),
    )


def job_object(job: Any, name: str) -> ObjectModel:
    """Object ``name`` as every trial of job config ``job`` sees it: dataset ``job.dataset``, a cloud of
    ``job.planner.n_points`` samples seeded by :func:`graspexp.core.seeding.cloud_seed` (the same cloud
    for every trial of the object, in the runner, ``graspexp.tools.plan``, re-simulation and the benches)."""
    return load_object(job.dataset, name, int(job.planner.n_points), cloud_seed(job, name))


def select_objects(dataset: Any, objects: list[str] | None) -> list[str]:
    """The objects to run: ``objects`` if given (each must be in the dataset's catalogue, not only in its
    default list), else the dataset's list less the objects whose files are missing (named in a warning
    with the download command). ``dataset``: the job's ``dataset`` config."""
    if objects:
        names = catalogue(dataset)
        unknown = [o for o in objects if o not in names]
        if unknown:
            raise DatasetError(
                f"unknown object(s) {unknown} in dataset {dataset.name!r}; valid: {', '.join(names)}"
            )
        return list(objects)
    names = dataset_objects(dataset)
    present = available_objects(dataset)
    if not present:
        load_object(dataset, names[0], 16, 0)  # raises the DatasetError that names the missing path
    missing = [o for o in names if o not in present]
    if missing:
        log.warning(
            "dataset %s: no mesh for %s under the data root; skipping them (get them with "
            "`python -m graspexp download dataset=%s`)",
            dataset.name,
            missing,
            dataset.name,
        )
    return [o for o in names if o in present]
