"""The offline default dataset: six household-like shapes made by code (no download).

Object frame as in YCB google_16k: z up, metres, base at z = 0, roughly centred in x and y. Every mesh
is deterministic (no randomness at all) and watertight, except ``mug``, whose handle is a separate
closed tube whose ends are buried in the cup wall (a concatenation, not a boolean union).
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import trimesh

SECTIONS = 64
"""Segments around every surface of revolution and tube."""


def _revolve(profile_rz_m: list[tuple[float, float]]) -> trimesh.Trimesh:
    """Surface of revolution about z of a (radius, z) profile, metres, that starts and ends on the axis."""
    mesh = trimesh.creation.revolve(np.asarray(profile_rz_m, dtype=float), sections=SECTIONS)
    if mesh.volume < 0:
        mesh.invert()
    return mesh


def _tube(path_m: np.ndarray, radius_m: float) -> trimesh.Trimesh:
    """A closed tube of circular section (``radius_m``) along the polyline ``path_m`` (n, 3), flat caps.

    Frames are propagated along the path (parallel transport) so the rings do not twist.
    """
    path = np.asarray(path_m, dtype=float)
    tangents = np.gradient(path, axis=0)
    tangents /= np.linalg.norm(tangents, axis=1, keepdims=True)
    helper = np.array([0.0, 0.0, 1.0]) if abs(tangents[0, 2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    u = np.cross(tangents[0], helper)
    u /= np.linalg.norm(u)
    angles = np.linspace(0.0, 2.0 * np.pi, SECTIONS, endpoint=False)
    rings = []
    for i, t in enumerate(tangents):
        if i > 0:
            u = u - np.dot(u, t) * t
            u /= np.linalg.norm(u)
        v = np.cross(t, u)
        rings.append(path[i] + radius_m * (np.outer(np.cos(angles), u) + np.outer(np.sin(angles), v)))
    n_ring, n_sec = len(rings), SECTIONS
    vertices = np.vstack([*rings, path[0], path[-1]])
    faces = []
    for i in range(n_ring - 1):
        for j in range(n_sec):
            a, b = i * n_sec + j, i * n_sec + (j + 1) % n_sec
            c, d = a + n_sec, b + n_sec
            faces += [[a, b, d], [a, d, c]]
    start, end = n_ring * n_sec, n_ring * n_sec + 1
    last = (n_ring - 1) * n_sec
    for j in range(n_sec):
        faces.append([start, (j + 1) % n_sec, j])
        faces.append([end, last + j, last + (j + 1) % n_sec])
    mesh = trimesh.Trimesh(vertices, np.asarray(faces), process=True)
    if mesh.volume < 0:
        mesh.invert()
    return mesh


def can() -> trimesh.Trimesh:
    """Closed cylinder, radius 33 mm, height 100 mm (a soup can)."""
    return _revolve([(0.0, 0.0), (0.033, 0.0), (0.033, 0.100), (0.0, 0.100)])


def box() -> trimesh.Trimesh:
    """Box 50 x 80 x 120 mm (x, y, z)."""
    return trimesh.creation.box(extents=[0.050, 0.080, 0.120], transform=_lift(0.060))


def bottle() -> trimesh.Trimesh:
    """Bottle: body diameter 60 mm up to 140 mm, conical shoulder, neck diameter 24 mm, 190 mm tall."""
    return _revolve([(0.0, 0.0), (0.030, 0.0), (0.030, 0.140), (0.012, 0.165), (0.012, 0.190), (0.0, 0.190)])


def mug() -> trimesh.Trimesh:
    """Mug: open cup (outer diameter 80 mm, wall 5 mm, floor 6 mm, 95 mm tall), handle on the +x side.

    The handle is a C-shaped tube (radius 6 mm) from z = 25 mm to z = 75 mm reaching x = 65 mm; its
    ends sit inside the cup wall (x = 37.5 mm), so the two parts are concatenated, not unioned.
    """
    cup = _revolve([(0.0, 0.0), (0.040, 0.0), (0.040, 0.095), (0.035, 0.095), (0.035, 0.006), (0.0, 0.006)])
    theta = np.linspace(-np.pi / 2, np.pi / 2, 25)
    centre_x, centre_z, reach_x, half_z = 0.0375, 0.050, 0.0275, 0.025
    path = np.column_stack(
        [centre_x + reach_x * np.cos(theta), np.zeros_like(theta), centre_z + half_z * np.sin(theta)]
    )
    return trimesh.util.concatenate([cup, _tube(path, 0.006)])


def banana() -> trimesh.Trimesh:
    """Banana: tube of diameter 35 mm along a 100-degree arc in the xy plane, 180 mm along the arc.

    The middle of the arc bulges towards +x; its chord runs along y; it lies on the table (z 0 to 35 mm).
    """
    radius_m, length_m, arc = 0.035 / 2, 0.180, np.deg2rad(100.0)
    bend_radius = length_m / arc
    phi = np.linspace(-arc / 2, arc / 2, 33)
    x = -bend_radius * (1.0 - np.cos(phi))
    path = np.column_stack([x, bend_radius * np.sin(phi), np.full_like(phi, radius_m)])
    mesh = _tube(path, radius_m)
    centre = mesh.bounds.mean(axis=0)
    mesh.apply_translation([-centre[0], -centre[1], -mesh.bounds[0, 2]])
    return mesh


def block() -> trimesh.Trimesh:
    """Wood-block-like box 85 x 85 x 200 mm."""
    return trimesh.creation.box(extents=[0.085, 0.085, 0.200], transform=_lift(0.100))


def _lift(z_m: float) -> np.ndarray:
    transform = np.eye(4)
    transform[2, 3] = z_m
    return transform


PRIMITIVES: dict[str, Callable[[], trimesh.Trimesh]] = {
    "can": can,
    "box": box,
    "bottle": bottle,
    "mug": mug,
    "banana": banana,
    "block": block,
}
"""Name -> mesh builder; names match ``conf/dataset/primitives.yaml``."""
