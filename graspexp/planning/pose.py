"""The grasp frame of paper Fig. 9, the opening width, and the object-wider-than-gripper test.

Frame
    +Z = approach direction ``d`` (from the sphere point towards the centre); +X = main axis made
    orthogonal to Z by Gram-Schmidt, ``a - (a . Z) Z`` normalised; +Y = Z x X (the closing axis).
    Origin = cluster centre ``c_k``. When the main axis is within ``PARALLEL_TOL`` (sine of the angle)
    of the approach, the X seed falls back to the world axis least aligned with Z (lowest index on a
    tie), which is deterministic and never parallel to Z. The rotation is orthonormal with det +1.

Width
    ``clip(2 r_k (1 + width_margin), gripper.min_width_m, gripper.max_width_m)``, metres.

Section between the pads
    In the grasp frame, take the object points inside the pads' sweep: ``|x| <= finger_width/2`` and
    ``z`` within the fingers' extent (:class:`graspexp.grippers.GripperGeometry`). Their span ``[y_lo, y_hi]`` along the
    closing axis is the section the fingers close on (:func:`slab_spans_m`); its extent
    ``y_hi - y_lo`` is the opening it needs. The pads close symmetrically, so the planner moves the
    grasp point along Y to the section's middle, ``c_k + (y_lo + y_hi)/2 * Y`` (the paper's c_k is a
    mean of surface points and can sit off the section's middle, e.g. half a ring for K = 2); X, Y, Z
    are unchanged. The planner (:mod:`.optimal`, step 7) keeps a path only if the extent fits the
    opening, and reports ``NoFeasibleGrasp("object wider than the gripper ...")`` when no path's extent
    fits even the stroke ``max_width_m``. No points in the slab: span [0, 0] (nothing to squeeze). Only
    the pads' region is checked: the palm and the fingers' travel behind it are not (the paper's cost is
    what steers paths away from the object).
"""

import numpy as np

from graspexp.config import GripperConfig
from graspexp.grippers import GripperGeometry
from graspexp.planning.kernels import grasp_frames, slab_spans

PARALLEL_TOL = 1e-6
"""Below this norm of the Gram-Schmidt residual the main axis counts as parallel to the approach."""


def grasp_rotations(approaches: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """(B,3,3) rotations whose columns are X, Y, Z of the grasp frame (module doc), world.

    approaches : (B, 3) approach directions (normalised here); axis : (3,) unit main axis. Compiled
    (:func:`graspexp.planning.kernels.grasp_frames`): numpy's per-call overhead on (B, 3) arrays was a
    tenth of a plan.
    """
    z = np.ascontiguousarray(approaches, dtype=np.float64).reshape(-1, 3)
    return grasp_frames(z, np.ascontiguousarray(axis, dtype=np.float64), PARALLEL_TOL)


def grasp_rotation(approach: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """(3,3) rotation whose columns are X, Y, Z of the grasp frame (module doc), world."""
    return grasp_rotations(np.asarray(approach)[None], axis)[0]


def grasp_pose(center_m: np.ndarray, approach: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """(4,4) world pose of the grasp frame: rotation from :func:`grasp_rotation`, origin ``center_m``."""
    pose = np.eye(4)
    pose[:3, :3] = grasp_rotation(approach, axis)
    pose[:3, 3] = center_m
    return pose


def opening_widths_m(radii_m: np.ndarray, width_margin: float, gripper: GripperConfig) -> np.ndarray:
    """(K,) planned openings, metres, for (K,) cluster radii ``r_k`` in metres (module doc)."""
    return np.clip(2.0 * np.asarray(radii_m) * (1.0 + width_margin), gripper.min_width_m, gripper.max_width_m)


def slab_spans_m(
    points_m: np.ndarray,
    centers_m: np.ndarray,
    rotations: np.ndarray,
    gripper: GripperConfig,
    margin_m: float = 0.0,
) -> np.ndarray:
    """Span ``[y_lo, y_hi]`` along +Y of the object points in the pads' sweep (module doc), the sweep
    grown by ``margin_m`` along X and Z (the collision checks' clearance, m).

    points_m : (N, 3) world, metres; centers_m : (3,) or (B, 3) grasp-frame origins (cluster centres),
    world, metres; rotations : (B, 3, 3) grasp rotations.

    Returns
    -------
    (B, 2) float64, metres, relative to each centre ([0, 0] where no point falls in the slab). Compiled
    (:func:`graspexp.planning.kernels.slab_spans`): one pass over the points per rotation.
    """
    rots = np.ascontiguousarray(rotations, dtype=np.float64)
    centers = np.ascontiguousarray(np.broadcast_to(np.asarray(centers_m, dtype=np.float64), (len(rots), 3)))
    geometry = GripperGeometry.of(gripper)
    return slab_spans(
        np.ascontiguousarray(points_m, dtype=np.float64),
        centers,
        rots,
        geometry.finger_width_m / 2 + margin_m,
        geometry.root_z_m - margin_m,
        geometry.tip_z_m + margin_m,
    )
