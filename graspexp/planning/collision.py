"""Finger and palm volumes of a parallel gripper, checked against the object cloud and the support plane.

Shared by the ``antipodal``, ``obb``, ``random`` and ``optimal_plus`` planners. Pure numpy.

Geometry (the same as :mod:`graspexp.sim.gripper`), in the grasp frame (+Z approach, +Y closing axis,
origin midway between the pads), for an opening ``w``, finger span ``[z0, z1]`` along Z
(:class:`graspexp.grippers.GripperGeometry`: palm face to fingertips), width ``fw`` (X),
thickness ``t`` (Y) and palm size ``(px, py, pz)``:

- left finger  ``x in [-fw/2, fw/2]``, ``y in [ w/2,  w/2 + t]``, ``z in [z0, z1]``;
- right finger ``x in [-fw/2, fw/2]``, ``y in [-w/2 - t, -w/2]``, ``z in [z0, z1]``;
- palm         ``x in [-px/2, px/2]``, ``y in [-py/2, py/2]``, ``z in [z0 - pz, z0]``.

The trial moves the gripper in a straight line from the pre-grasp pose (``-sweep_m`` along +Z, where
``sweep_m = planner.sphere_radius_m``) to the grasp pose with the fingers already open, so the volume a
box sweeps is the same box extended by ``sweep_m`` towards -Z. A candidate collides with the cloud when
any cloud point lies inside a swept box grown by ``margin_m`` on every side; points between the pads
(``|y| < w/2 - margin_m``) in front of the palm are what the fingers close on and never count.

Support: the lowest corner of every box, at both ends of the straight approach (the hull of the motion
is spanned by them), must lie at or above ``table_z + margin_m``.

A URDF gripper (``gripper.urdf``) is checked the same way on its convex pieces instead of the boxes
(:mod:`.hull_sweep`); the pads' reach (:mod:`.pose`, :mod:`.stability`) uses its fingers' bounding box.
"""

from dataclasses import dataclass

import numpy as np

from graspexp.config import GripperConfig
from graspexp.grippers import GripperGeometry
from graspexp.planning.cells import CellCloud, cell_cloud
from graspexp.planning.hull_sweep import hull_cloud_hits, hull_lowest_z
from graspexp.planning.kernels import COUNT_ALL, box_lowest_z, swept_box_hits
from graspexp.planning.neighbour_kernels import cells_swept_hits
from graspexp.planning.pose import slab_spans_m


def lowest_z(poses: np.ndarray, gripper: GripperConfig, widths_m: np.ndarray, sweep_m: float) -> np.ndarray:
    """Lowest world z reached by any gripper box (or URDF piece) during the approach, for a batch of grasps.

    poses : (B, 4, 4) grasp poses, world; widths_m : (B,) openings, m; sweep_m : approach length, m.
    A box swept ``sweep_m`` back along -Z is the box with its z range grown by ``sweep_m`` towards -Z; the
    lowest world z of an axis-aligned box ``[lo, hi]`` under rotation R is ``t_z + sum_a min(R[2, a] lo_a,
    R[2, a] hi_a)``.

    Returns
    -------
    (B,) float64, world z, metres.
    """
    poses = np.asarray(poses, dtype=np.float64).reshape(-1, 4, 4)
    widths = np.broadcast_to(np.asarray(widths_m, dtype=np.float64), (len(poses),))
    geometry = GripperGeometry.of(gripper)
    if geometry.hand is not None:
        return hull_lowest_z(poses, geometry.hand, widths, sweep_m)
    px, py, pz = geometry.palm_size_m
    root = geometry.root_z_m
    return box_lowest_z(
        np.ascontiguousarray(poses),
        np.ascontiguousarray(widths / 2),
        np.array([geometry.finger_width_m, geometry.finger_thickness_m, root - sweep_m, geometry.tip_z_m]),
        np.array([px, py, root - pz - sweep_m, root]),
    )


