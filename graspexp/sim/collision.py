"""Convex decomposition of object meshes with CoACD, cached on disk.

The cache key is the SHA-256 of the mesh content (merged vertices and faces) and the decomposition
parameters, so a changed mesh or a changed parameter never reuses a stale decomposition.
"""

import hashlib
import json
import os
import tempfile
from pathlib import Path

import numpy as np
import trimesh

from graspexp.config import SimConfig


def cache_dir(cfg: SimConfig) -> Path:
    """``sim.cache_dir``, else env ``GRASPEXP_CACHE``, else ``~/.cache/graspexp``; ``coacd/`` below it."""
    base = cfg.cache_dir or os.environ.get("GRASPEXP_CACHE") or Path.home() / ".cache" / "graspexp"
    return Path(base) / "coacd"


def coacd_params(cfg: SimConfig) -> dict:
    """The CoACD keyword arguments taken from ``conf/sim`` (seed fixed: decompositions are deterministic)."""
    return {
        "threshold": float(cfg.coacd_threshold),
        "preprocess_resolution": int(cfg.coacd_preprocess_resolution),
        "resolution": int(cfg.coacd_resolution),
        "mcts_iterations": int(cfg.coacd_mcts_iterations),
        "max_convex_hull": int(cfg.coacd_max_convex_hull),
        "seed": 0,
    }


def mesh_key(mesh: trimesh.Trimesh, params: dict) -> str:
    """Content hash of the mesh geometry and the decomposition parameters."""
    h = hashlib.sha256()
    h.update(np.ascontiguousarray(mesh.vertices, dtype=np.float64).tobytes())
    h.update(np.ascontiguousarray(mesh.faces, dtype=np.int64).tobytes())
    h.update(json.dumps(params, sort_keys=True).encode())
    return h.hexdigest()[:32]


def convex_hulls(mesh: trimesh.Trimesh, cfg: SimConfig) -> list[np.ndarray]:
    """Convex pieces of ``mesh`` as a list of (V, 3) float32 vertex arrays, object frame, metres.

    A mesh that is already convex (within 0.1 % of its hull volume) is used as one hull without CoACD.
    """
    params = coacd_params(cfg)
    path = cache_dir(cfg) / f"{mesh_key(mesh, params)}.npz"
    if path.exists():
        with np.load(path) as data:
            return [data[k] for k in sorted(data.files, key=lambda s: int(s.split("_")[1]))]
    hulls = _decompose(mesh, params)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".npz.partial")
    with os.fdopen(fd, "wb") as f:
        np.savez(f, **{f"hull_{i}": h for i, h in enumerate(hulls)})
    os.replace(tmp, path)
    return hulls


def _decompose(mesh: trimesh.Trimesh, params: dict) -> list[np.ndarray]:
    hull = mesh.convex_hull
    if mesh.is_volume and abs(hull.volume - mesh.volume) <= 1e-3 * hull.volume:
        return [np.asarray(hull.vertices, dtype=np.float32)]
    import coacd

    coacd.set_log_level("error")
    parts = coacd.run_coacd(coacd.Mesh(np.asarray(mesh.vertices), np.asarray(mesh.faces)), **params)
    hulls = [np.asarray(v, dtype=np.float32) for v, _ in parts]
    if not hulls:
        raise ValueError(f"convex decomposition of the mesh returned no hull (params {params})")
    return hulls


def hull_meshes(hulls: list[np.ndarray]) -> list[trimesh.Trimesh]:
    """Triangle meshes of the hulls (for the MCAP scene), object frame, metres."""
    return [trimesh.convex.convex_hull(h) for h in hulls]
