"""View-based antipodal sampling (GPD's class of method, ten Pas et al., IJRR 2017): grasp candidates
sampled on the observed cloud only (``PlanRequest.observation``: what the depth camera saw of the target,
with noise and without its far side), never on the object's model or pose.

Steps (world frame, metres; the target's observed points and their normals, oriented towards the camera):

1. seeds: ``planner.n_candidates`` observed target points drawn without replacement with
   ``np.random.default_rng(req.seed)``;
2. for each seed: closing axis +Y along the inverted normal (into the object: the seed's pad presses its
   surface head-on, inside any friction cone), ``planner.n_approach`` approach directions about it
   (:func:`graspexp.planning.antipodal.approaches_about`, the first the most downward);
3. each candidate is centred on the observed points between the pads and opened to the gripper's full
   stroke (GPD's fixed-aperture hand: the far side is unseen, so its extent is unknown), moved back if
   a box would dip below the support, and checked for finger and palm collisions with the observed
   cloud along the straight approach (:func:`graspexp.planning.collision.place_grasps`);
4. each pad's contact: the observed points within ``planner.contact_band_m`` of the section's extreme
   between the pads on its side; the angle between their mean normal and the pad's pressing direction.
   The near (seed) side must lie inside the friction cone ``atan(planner.friction_coef)``; the far side
   counts when its contact faces the far pad within that cone (an observed antipodal contact), else it
   is unseen and costs ``planner.unseen_side_deg``;
5. cost = the larger of the two sides' angles (degrees; the unseen side's cost) +
   ``planner.approach_tilt_weight`` * the angle between the approach and world -Z (degrees); the cheapest
   surviving candidate wins.

``Grasp.n_feasible`` counts the surviving candidates; ``extras``: ``n_observed`` (target points seen),
``far_side_seen`` (1.0 when the winner's far contact was observed) and the rejection counts.
"""

import numpy as np

from graspexp.grippers import GripperGeometry
from graspexp.planning.antipodal import approaches_about, tilt_deg
from graspexp.planning.collision import frame_from_axes, max_lift_m, place_grasps
from graspexp.planning.grasp import Grasp, NoFeasibleGrasp
from graspexp.planning.request import PlanRequest, PlanResult

SEED_BATCH = 32
"""Seeds whose candidates are placed and scored together."""


def side_angles_deg(
    points: np.ndarray, normals: np.ndarray, poses: np.ndarray, geometry: GripperGeometry, band_m: float
) -> tuple[np.ndarray, np.ndarray]:
    """(near, far) contact angles (B,) of each grasp, degrees (step 4 of the module doc): near = the -Y
    pad (pressing along +Y), far = the +Y pad (pressing along -Y). NaN where a side has no point.

    points, normals : (N, 3) world observed points and unit normals; poses : (B, 4, 4) world grasp frames.
    """
    R, o = poses[:, :3, :3], poses[:, :3, 3]
    local = np.einsum("bnk,bkj->bnj", points[None, :, :] - o[:, None, :], R)  # (B, N, 3)
    ny = np.einsum("nk,bk->bn", normals, R[:, :, 1])  # normal component along each grasp's +Y
    inside = (
        (np.abs(local[..., 0]) <= geometry.finger_width_m / 2)
        & (local[..., 2] >= geometry.root_z_m)
        & (local[..., 2] <= geometry.tip_z_m)
    )
    y = np.where(inside, local[..., 1], np.nan)
    out = []
    for sign in (-1.0, 1.0):
        with np.errstate(all="ignore"):
            extreme = np.nanmax(sign * y, axis=1)  # the side's outermost observed point
            band = inside & (sign * y >= extreme[:, None] - band_m)
            mean_ny = np.where(band, ny, 0.0).sum(axis=1) / band.sum(axis=1)
        # the surface under the pad faces it: its normal points along sign * Y
        out.append(np.degrees(np.arccos(np.clip(sign * mean_ny, -1.0, 1.0))))
    return out[0], out[1]