def cloud_hits(
    points_m: np.ndarray,
    poses: np.ndarray,
    gripper: GripperConfig,
    widths_m: np.ndarray,
    *,
    sweep_m: float,
    margin_m: float,
    stop_at: int = COUNT_ALL,
) -> np.ndarray:
    """Number of cloud points inside the swept finger and palm boxes (or URDF pieces) (module doc), per
    grasp, counted up to ``stop_at`` (``stop_at=1``: the scan of a grasp ends at its first hit, for a
    free / not free test). Compiled (:func:`graspexp.planning.kernels.swept_box_hits`).

    points_m : (N, 3) world; poses : (B, 4, 4) world; widths_m : (B,) or scalar openings, m.

    Returns
    -------
    (B,) int64; 0 means collision-free.
    """
    poses = np.ascontiguousarray(np.asarray(poses, dtype=np.float64).reshape(-1, 4, 4))
    widths = np.broadcast_to(np.asarray(widths_m, dtype=np.float64), (len(poses),))
    geometry = GripperGeometry.of(gripper)
    if geometry.hand is not None:
        return hull_cloud_hits(
            points_m, poses, geometry.hand, widths, sweep_m=sweep_m, margin_m=margin_m, stop_at=stop_at
        )
    fw, t = geometry.finger_width_m, geometry.finger_thickness_m
    px, py, pz = geometry.palm_size_m
    root, tip = geometry.root_z_m, geometry.tip_z_m
    m = margin_m
    finger = np.array([fw / 2 + m, t, root - sweep_m - m, tip + m, m])
    palm = np.array([px / 2 + m, py / 2 + m, root - pz - sweep_m - m, root + m])
    return swept_box_hits(
        np.ascontiguousarray(points_m, dtype=np.float64),
        poses,
        np.ascontiguousarray(widths / 2),
        finger,
        palm,
        stop_at,
    )


def neighbour_hits(
    obstacles: CellCloud | np.ndarray,
    poses: np.ndarray,
    gripper: GripperConfig,
    widths_m: np.ndarray,
    *,
    sweep_m: float,
    margin_m: float,
    between_pads: bool = True,
) -> np.ndarray:
    """(B,) bool: whether the opened gripper, swept ``sweep_m`` along its approach, meets a point of the other
    objects' cloud ``obstacles`` (cubed, :class:`graspexp.planning.cells.CellCloud`, or (N, 3) world m) of a
    clutter round: in the finger and palm volumes (:func:`cloud_hits`) or, with ``between_pads``, between the
    pads (the fingers would close on it together with the target): ``|x| <= fw/2``, ``|y| < w/2``, ``z`` from
    the swept palm face to the fingertips, grown by ``margin_m``. Without ``between_pads`` it is
    ``cloud_hits(..., stop_at=1) > 0`` (the target's own cloud, cubed). Compiled
    (:func:`graspexp.planning.neighbour_kernels.cells_swept_hits`: only the cubes near a grasp's volumes are
    scanned)."""
    cells = obstacles if isinstance(obstacles, CellCloud) else cell_cloud(obstacles)
    poses = np.ascontiguousarray(np.asarray(poses, dtype=np.float64).reshape(-1, 4, 4))
    widths = np.broadcast_to(np.asarray(widths_m, dtype=np.float64), (len(poses),))
    if len(cells.points) == 0 or len(poses) == 0:
        return np.zeros(len(poses), dtype=bool)
    g, m = GripperGeometry.of(gripper), margin_m
    if g.hand is not None:  # a URDF hand's pieces: every point against its hulls
        out = cloud_hits(cells.points, poses, gripper, widths, sweep_m=sweep_m, margin_m=m, stop_at=1) > 0
        if not between_pads:
            return out
    fw, t = g.finger_width_m, g.finger_thickness_m
    px, py, pz = g.palm_size_m
    root, tip = g.root_z_m, g.tip_z_m
    pads = np.array([fw / 2 + m, root - sweep_m - m, tip + m])
    finger = np.array([fw / 2 + m, t, root - sweep_m - m, tip + m, m])
    palm = np.array([px / 2 + m, py / 2 + m, root - pz - sweep_m - m, root + m])
    half = np.ascontiguousarray(widths / 2)
    args = (cells.points, cells.starts, cells.centres, cells.radii, poses, half, finger, palm, pads)
    if g.hand is not None:
        return out | cells_swept_hits(*args, False, True)
    return cells_swept_hits(*args, True, between_pads)


