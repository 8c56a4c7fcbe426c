"""Object collision shapes, cached on disk by mesh content and parameters.

Three methods (``sim.collision_method``):

* ``mesh``: each sizeable part of the mesh repaired to a closed, manifold surface (MeshFix; scanned
  meshes have holes and loose bits), decimated to ``sim.mesh_max_faces`` triangles, repaired again, and collided as one PhysX
  triangle mesh with an SDF (PhysX simulates a dynamic triangle mesh only with an SDF). Supports and
  floors must then be boxes: PhysX makes no contacts between such a mesh and a plane.
* ``coacd`` / ``vhacd``: a convex decomposition (CoACD, or V-HACD through ``vhacdx``); one convex
  PhysX shape per hull.

The cache key is the SHA-256 of the mesh content (merged vertices and faces) and the method's
parameters, so a changed mesh or parameter never reuses a stale shape. ``mesh`` also writes the mesh as
an OBJ file beside the cache entry: SAPIEN cooks a mesh file once per process and reuses it.
"""

import dataclasses
import hashlib
import json
import logging
import os
import sys
from contextlib import contextmanager
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

import numpy as np
import trimesh
from omegaconf import OmegaConf

from graspexp.config import SimConfig
from graspexp.core.files import write_atomic
from graspexp.sim.collision_accuracy import shape_accuracy, surface_points
from graspexp.sim.shape import CollisionShape

log = logging.getLogger(__name__)
METHODS = ("mesh", "coacd", "vhacd")
FALLBACK_METHOD = "coacd"
"""The method an object falls back to when ``mesh`` cannot repair it (a convex decomposition needs no
closed surface)."""


class ShapeError(ValueError):
    """No collision shape can be built for a mesh (the message names why and what to try)."""


class RepairError(ShapeError):
    """``sim.collision_method=mesh`` cannot repair a part of the mesh into a closed surface."""


def cache_dir(cfg: SimConfig) -> Path:
    """``sim.cache_dir``, else env ``GRASPEXP_CACHE``, else ``~/.cache/graspexp``; ``collision/`` below it."""
    base = cfg.cache_dir or os.environ.get("GRASPEXP_CACHE") or Path.home() / ".cache" / "graspexp"
    return Path(base) / "collision"


def shape_params(cfg: SimConfig) -> dict:
    """The method and its parameters from ``conf/sim`` (seeds fixed: every method is deterministic)."""
    method = cfg.collision_method
    if method == "mesh":
        return {
            "method": method,
            "max_faces": int(cfg.mesh_max_faces),
            "min_part_area": float(cfg.mesh_min_part_area),
            "tolerance_m": float(cfg.mesh_tolerance_m),
            "sdf_spacing_m": float(cfg.sdf_spacing_m),
        }
    if method == "coacd":
        return {
            "method": method,
            "threshold": float(cfg.coacd_threshold),
            "preprocess_resolution": int(cfg.coacd_preprocess_resolution),
            "resolution": int(cfg.coacd_resolution),
            "mcts_iterations": int(cfg.coacd_mcts_iterations),
            "max_convex_hull": int(cfg.coacd_max_convex_hull),
            "seed": 0,
        }
    if method == "vhacd":
        return {
            "method": method,
            "maxConvexHulls": int(cfg.vhacd_max_hulls),
            "resolution": int(cfg.vhacd_resolution),
            "minimumVolumePercentErrorAllowed": float(cfg.vhacd_min_volume_error_pct),
            "shrinkWrap": bool(cfg.vhacd_shrinkwrap),
        }
    raise ValueError(f"sim.collision_method={method!r} is invalid: expected one of {', '.join(METHODS)}")


CACHE_FORMAT = 2
"""Version of the cache entries' layout and builders, part of every key: bump it when a builder changes."""
METHOD_LIBRARIES = {
    "mesh": ("pymeshfix", "fast-simplification", "trimesh"),
    "coacd": ("coacd", "trimesh"),
    "vhacd": ("vhacdx", "trimesh"),
}
"""The libraries whose versions are part of a method's cache key (an upgrade rebuilds the shapes)."""


