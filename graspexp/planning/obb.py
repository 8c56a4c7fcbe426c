"""Bounding-box baseline: close across the object's narrower horizontal side, straight from above.

The box is the gravity-aligned oriented bounding box of the cloud (world frame, metres): the
minimum-area rectangle of the points' XY projection (``trimesh.bounds.oriented_bounds_2D``) times the
cloud's z range. A top-down grasp can only close horizontally, so of the box's axes only the two
horizontal ones are candidates; the shorter one is the closing axis.

- approach +Z = world -Z (top-down); closing axis +Y = the rectangle's shorter side; +X = the longer;
- grasp point = the box centre (rectangle centre, mid-height of the cloud), raised where needed so no
  gripper box reaches below ``table_z + planner.collision_margin_m`` (the fingertips, for a top-down
  grasp);
- opening = shorter side + ``2 planner.width_clearance_m``, at least ``gripper.min_width_m``;
  wider than ``gripper.max_width_m`` -> :class:`NoFeasibleGrasp`.

No collision check against the cloud (a naive baseline). ``details``: ``obb_center`` (3,),
``obb_extents`` (3,) (long side, short side, height), ``obb_axes`` (3, 3) columns long, short, up.
"""

import numpy as np
from trimesh.bounds import oriented_bounds_2D

from graspexp.planning.collision import frame_from_axes, support_lift_m
from graspexp.planning.grasp import Grasp, NoFeasibleGrasp
from graspexp.planning.request import PlanRequest, PlanResult

NAME = "obb"


def gravity_obb(points_m: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Gravity-aligned OBB of (N, 3) points: centre (3,), extents (3,) (long, short, height), axes (3, 3).

    The axes are the columns: the rectangle's longer side, its shorter side (both horizontal, unit) and
    world +Z.
    """
    pts = np.asarray(points_m, dtype=np.float64)
    transform, size = oriented_bounds_2D(pts[:, :2])
    inv = np.linalg.inv(transform)
    centre_xy = inv[:2, 2]
    dirs = inv[:2, :2]  # columns: the rectangle's axes in world XY
    long_i = int(np.argmax(size))
    short_i = 1 - long_i
    axes = np.zeros((3, 3))
    axes[:2, 0] = dirs[:, long_i] / np.linalg.norm(dirs[:, long_i])
    axes[:2, 1] = dirs[:, short_i] / np.linalg.norm(dirs[:, short_i])
    axes[2, 2] = 1.0
    z_lo, z_hi = float(pts[:, 2].min()), float(pts[:, 2].max())
    centre = np.array([centre_xy[0], centre_xy[1], (z_lo + z_hi) / 2])
    extents = np.array([size[long_i], size[short_i], z_hi - z_lo])
    return centre, extents, axes


def plan_obb(req: PlanRequest) -> PlanResult:
    """Plan one top-down grasp across the cloud's narrower horizontal side; see the module doc.

    Raises
    ------
    NoFeasibleGrasp
        The narrower side plus clearance exceeds the stroke, or the cloud has fewer than 3 points.
    """
    pl, gr = req.planner, req.gripper
    points = np.asarray(req.points, dtype=np.float64)
    if len(points) < 3:
        raise NoFeasibleGrasp(f"obb: a bounding box needs at least 3 cloud points, got {len(points)}")
    centre, extents, axes = gravity_obb(points)
    width = max(float(extents[1]) + 2.0 * pl.width_clearance_m, gr.min_width_m)
    if width > gr.max_width_m:
        raise NoFeasibleGrasp(
            f"obb: the box's narrower horizontal side {extents[1]:.4f} m plus clearance "
            f"2 x {pl.width_clearance_m} m exceeds gripper.max_width_m = {gr.max_width_m} m"
        )
    pose = frame_from_axes(np.array([0.0, 0.0, -1.0]), axes[:, 1], centre)
    lift = float(
        support_lift_m(
            pose[None],
            gr,
            np.array([width]),
            sweep_m=pl.sphere_radius_m,
            table_z=req.table_z,
            margin_m=pl.collision_margin_m,
        )[0]
    )
    pose[:3, 3] -= lift * pose[:3, 2]
    grasp = Grasp(
        pose=pose,
        width_m=width,
        cost=float(extents[1]),
        cluster=-1,
        path=-1,
        n_feasible=1,
        planner=NAME,
        extras={"obb_short_m": float(extents[1]), "obb_long_m": float(extents[0]), "lift_m": lift},
    )
    details = {"cloud": points, "obb_center": centre, "obb_extents": extents, "obb_axes": axes, "pose": pose}
    return PlanResult(grasp=grasp, details=details)
