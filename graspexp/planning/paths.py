"""Grasping paths from a Fibonacci sphere (paper III-C) and the support-plane test (III-D, Fig. 8).

Around each cluster centre ``c_k`` sits a sphere of radius ``R`` carrying ``M`` evenly spread points
``c_k + R u_p`` (``u_p`` unit, a Fibonacci lattice). Path ``p`` of cluster ``k`` runs in a straight line
from its sphere point to the centre, so its approach direction is ``d_p = -u_p``. The lattice is the
same for every cluster; only the centre moves.

A path is infeasible when its sphere point (the pre-grasp standoff) lies below the support plane
``z = table_z + clearance``: the gripper would come up through the box/table top. Because the centre
lies above the plane (it is a mean of surface points of an object standing on it), the whole segment is
then above the plane exactly when the sphere point is.
"""

from functools import lru_cache

import numpy as np

from graspexp.planning.neighbour_kernels import occupancy_grid, paths_clear

GOLDEN_ANGLE_RAD = np.pi * (3.0 - np.sqrt(5.0))
"""Azimuth increment of the Fibonacci lattice, radians (about 137.5 degrees)."""


@lru_cache(maxsize=8)
def fibonacci_sphere(m: int) -> np.ndarray:
    """``m`` evenly spread unit vectors.

    Point ``i`` has height ``z_i = 1 - (2 i + 1) / m`` (equal-area bands, so ``sum z_i = 0``) and azimuth
    ``i * golden_angle``.

    Returns
    -------
    (m, 3) float64 unit vectors (norm 1 to rounding), read-only (the lattice is cached per ``m``).
    """
    if m < 1:
        raise ValueError(f"m={m!r} is invalid: expected a positive number of paths")
    i = np.arange(m, dtype=np.float64)
    z = 1.0 - (2.0 * i + 1.0) / m
    rho = np.sqrt(np.clip(1.0 - z * z, 0.0, None))
    theta = i * GOLDEN_ANGLE_RAD
    lattice = np.stack([rho * np.cos(theta), rho * np.sin(theta), z], axis=1)
    lattice.flags.writeable = False
    return lattice


def approach_directions(centers_m: np.ndarray, m: int) -> np.ndarray:
    """Approach directions of every path.

    centers_m : (K, 3) cluster centres, world, metres (only K is used: the lattice is shared).

    Returns
    -------
    (K, m, 3) float64 unit vectors ``d = -u_p`` pointing from the sphere point towards the centre.
    """
    u = fibonacci_sphere(m)
    return np.broadcast_to(-u, (len(centers_m), m, 3)).copy()


def sphere_points(centers_m: np.ndarray, directions: np.ndarray, sphere_radius_m: float) -> np.ndarray:
    """Start point ``c_k - R d`` (= ``c_k + R u_p``) of every path.

    centers_m : (K, 3) world, metres; directions : (K, M, 3) unit approach directions.

    Returns
    -------
    (K, M, 3) float64, world, metres.
    """
    return centers_m[:, None, :] - sphere_radius_m * directions


def above_support(
    centers_m: np.ndarray,
    directions: np.ndarray,
    sphere_radius_m: float,
    table_z_m: float,
    clearance_m: float,
) -> np.ndarray:
    """(K, M) bool: True where the path's sphere point is at or above ``z = table_z_m + clearance_m``."""
    return sphere_points(centers_m, directions, sphere_radius_m)[..., 2] >= table_z_m + clearance_m


MAX_GRID_CELLS = 1 << 26
"""Largest occupancy grid (:func:`clear_of`), cubes (64 MB); past it the obstacle's sorted cube keys serve."""


def clear_of(
    centers_m: np.ndarray,
    radii_m: np.ndarray,
    directions: np.ndarray,
    sphere_radius_m: float,
    obstacle_m: np.ndarray,
    voxel_m: float,
) -> np.ndarray:
    """(K, M) bool: True where the path from the sphere point towards its centre passes through no occupied
    cube of side ``voxel_m`` (m) of the obstacle cloud ``obstacle_m`` ((N, 3) world m: the other objects of a
    clutter round). The path is sampled every ``voxel_m / 2`` from the sphere point to ``radii_m`` (K,) m
    (the cluster radius r_k) from the centre: nearer, the fingers close about the target, and what they may
    meet there is the swept check's to judge. Compiled (:func:`graspexp.planning.neighbour_kernels.
    paths_clear`, an occupancy grid, each path's scan ending at its first occupied cube)."""
    k, m = directions.shape[:2]
    if len(obstacle_m) == 0:
        return np.ones((k, m), dtype=bool)
    n = int(np.ceil(sphere_radius_m / (voxel_m / 2))) + 1
    frac = np.linspace(0.0, 1.0, n)
    start = np.minimum(np.asarray(radii_m, dtype=np.float64), sphere_radius_m)
    steps = start[:, None] + frac[None, :] * (sphere_radius_m - start[:, None])  # (K, S) m from the centre
    obstacle = np.ascontiguousarray(obstacle_m, dtype=np.float64)
    grid, first = occupancy_grid(obstacle, voxel_m, MAX_GRID_CELLS)
    centers = np.ascontiguousarray(centers_m, dtype=np.float64)
    if grid.size:
        return paths_clear(
            centers, steps, np.ascontiguousarray(directions, dtype=np.float64), grid, first, voxel_m
        )
    occupied = np.unique(_cube_keys(obstacle, voxel_m))
    samples = centers[:, None, None, :] - steps[:, None, :, None] * directions[:, :, None, :]  # (K, M, S, 3)
    keys = _cube_keys(samples.reshape(-1, 3), voxel_m)
    at = np.minimum(np.searchsorted(occupied, keys), len(occupied) - 1)
    return ~(occupied[at] == keys).reshape(k, m, n).any(axis=2)


def _cube_keys(points_m: np.ndarray, voxel_m: float) -> np.ndarray:
    """(N,) int64 key of the cube of side ``voxel_m`` holding each point (21 bits per axis: +-1 km at 1 mm)."""
    idx = np.floor(np.asarray(points_m, dtype=np.float64) / voxel_m).astype(np.int64) + (1 << 20)
    return (idx[:, 0] << 42) | (idx[:, 1] << 21) | idx[:, 2]