def support_lift_m(
    poses: np.ndarray,
    gripper: GripperConfig,
    widths_m: np.ndarray,
    *,
    sweep_m: float,
    table_z: float,
    margin_m: float,
) -> np.ndarray:
    """How far each grasp must move back along -Z (away from the object) to clear the support, m.

    0 where the lowest box corner is already at or above ``table_z + margin_m``; ``inf`` where moving
    back cannot help (an approach that does not point downwards).

    Returns
    -------
    (B,) float64, metres.
    """
    poses = np.asarray(poses, dtype=np.float64).reshape(-1, 4, 4)
    deficit = table_z + margin_m - lowest_z(poses, gripper, widths_m, sweep_m)
    down = -poses[:, 2, 2]  # how much world height one metre back along -Z gains
    with np.errstate(divide="ignore", invalid="ignore"):
        lift = np.where(deficit <= 0, 0.0, np.where(down > 1e-9, deficit / down, np.inf))
    return lift


def frame_from_axes(approach: np.ndarray, closing: np.ndarray, origin: np.ndarray) -> np.ndarray:
    """(4,4) grasp pose with +Z = ``approach``, +Y = ``closing`` made orthogonal to it, +X = Y x Z.

    approach, closing : (3,) non-parallel vectors (normalised here); origin : (3,) world, m. The rotation
    is orthonormal with det +1 (X = Y x Z makes the triad right-handed: Y = Z x X).
    """
    z = np.asarray(approach, dtype=np.float64)
    z = z / np.linalg.norm(z)
    y = np.asarray(closing, dtype=np.float64)
    y = y - (y @ z) * z
    y = y / np.linalg.norm(y)
    x = np.cross(y, z)
    pose = np.eye(4)
    pose[:3, :3] = np.stack([x, y, z], axis=1)
    pose[:3, 3] = origin
    return pose


@dataclass(frozen=True)
class Placement:
    """Candidate grasps after :func:`place_grasps`.

    poses : (B, 4, 4) world poses, centred on the section along +Y and moved back along -Z where the
        support required it.
    widths_m : (B,) openings, m (clipped to the stroke; meaningful where ``ok``).
    lift_m : (B,) how far each grasp was moved back, m (inf: could not clear the support).
    ok : (B,) bool, True where the grasp fits the stroke, clears the support and hits no cloud point.
    too_wide, below_support, collides : (B,) bool, the first failed check of each rejected candidate.
    """

    poses: np.ndarray
    widths_m: np.ndarray
    lift_m: np.ndarray
    ok: np.ndarray
    too_wide: np.ndarray
    below_support: np.ndarray
    collides: np.ndarray

    def rows(self, index: slice | np.ndarray) -> "Placement":
        """The placements of the candidates ``index`` selects."""
        return Placement(
            poses=self.poses[index],
            widths_m=self.widths_m[index],
            lift_m=self.lift_m[index],
            ok=self.ok[index],
            too_wide=self.too_wide[index],
            below_support=self.below_support[index],
            collides=self.collides[index],
        )

    def counts(self) -> dict[str, int]:
        """Rejections per check, for messages and ``Grasp.extras``."""
        return {
            "n_too_wide": int(self.too_wide.sum()),
            "n_below_support": int(self.below_support.sum()),
            "n_collides": int(self.collides.sum()),
        }