def _library_versions(method: str) -> dict[str, str]:
    out = {}
    for name in METHOD_LIBRARIES[method]:
        try:
            out[name] = version(name)
        except PackageNotFoundError:
            out[name] = "absent"
    return out


def mesh_key(mesh: trimesh.Trimesh, params: dict) -> str:
    """Content hash of the mesh geometry, the shape parameters, :data:`CACHE_FORMAT` and the versions of the
    method's libraries (the cache file's name, and the ``collision_key`` of a trial's log)."""
    h = hashlib.sha256()
    h.update(np.ascontiguousarray(mesh.vertices, dtype=np.float64).tobytes())
    h.update(np.ascontiguousarray(mesh.faces, dtype=np.int64).tobytes())
    versioned = {**params, "cache_format": CACHE_FORMAT, "libraries": _library_versions(params["method"])}
    h.update(json.dumps(versioned, sort_keys=True).encode())
    return h.hexdigest()[:32]


def is_cached(mesh: trimesh.Trimesh, cfg: SimConfig) -> bool:
    """Whether :func:`collision_shape` would read ``mesh``'s shape from the cache (an intact entry)."""
    params = shape_params(cfg)
    return _read_entry(cache_dir(cfg) / f"{mesh_key(mesh, params)}.npz") is not None


def collision_shape(mesh: trimesh.Trimesh, cfg: SimConfig) -> CollisionShape:
    """The collision shape of ``mesh`` (object frame, metres) for ``cfg.collision_method``: from the
    cache, or built and cached. A mesh that is already convex (within 0.1 % of its hull volume) is its
    own single hull under every method.

    Every cache entry records the SHA-256 of its parts (and of the OBJ file SAPIEN cooks); an entry or OBJ
    that does not match (damaged, cut, edited) is rebuilt and rewritten, never used.
    """
    params = shape_params(cfg)
    key = mesh_key(mesh, params)
    path = cache_dir(cfg) / f"{key}.npz"
    entry = _read_entry(path)
    if entry is None:
        if path.exists():
            log.warning("collision cache entry %s does not match its checksum; rebuilding it", path)
        convex, parts = _build(mesh, params)
        obj_text = b"" if convex else _obj_text(parts[0])
        arrays = {f"{kind}_{i}": a for i, (v, f) in enumerate(parts) for kind, a in (("v", v), ("f", f))}
        digests = {"sha256": _parts_digest(convex, parts), "obj_sha256": hashlib.sha256(obj_text).hexdigest()}
        write_atomic(path, lambda fh: np.savez(fh, convex=convex, n_parts=len(parts), **digests, **arrays))
        entry = (convex, tuple(parts), digests["obj_sha256"], digests["sha256"])
    convex, parts, obj_sha256, sha256 = entry
    if convex:
        return CollisionShape(params["method"], parts, True, key=key, sha256=sha256)
    obj = path.with_suffix(".obj")  # OBJ: SAPIEN 3.0.3 crashes cooking some binary PLY files (16k faces)
    if not obj.is_file() or hashlib.sha256(obj.read_bytes()).hexdigest() != obj_sha256:
        if obj.exists():
            log.warning("collision cache file %s does not match its checksum; rewriting it", obj)
        text = _obj_text(parts[0])
        write_atomic(obj, lambda fh: fh.write(text))
    return CollisionShape(params["method"], parts, False, obj, key=key, sha256=sha256)


def _obj_text(part: tuple[np.ndarray, np.ndarray]) -> bytes:
    return trimesh.Trimesh(*part, process=False).export(file_type="obj", include_normals=False).encode()


def _parts_digest(convex: bool, parts) -> str:
    h = hashlib.sha256(b"convex" if convex else b"mesh")
    for v, f in parts:
        h.update(np.ascontiguousarray(v, dtype=np.float32).tobytes())
        h.update(np.ascontiguousarray(f, dtype=np.int64).tobytes())
    return h.hexdigest()


