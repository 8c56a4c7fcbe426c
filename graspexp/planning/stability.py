"""What keeps a planned grasp in the hand once the object is lifted: pad depth, pad edges, gravity arm, pose
noise.

Pure numpy/scipy, world frame, metres. Grasp frames as in :mod:`.collision` (+Z approach, +Y closing
axis, origin midway between the pads; the fingers span ``[root_z_m, tip_z_m]`` along Z).

- **Pad contacts.** The contact points of a side are the points in the pads' reach (``|x| <= fw/2``,
  ``z`` in the finger span) within ``band_m`` of that side's extreme ``y`` (the first points a closing
  pad meets). A side's depth is ``tip_z_m - mean z`` of its contact points: how far from the fingertip
  the contact is centred. Its angle is the one between the mean outward normal there and the closing
  axis: a pad pressing on a surface tilted beyond the friction cone (``atan(mu)``) pushes the object
  along the approach. A grasp held by the fingertip edges (depth near 0) or on slopes is squeezed out
  when the pads press. A side's share in the area is the fraction of its contact points that are
  grasping-area points: where the pads will touch, whatever the grasp point was aimed at.
- **Pad edges.** A finger closes until its pad face meets the extreme ``y`` of the points in its reach (its
  contact plane). Where the object, within ``clearance_m`` of the finger's side faces (``|x|`` just past
  ``fw/2``) or of its tip face (``z`` just past ``tip_z_m``), reaches past that plane, the finger meets it
  with an edge: a surface that rises beside the pad, or a groove the finger sits in. A small shift or turn
  of the object in the closing hand then presses the finger's side or tip face, not its pad, on it.
- **Gravity arm.** Once the support is gone, gravity pulls at the centre of mass; its torque about the
  closing axis (the line through the grasp point along +Y) is resisted only by the pads' torsional
  friction. Its arm is ``|Y . ((g - o) x z_world)|``.
- **Centre of mass.** The planner sees a surface cloud only; the centroid of the solid convex hull of
  the cloud is its estimate (uniform density). For clouds without a 3-D hull, the point mean.
- **Pose noise.** The pose the planner is given carries the estimator's error. A grasp is robust when it
  still passes the collision and depth tests with the cloud moved by poses drawn from that error.
"""

import numpy as np
from scipy.spatial import ConvexHull, QhullError

from graspexp.core.geometry import pose_error
from graspexp.grippers import GripperGeometry
from graspexp.planning.kernels import pad_contact_stats, pad_edge_excess


def volume_centroid_m(points_m: np.ndarray) -> np.ndarray:
    """(3,) centroid of the solid convex hull of ``points_m`` (N, 3), m (module doc)."""
    p = np.asarray(points_m, dtype=np.float64)
    try:
        hull = ConvexHull(p)
    except (QhullError, ValueError):
        return p.mean(axis=0)
    used = np.zeros(len(p), dtype=bool)  # hull.vertices (np.unique of the simplices) without its sort
    used[hull.simplices] = True
    apex = p[np.flatnonzero(used)].mean(axis=0)
    tri = p[hull.simplices]  # (F, 3, 3)
    vol = np.abs(np.einsum("ij,ij->i", tri[:, 0] - apex, np.cross(tri[:, 1] - apex, tri[:, 2] - apex))) / 6
    if vol.sum() <= 0:
        return p.mean(axis=0)
    centres = (tri.sum(axis=1) + apex) / 4
    return (vol[:, None] * centres).sum(axis=0) / vol.sum()


def gravity_arm_m(poses: np.ndarray, com_m: np.ndarray) -> np.ndarray:
    """(B,) arm of gravity's torque about each grasp's closing axis, m (module doc).

    poses : (B, 4, 4) world grasp poses; com_m : (3,) world centre of mass.
    """
    poses = np.asarray(poses, dtype=np.float64).reshape(-1, 4, 4)
    r = np.asarray(com_m, dtype=np.float64)[None] - poses[:, :3, 3]
    moment = np.cross(r, np.array([0.0, 0.0, 1.0]))
    return np.abs(np.einsum("bi,bi->b", moment, poses[:, :3, 1]))


def pad_contacts(
    points_m: np.ndarray,
    normals: np.ndarray,
    poses: np.ndarray,
    geometry: GripperGeometry,
    band_m: float,
    area_mask: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Depth of the shallower side's contact from the fingertips, m, the larger of the two sides' angles
    between the contact normal and the closing axis, rad (module doc), and the smaller of the two sides'
    shares of contact points in the grasping area, per grasp.

    points_m : (N, 3) world cloud; normals : (N, 3) its outward unit normals; poses : (B, 4, 4) world grasp
    frames; area_mask : (N,) bool grasping area (None: all points). A side's normal is the mean of its
    contact points' normals; the left pad (+Y side) presses against a surface facing +Y. Where a side has
    no contact point: depth -inf, angle pi and share 0. Compiled
    (:func:`graspexp.planning.kernels.pad_contact_stats`): numpy's (B, N) passes were most of a plan.

    Returns
    -------
    depth_m, angle_rad, in_area : (B,) float64.
    """
    p = np.ascontiguousarray(points_m, dtype=np.float64)
    area = np.ones(len(p), dtype=bool) if area_mask is None else np.asarray(area_mask, dtype=bool)
    stats = pad_contact_stats(
        p,
        np.ascontiguousarray(normals, dtype=np.float64),
        np.ascontiguousarray(area),
        np.ascontiguousarray(np.asarray(poses, dtype=np.float64).reshape(-1, 4, 4)),
        geometry.finger_width_m / 2,
        geometry.root_z_m,
        geometry.tip_z_m,
        band_m,
    )
    return stats[:, 0], stats[:, 1], stats[:, 2]


def pad_edge_excess_m(
    points_m: np.ndarray, poses: np.ndarray, geometry: GripperGeometry, clearance_m: float
) -> np.ndarray:
    """(B,) how far the object reaches past either pad's contact plane within ``clearance_m`` of that
    finger's side and tip faces, m (module doc, "Pad edges"); -inf where nothing lies there. Points
    farther past the plane than the finger's thickness plus ``clearance_m`` lie behind the finger and do
    not count.

    points_m : (N, 3) world cloud; poses : (B, 4, 4) world grasp frames. Compiled
    (:func:`graspexp.planning.kernels.pad_edge_excess`).
    """
    return pad_edge_excess(
        np.ascontiguousarray(points_m, dtype=np.float64),
        np.ascontiguousarray(np.asarray(poses, dtype=np.float64).reshape(-1, 4, 4)),
        geometry.finger_width_m / 2,
        geometry.root_z_m,
        geometry.tip_z_m,
        geometry.finger_thickness_m,
        clearance_m,
    )


def pose_perturbations(
    rng: np.random.Generator, n: int, trans_mm: float, rot_deg: float, origin_m: np.ndarray
) -> np.ndarray:
    """(n, 4, 4) world rigid motions of :func:`pose_error` draws, each rotating about ``origin_m`` (the
    object's origin, world, m) and then translating."""
    out = np.tile(np.eye(4), (n, 1, 1))
    origin = np.asarray(origin_m, dtype=np.float64)
    for i in range(n):
        rot, trans = pose_error(rng, trans_mm, rot_deg)
        out[i, :3, :3] = rot
        out[i, :3, 3] = origin - rot @ origin + trans
    return out
