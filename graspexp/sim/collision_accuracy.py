"""How far an object's collision shape sticks out of its mesh.

The collision shape is a union of convex hulls or one closed mesh. Its surface is sampled uniformly by area
(for hulls: points of one hull inside another, or on a cut plane two hulls share, are not on the union's
surface and are dropped), and each sample's
signed distance to the mesh is measured: positive outside the mesh, negative inside.

"Outside" is decided by the nearest mesh face: the sign of ``(p - c) . n`` where ``c`` is the closest
point on the mesh and ``n`` the normal of the face that holds ``c``. This needs no watertight mesh (the
YCB google_16k meshes are not), only consistently outward face normals, which scanned meshes have; it
is exact for a closed mesh wherever the closest point lies inside a face, and at a convex edge or
vertex every adjacent face gives the same sign.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import trimesh

from graspexp.sim.shape import CollisionShape

_ON_HULL_M = 1e-5
"""Tolerance for a sample to lie on another hull's boundary, m."""


@dataclass(frozen=True)
class ShapeAccuracy:
    """Distances of the collision surface from the mesh, mm (percentiles over area-uniform samples)."""

    outside_p50_mm: float
    """Median of max(0, signed distance): half the collision surface sticks out less than this."""
    outside_p90_mm: float
    """90th percentile of max(0, signed distance): the headline figure (target <= 1 mm)."""
    outside_max_mm: float
    inside_p90_mm: float
    """90th percentile of max(0, -signed distance): how deep the collision surface sinks into the mesh."""
    n_samples: int


def union_surface_points(hulls: list[np.ndarray], n: int, *, rng: np.random.Generator) -> np.ndarray:
    """About ``n`` points uniform by area on the surface of the union of ``hulls``.

    ``hulls``: convex pieces as (V, 3) vertex arrays, object frame, metres. Returns (m, 3) float64,
    object frame, metres, with m <= n (samples inside another hull, or on an inner cut between two hulls, are dropped; an outer face two hulls share counts once).
    """
    pieces = [trimesh.convex.convex_hull(np.asarray(h, dtype=np.float64)) for h in hulls]
    areas = np.array([p.area for p in pieces])
    counts = rng.multinomial(n, areas / areas.sum())
    points = []
    for i, (piece, k) in enumerate(zip(pieces, counts, strict=True)):
        if k == 0:
            continue
        p, face = trimesh.sample.sample_surface(piece, int(k), seed=int(rng.integers(2**31)))
        own_normal = piece.face_normals[face]
        keep = np.ones(len(p), dtype=bool)
        for j, other in enumerate(pieces):
            if j == i:
                continue
            # signed height of each sample over each facet plane of the other hull (inside: all < 0)
            height = p @ other.face_normals.T - np.einsum(
                "ij,ij->i", other.face_normals, other.triangles[:, 0]
            )
            inside = height.max(axis=1) < -_ON_HULL_M
            on = ~inside & (height.max(axis=1) <= _ON_HULL_M)
            # on the other hull's boundary: a facet facing the same way is shared outer surface (kept
            # once, from the lower index); a facet facing the other way is an inner cut between hulls
            same_way = ((np.abs(height) <= _ON_HULL_M) & (own_normal @ other.face_normals.T > 0.99)).any(
                axis=1
            )
            keep &= ~inside & ~(on & ~(same_way & (i < j)))
        points.append(p[keep])
    return np.concatenate(points) if points else np.zeros((0, 3))


def surface_points(shape: CollisionShape, n: int, *, rng: np.random.Generator) -> np.ndarray:
    """About ``n`` points uniform by area on the surface of ``shape`` ((m, 3), object frame, metres)."""
    if shape.convex:
        return union_surface_points([v for v, _ in shape.parts], n, rng=rng)
    points, _ = trimesh.sample.sample_surface(shape.meshes()[0], n, seed=int(rng.integers(2**31)))
    return points


def signed_distance_m(points: np.ndarray, mesh: trimesh.Trimesh) -> np.ndarray:
    """Signed distance of ``points`` ((n, 3), object frame, m) to ``mesh``: (n,) m, positive outside.

    The sign comes from the normal of the nearest face (see the module docstring).
    """
    closest, dist, face = trimesh.proximity.closest_point(mesh, points)
    side = np.einsum("ij,ij->i", points - closest, mesh.face_normals[face])
    return np.where(side < 0.0, -dist, dist)


def uncovered_m(points: np.ndarray, shape: CollisionShape) -> np.ndarray:
    """How far each point ((n, 3), object frame, m; e.g. samples of the mesh surface) lies outside
    ``shape``: (n,) m, 0 inside. A fingertip on such a point would sink that deep into the object.

    Each closed piece (a hull, or a shell of the ``mesh`` shape) gives a signed distance by the nearest
    face's normal; the union's is the smallest.
    """
    pieces = [
        p for m in shape.meshes() for p in (m.split(only_watertight=False) if not shape.convex else [m])
    ]
    if shape.convex:
        pieces = [trimesh.convex.convex_hull(np.asarray(m.vertices, dtype=np.float64)) for m in pieces]
    d = np.min([signed_distance_m(points, piece) for piece in pieces], axis=0)
    return np.maximum(d, 0.0)


def shape_accuracy(surface_points: np.ndarray, mesh: trimesh.Trimesh) -> ShapeAccuracy:
    """Outside/inside distances of collision-surface samples ((n, 3), object frame, m) against ``mesh``."""
    d = signed_distance_m(surface_points, mesh) * 1e3
    out, ins = np.maximum(d, 0.0), np.maximum(-d, 0.0)
    return ShapeAccuracy(
        outside_p50_mm=float(np.median(out)),
        outside_p90_mm=float(np.percentile(out, 90)),
        outside_max_mm=float(out.max()),
        inside_p90_mm=float(np.percentile(ins, 90)),
        n_samples=len(surface_points),
    )