def _read_entry(path: Path) -> tuple[bool, tuple, str, str] | None:
    """(convex, parts, OBJ checksum, parts' checksum) of an intact cache entry; None when absent,
    unreadable or damaged (an entry rewritten with a matching checksum is intact: the checksum guards
    against damage, not against another writer; the logs record the parts' checksum, module doc)."""
    try:
        with np.load(path) as data:
            n, convex = int(data["n_parts"]), bool(data["convex"])
            parts = tuple((data[f"v_{i}"], data[f"f_{i}"]) for i in range(n))
            digest, obj_sha256 = str(data["sha256"]), str(data["obj_sha256"])
    except FileNotFoundError:
        return None
    except Exception:  # a truncated zip, a missing array, a bad header: rebuilt by the caller
        return None
    return (convex, parts, obj_sha256, digest) if _parts_digest(convex, parts) == digest else None


def shape_with_fallback(mesh: trimesh.Trimesh, cfg: SimConfig) -> tuple[CollisionShape, str]:
    """(shape, note): :func:`collision_shape` under ``cfg``; a mesh that ``mesh`` cannot repair (an open
    low-poly CAD export, say) gets :data:`FALLBACK_METHOD` instead, and the note says so with the measured
    accuracy of the shape it got ("" when the configured method worked). The failed repair and the note
    are cached beside the shapes (``<key>.fallback.json``, the configured method's key), so later jobs
    neither repeat the repair nor measure again."""
    record = cache_dir(cfg) / f"{mesh_key(mesh, shape_params(cfg))}.fallback.json"
    note = _read_fallback(record)
    if note is None:
        try:
            return collision_shape(mesh, cfg), ""
        except RepairError as err:
            why = str(err).split(";")[0]
    shape = collision_shape(mesh, _with_method(cfg, FALLBACK_METHOD))
    if note is None:
        acc = shape_accuracy(surface_points(shape, 2000, rng=np.random.default_rng(0)), mesh)
        note = (
            f"collision: {FALLBACK_METHOD} (fallback: sim.collision_method={cfg.collision_method} failed: "
            f"{why}); its surface lies outside the mesh by {acc.outside_p50_mm:.2f} mm median, "
            f"{acc.outside_p90_mm:.2f} mm p90, {acc.outside_max_mm:.2f} mm max"
        )
        text = json.dumps({"note": note}).encode()
        write_atomic(record, lambda fh: fh.write(text))
    return shape, note


def _read_fallback(path: Path) -> str | None:
    """The note of a cached fallback record; None when absent or unreadable (the repair is tried again)."""
    try:
        note = json.loads(path.read_text())["note"]
    except (OSError, ValueError, KeyError, TypeError):
        return None
    return note if isinstance(note, str) and note.startswith("collision: ") else None


def _with_method(cfg: SimConfig, method: str) -> SimConfig:
    """``cfg`` with ``collision_method`` replaced (a SimConfig dataclass or its DictConfig)."""
    if dataclasses.is_dataclass(cfg):
        return dataclasses.replace(cfg, collision_method=method)
    return OmegaConf.merge(cfg, {"collision_method": method})


def _build(mesh: trimesh.Trimesh, params: dict) -> tuple[bool, list[tuple[np.ndarray, np.ndarray]]]:
    """(convex, parts) for ``mesh`` under ``params`` (see :func:`collision_shape`)."""
    hull = mesh.convex_hull
    if mesh.is_volume and abs(hull.volume - mesh.volume) <= 1e-3 * hull.volume:
        return True, [_part(hull.vertices, hull.faces)]
    method = params["method"]
    if method == "mesh":
        return False, [_closed_mesh(mesh, params)]
    if method == "coacd":
        import coacd

        coacd.set_log_level("error")
        kw = {k: v for k, v in params.items() if k != "method"}
        raw = coacd.run_coacd(coacd.Mesh(np.asarray(mesh.vertices), np.asarray(mesh.faces)), **kw)
    else:
        import vhacdx

        kw = {k: v for k, v in params.items() if k != "method"}
        raw = vhacdx.compute_vhacd(np.asarray(mesh.vertices), np.asarray(mesh.faces, dtype=np.uint32), **kw)
    parts = [_part(v, f) for v, f in raw]
    if not parts:
        raise ShapeError(f"convex decomposition of the mesh returned no hull (params {params})")
    return True, parts


