"""The volume checks of :mod:`.collision` for a URDF gripper: its convex pieces, swept along the approach.

A piece (:class:`graspexp.grippers.HandMeshes`) is a convex hull in the gripper frame (+Z
approach, +Y closing axis, origin the TCP), a finger's at zero opening; half the opening ``w/2`` moves the
left finger's pieces along +Y and the right finger's along -Y. The trial moves the open gripper straight
from ``-sweep_m`` along +Z to the grasp pose, so a piece sweeps the hull of its vertices and the same
vertices moved ``sweep_m`` back along -Z. A cloud point collides when it lies inside a swept piece whose
half-spaces ``n . p <= d`` are pushed out by ``margin_m`` (``d + margin_m``), as the boxes of the box
model are grown by the margin on every side. Pure numpy/scipy plus one compiled kernel.
"""

import functools

import numpy as np
from scipy.spatial import ConvexHull

from graspexp.grippers.urdf import SLIDE, HandMeshes
from graspexp.planning.kernels import COUNT_ALL, swept_hull_hits


def _swept_vertices(hull: np.ndarray, sweep_m: float) -> np.ndarray:
    """(2V, 3) a piece's vertices and the same moved ``sweep_m`` back along -Z, gripper frame, m."""
    return np.concatenate([hull, hull - [0.0, 0.0, sweep_m]])


@functools.lru_cache(maxsize=16)
def _half_spaces(hand: HandMeshes, sweep_m: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Unit normals (P, F, 3) and offsets (P, F) of the swept pieces' faces (``n . p <= d``, zero opening,
    no margin; padding rows: zero normal, offset 0) and the pieces' slides (P,)."""
    planes = [ConvexHull(_swept_vertices(h, sweep_m)).equations for h in hand.hulls]  # n . p + c <= 0
    faces = max(len(e) for e in planes)
    normals = np.zeros((len(planes), faces, 3))
    offsets = np.zeros((len(planes), faces))
    for p, e in enumerate(planes):
        normals[p, : len(e)] = e[:, :3]
        offsets[p, : len(e)] = -e[:, 3]
    slides = np.array([SLIDE[part] for part in hand.hull_parts], dtype=np.float64)
    return normals, offsets, slides


def hull_lowest_z(poses: np.ndarray, hand: HandMeshes, widths_m: np.ndarray, sweep_m: float) -> np.ndarray:
    """(B,) lowest world z of any swept piece for each of (B, 4, 4) world grasp poses and (B,) openings, m."""
    vertices = np.concatenate([_swept_vertices(h, sweep_m) for h in hand.hulls])  # (M, 3)
    slides = np.concatenate(
        [np.full(2 * len(h), SLIDE[p]) for h, p in zip(hand.hulls, hand.hull_parts, strict=True)]
    )
    r = poses[:, 2, :3]  # (B, 3): row z of each rotation
    z = r @ vertices.T + (np.asarray(widths_m, dtype=np.float64) / 2)[:, None] * slides[None] * r[:, 1:2]
    return poses[:, 2, 3] + z.min(axis=1)


def hull_cloud_hits(
    points_m: np.ndarray,
    poses: np.ndarray,
    hand: HandMeshes,
    widths_m: np.ndarray,
    *,
    sweep_m: float,
    margin_m: float,
    stop_at: int = COUNT_ALL,
) -> np.ndarray:
    """(B,) number of cloud points (N, 3) world inside the swept pieces grown by ``margin_m`` (module doc),
    for (B, 4, 4) world grasp poses and (B,) openings, m, counted up to ``stop_at``; 0 means collision-free."""
    normals, offsets, slides = _half_spaces(hand, sweep_m)
    grown = np.where(np.any(normals != 0, axis=2), offsets + margin_m, 1.0)
    swept = [_swept_vertices(h, sweep_m) for h in hand.hulls]
    lo = np.array([v.min(axis=0) for v in swept]) - margin_m
    hi = np.array([v.max(axis=0) for v in swept]) + margin_m
    return swept_hull_hits(
        np.ascontiguousarray(points_m, dtype=np.float64),
        np.ascontiguousarray(poses, dtype=np.float64),
        np.ascontiguousarray(np.asarray(widths_m, dtype=np.float64) / 2),
        normals,
        np.ascontiguousarray(grown),
        slides,
        lo,
        hi,
        stop_at,
    )