def plan_antipodal_view(req: PlanRequest) -> PlanResult:
    """Plan one grasp on the observed cloud; see the module doc.

    Raises
    ------
    ValueError
        The request carries no observation (the trial rendered no camera).
    NoFeasibleGrasp
        Too few observed target points, or every candidate collides, is too wide or misses the cone.
    """
    pl, gr = req.planner, req.gripper
    obs = req.observation
    if obs is None:
        raise ValueError("planner antipodal_view plans on the camera's cloud: the request has no observation")
    points, normals = obs.target()
    if len(points) < pl.min_points:
        raise NoFeasibleGrasp(
            f"antipodal_view: the camera saw {len(points)} points of the object (< planner.min_points = "
            f"{pl.min_points})"
        )
    geometry = GripperGeometry.of(gr)
    cone_deg = float(np.degrees(np.arctan(pl.friction_coef)))
    rng = np.random.default_rng(req.seed)
    seeds = rng.choice(len(points), size=min(int(pl.n_candidates), len(points)), replace=False)
    table_z = req.table_z if req.support_blocks_gripper else -np.inf
    best: tuple[float, np.ndarray, float, bool] | None = None  # cost, pose, width, far side seen
    counts = {"n_too_wide": 0, "n_below_support": 0, "n_collides": 0, "n_outside_cone": 0}
    n_ok = 0
    for s in range(0, len(seeds), SEED_BATCH):
        poses, tilts = [], []
        for i in seeds[s : s + SEED_BATCH]:
            closing = -normals[i]
            dirs = approaches_about(closing, int(pl.n_approach))
            poses += [frame_from_axes(d, closing, points[i]) for d in dirs]
            tilts.append(tilt_deg(dirs))
        placed = place_grasps(
            points,
            np.array(poses),
            gr,
            sweep_m=pl.sphere_radius_m,
            table_z=table_z,
            margin_m=pl.collision_margin_m,
            clearance_m=pl.width_clearance_m,
            max_lift_m=max_lift_m(gr),
            min_widths_m=gr.max_width_m,
        )
        for key, n in placed.counts().items():
            counts[key] += n
        ok = np.flatnonzero(placed.ok)
        if len(ok) == 0:
            continue
        near, far = side_angles_deg(points, normals, placed.poses[ok], geometry, pl.contact_band_m)
        far_seen = far <= cone_deg
        good = near <= cone_deg
        counts["n_outside_cone"] += int((~good).sum())
        cost = np.maximum(near, np.where(far_seen, far, pl.unseen_side_deg))
        cost += pl.approach_tilt_weight * np.concatenate(tilts)[ok]
        cost = np.where(good, cost, np.inf)
        n_ok += int(good.sum())
        j = int(np.argmin(cost))
        if np.isfinite(cost[j]) and (best is None or cost[j] < best[0]):
            best = (float(cost[j]), placed.poses[ok[j]], float(placed.widths_m[ok[j]]), bool(far_seen[j]))
    if best is None:
        raise NoFeasibleGrasp(
            f"antipodal_view: all {len(seeds) * int(pl.n_approach)} candidates on {len(points)} observed "
            f"points failed: {counts['n_too_wide']} too wide for the stroke, {counts['n_below_support']} "
            f"below the support, {counts['n_collides']} colliding with the cloud, "
            f"{counts['n_outside_cone']} with the seed's contact outside the friction cone"
        )
    cost, pose, width, seen = best
    grasp = Grasp(
        pose=pose,
        width_m=width,
        cost=cost,
        cluster=-1,
        path=-1,
        n_feasible=n_ok,
        planner=req.planner.name,
        extras={"n_observed": int(len(points)), "far_side_seen": float(seen), **counts},
    )
    return PlanResult(grasp=grasp, details={"cloud": points, "pose": pose, "width": np.float64(width)})
