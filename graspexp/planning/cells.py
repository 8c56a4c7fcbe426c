"""The other objects' cloud of a clutter round sorted into cubes, so that the swept test of each path
(:func:`graspexp.planning.collision.neighbour_hits`) scans only the cubes near the gripper instead of the
~8000 points of four neighbours. The test stays exact: a cube's points are skipped only where the cube's
bounding sphere misses the gripper's volumes."""

from dataclasses import dataclass

import numpy as np

from graspexp.planning.neighbour_kernels import cube_sort

CELL_M = 0.02
"""Side of the cubes a neighbour cloud is sorted into, m: about a finger's width, so a swept finger or palm
box skips most cubes at the cost of one sphere test each. Only the speed depends on it (the test is
exact)."""

SPHERE_SLACK_M = 1e-9
"""Added to each cube's bounding radius, m: far above the rounding of a coordinate below a kilometre, so a
cube skipped by its sphere holds no point the exact test would accept."""


@dataclass(frozen=True)
class CellCloud:
    """A cloud sorted by cube: points : (N, 3) world m, cube by cube; starts : (C + 1,) int64, cube c holds
    ``points[starts[c]:starts[c + 1]]``; centres : (C, 3) the middle of each cube's points' box, m; radii :
    (C,) the farthest of its points from that centre plus :data:`SPHERE_SLACK_M`, m."""

    points: np.ndarray
    starts: np.ndarray
    centres: np.ndarray
    radii: np.ndarray


def cell_cloud(points_m: np.ndarray, side_m: float = CELL_M) -> CellCloud:
    """The (N, 3) world cloud ``points_m`` sorted into cubes of side ``side_m``, m (:class:`CellCloud`;
    compiled: :func:`graspexp.planning.neighbour_kernels.cube_sort`)."""
    pts = np.ascontiguousarray(points_m, dtype=np.float64).reshape(-1, 3)
    if len(pts) == 0:
        return CellCloud(np.zeros((0, 3)), np.zeros(1, np.int64), np.zeros((0, 3)), np.zeros(0))
    return CellCloud(*cube_sort(pts, side_m, SPHERE_SLACK_M))