def _part(vertices: np.ndarray, faces: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return np.asarray(vertices, dtype=np.float32), np.asarray(faces, dtype=np.int64)


def _closed_mesh(mesh: trimesh.Trimesh, params: dict) -> tuple[np.ndarray, np.ndarray]:
    """``mesh`` as closed manifold shells, checked against ``mesh``.

    Each connected component with at least ``min_part_area`` of the mesh's area (smaller ones are scan
    debris) is repaired by MeshFix, decimated to its share (by area) of the face budget and repaired
    again. Decimation can collapse a thin wall, so the result is measured: if the 90th percentile of
    its surface outside the mesh, or of the mesh outside it, exceeds ``tolerance_m``, the budget doubles
    (from ``max_faces`` up to no decimation). Returns the shells in one (vertices, faces) pair.
    """
    from graspexp.sim.collision_accuracy import signed_distance_m

    kept = [c for c in mesh.split(only_watertight=False) if c.area >= params["min_part_area"] * mesh.area]
    if not kept:  # a triangle soup: every connected part is as small as scan debris
        raise RepairError(
            f"no connected part of the mesh holds {params['min_part_area']:g} of its area (sim.mesh_min_part_area): "
            "its faces share no edges (a triangle soup?); use sim.collision_method=coacd for this object"
        )
    area = sum(c.area for c in kept)
    mesh_pts, _ = trimesh.sample.sample_surface(mesh, 2000, seed=0)
    budget = params["max_faces"]
    while True:
        shells = [_closed_shell(c, max(int(budget * c.area / area), 64)) for c in kept]
        joined = trimesh.util.concatenate(shells)
        own_pts, _ = trimesh.sample.sample_surface(joined, 2000, seed=0)
        out = np.percentile(np.maximum(signed_distance_m(own_pts, mesh), 0.0), 90)
        gap = np.percentile(
            np.maximum(np.min([signed_distance_m(mesh_pts, s) for s in shells], axis=0), 0.0), 90
        )
        if max(out, gap) <= params["tolerance_m"] or budget >= len(mesh.faces):
            return _part(joined.vertices, joined.faces)
        budget *= 2


def _closed_shell(component: trimesh.Trimesh, budget: int) -> trimesh.Trimesh:
    """One component repaired by MeshFix, decimated to ``budget`` faces and repaired again."""
    import pymeshfix

    with _quiet_stdio():  # MeshFix prints "could not fix everything" from C for shells it did close
        v, f = pymeshfix.clean_from_arrays(
            np.asarray(component.vertices), np.asarray(component.faces, dtype=np.int32)
        )
        if len(f) > budget:
            small = trimesh.Trimesh(v, f, process=False).simplify_quadric_decimation(face_count=budget)
            v, f = pymeshfix.clean_from_arrays(
                np.asarray(small.vertices), np.asarray(small.faces, dtype=np.int32)
            )
    shell = trimesh.Trimesh(v, f, process=False)
    if not shell.is_watertight or shell.volume <= 0:
        raise RepairError(
            "a part of the mesh could not be repaired into a closed surface for sim.collision_method=mesh "
            f"(after MeshFix: {len(f)} faces, watertight={shell.is_watertight}); "
            "use sim.collision_method=coacd for this object"
        )
    return shell


@contextmanager
def _quiet_stdio():
    """Silence the C-level stdout and stderr of a library call (Python's streams are flushed first)."""
    sys.stdout.flush()
    sys.stderr.flush()
    saved = [os.dup(1), os.dup(2)]
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, 1)
        os.dup2(devnull, 2)
        yield
    finally:
        os.dup2(saved[0], 1)
        os.dup2(saved[1], 2)
        for fd in (*saved, devnull):
            os.close(fd)


def hull_meshes(shape: CollisionShape) -> list[trimesh.Trimesh]:
    """Triangle meshes of the collision parts (for the MCAP scene), object frame, metres."""
    return shape.meshes()