def place_grasps(
    points_m: np.ndarray,
    poses: np.ndarray,
    gripper: GripperConfig,
    *,
    sweep_m: float,
    table_z: float,
    margin_m: float,
    clearance_m: float,
    max_lift_m: float,
    min_widths_m: np.ndarray | float = 0.0,
    obstacles_m: CellCloud | np.ndarray | None = None,
) -> Placement:
    """Open, lift and check a batch of candidate grasps against the cloud and the support.

    1. centre: each grasp point moves along +Y to the middle of the object's section between the pads
       (:func:`graspexp.planning.pose.slab_spans_m`, grown by ``margin_m``; the pads close symmetrically about the grasp point, so an off-centre
       point would need a needlessly wide opening); opening = ``max(min_widths_m, section + 2
       clearance_m)``, at least ``gripper.min_width_m``;
    2. move the grasp back along -Z by :func:`support_lift_m` (at most ``max_lift_m``, else rejected as
       below the support), then re-centre and recompute the opening there;
    3. reject when the opening exceeds ``gripper.max_width_m`` (too wide), when a box still dips below
       ``table_z + margin_m`` (below support), or when :func:`cloud_hits` finds a point (collides), or
       :func:`neighbour_hits` a point of ``obstacles_m`` (the other objects of a clutter round).

    points_m : (N, 3) world cloud; poses : (B, 4, 4) world candidate poses; obstacles_m : (M, 3) world, cubed (:class:`CellCloud`) or not, or None.
    """
    poses = np.array(poses, dtype=np.float64).reshape(-1, 4, 4)
    b = len(poses)
    floor = np.maximum(np.broadcast_to(np.asarray(min_widths_m, dtype=np.float64), (b,)), gripper.min_width_m)

    def centre_and_open(ps: np.ndarray, fl: np.ndarray) -> np.ndarray:
        """Shift each pose along its +Y to the middle of its section (in place); return the openings."""
        spans = slab_spans_m(points_m, ps[:, :3, 3], ps[:, :3, :3], gripper, margin_m)
        ps[:, :3, 3] += spans.mean(axis=1)[:, None] * ps[:, :3, 1]
        return np.maximum(spans[:, 1] - spans[:, 0] + 2.0 * clearance_m, fl)

    widths = centre_and_open(poses, floor)
    lift = support_lift_m(
        poses,
        gripper,
        np.minimum(widths, gripper.max_width_m),
        sweep_m=sweep_m,
        table_z=table_z,
        margin_m=margin_m,
    )
    lift = np.where(lift <= max_lift_m, lift, np.inf)
    movable = np.isfinite(lift)
    poses[movable, :3, 3] -= lift[movable, None] * poses[movable, :3, 2]
    moved = movable & (lift > 0)
    if moved.any():
        sub = poses[moved]
        widths[moved] = centre_and_open(sub, floor[moved])
        poses[moved] = sub
    too_wide = widths > gripper.max_width_m + 1e-12
    widths = np.minimum(widths, gripper.max_width_m)
    low = lowest_z(poses, gripper, widths, sweep_m) < table_z + margin_m - 1e-9
    below = ~too_wide & (~movable | low)
    check = ~too_wide & ~below
    hits = np.zeros(b, dtype=np.int64)
    if check.any():
        hits[check] = cloud_hits(
            points_m, poses[check], gripper, widths[check], sweep_m=sweep_m, margin_m=margin_m, stop_at=1
        )
        if obstacles_m is not None:
            hits[check] += neighbour_hits(
                obstacles_m, poses[check], gripper, widths[check], sweep_m=sweep_m, margin_m=margin_m
            )
    collides = check & (hits > 0)
    return Placement(
        poses=poses,
        widths_m=widths,
        lift_m=lift,
        ok=check & ~collides,
        too_wide=too_wide,
        below_support=below,
        collides=collides,
    )


MAX_LIFT_FRACTION = 0.8
"""A grasp may move back from its grasp point by at most this fraction of the fingertip reach
(:attr:`GripperGeometry.tip_z_m`), so the point it aimed at stays between the pads."""


def max_lift_m(gripper: GripperConfig) -> float:
    """Largest back-off along -Z that :func:`place_grasps` may apply to clear the support, m."""
    return MAX_LIFT_FRACTION * GripperGeometry.of(gripper).tip_z_m


def place_for_request(
    req, poses: np.ndarray, min_widths_m: np.ndarray | float = 0.0, *, neighbours: bool = True
) -> Placement:
    """:func:`place_grasps` with the request's cloud, support plane, gripper and planner settings
    (sweep = ``planner.sphere_radius_m``, ``collision_margin_m``, ``width_clearance_m``). A support that
    does not block the gripper (``req.support_blocks_gripper`` False) is not checked; a clutter round's other
    objects (``req.neighbours``) are obstacles (:func:`neighbour_hits`) unless ``neighbours`` is False."""
    pl, gr = req.planner, req.gripper
    return place_grasps(
        np.asarray(req.points, dtype=np.float64),
        poses,
        gr,
        sweep_m=pl.sphere_radius_m,
        table_z=req.table_z if req.support_blocks_gripper else -np.inf,
        margin_m=pl.collision_margin_m,
        clearance_m=pl.width_clearance_m,
        max_lift_m=max_lift_m(gr),
        min_widths_m=min_widths_m,
        obstacles_m=req.neighbour_cells if req.neighbours and neighbours else None,
    )
