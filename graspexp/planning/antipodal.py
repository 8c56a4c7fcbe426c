"""Antipodal sampling baseline (GPD / PointNetGPD style): two contacts inside each other's friction cone.

Steps (cloud and normals in the world frame, metres; normals point outwards):

1. seeds: ``planner.n_candidates`` cloud points drawn without replacement with
   ``np.random.default_rng(req.seed)``, from the whole cloud (GPD knows no grasping area) or, with
   ``planner.sample_area_only``, from the area (and the partners of step 2 too: both contacts in the area);
2. partner of each seed ``p1``: the cloud point ``p2`` that minimises the worse of the two cone angles
   ``a1 = angle(v, -n1)`` and ``a2 = angle(-v, -n2)`` (``v`` unit from ``p1`` to ``p2``), among partners
   with both angles ``<= atan(planner.friction_coef)`` and ``|p2 - p1| + 2 width_clearance_m`` within
   the stroke; seeds without such a partner are dropped;
3. for each pair: grasp point midway, closing axis +Y along ``v``, ``planner.n_approach`` approach
   directions evenly spaced about ``v``, starting from the most downward one (the projection of world
   -Z onto the plane normal to ``v``);
4. every candidate is opened, moved back if a box would dip below the support, and checked for finger
   and palm collisions with the cloud and the support along the straight approach
   (:func:`graspexp.planning.collision.place_for_request`);
5. cost = ``max(a1, a2)`` (degrees) + ``planner.approach_tilt_weight`` * the angle between the approach
   and world -Z (degrees); the cheapest surviving candidate wins. Pairs are examined in ascending
   ``max(a1, a2)``, which is a lower bound on their cost, so examination stops once it exceeds the best.
6. with ``planner.min_contacts_in_area`` > 0 (preset ``antipodal_area_pads``), a candidate survives step
   4 only if both pads' contacts are grasping-area points, with the fallback of
   :mod:`graspexp.planning.area_rule` (the rule ``optimal_plus`` follows): the two contacts of step 2
   lie in the area, but the pads close on whatever lies between them first.

``Grasp.n_feasible`` counts the surviving candidates among the examined pairs; ``extras`` holds
``in_area_required`` when step 6 applies.
``details``: ``pairs`` (P, 2) cloud indices, ``pair_angles_deg`` (P,), ``examined`` (number of pairs
examined), ``best_pair`` (2,).
"""

import numpy as np

from graspexp.grippers import GripperGeometry
from graspexp.planning.area_rule import area_test, fallback_share, no_grasp_in_area
from graspexp.planning.collision import frame_from_axes, place_for_request
from graspexp.planning.friction import cone_cosine, line_cone_cosines
from graspexp.planning.grasp import Grasp, NoFeasibleGrasp
from graspexp.planning.request import PlanRequest, PlanResult
from graspexp.planning.stability import pad_contacts

NAME = "antipodal"

PAIR_BATCH = 16
"""Contact pairs whose approaches are checked together."""


def _check_params(req: PlanRequest) -> None:
    pl = req.planner
    if pl.n_candidates < 1:
        raise ValueError(f"planner.n_candidates={pl.n_candidates!r} is invalid: expected a positive integer")
    if pl.n_approach < 1:
        raise ValueError(f"planner.n_approach={pl.n_approach!r} is invalid: expected a positive integer")
    if not pl.friction_coef > 0:
        raise ValueError(f"planner.friction_coef={pl.friction_coef!r} is invalid: expected a positive number")


def antipodal_pairs(
    points_m: np.ndarray,
    normals: np.ndarray,
    seeds: np.ndarray,
    friction_coef: float,
    max_distance_m: float,
    partners: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Best antipodal partner of each seed point (step 2 of the module doc).

    points_m : (N, 3) world; normals : (N, 3) outward unit; seeds : (S,) indices into points;
    partners : (N,) bool, the points a partner may be (None: all).

    Returns
    -------
    pairs : (P, 2) int64 ``(seed, partner)`` indices, P <= S, sorted by ascending angle.
    angles_deg : (P,) float64 worse cone angle of each pair, degrees.
    """
    p1, n1 = points_m[seeds], normals[seeds]
    d, cos1, cos2 = line_cone_cosines(  # (S, N): every seed against every point
        p1[:, None, :], n1[:, None, :], points_m[None, :, :], normals[None, :, :]
    )
    worst = np.minimum(cos1, cos2)
    valid = (d > 0) & (d <= max_distance_m) & (worst >= cone_cosine(friction_coef))
    if partners is not None:
        valid &= np.asarray(partners, dtype=bool)[None, :]
    worst = np.where(valid, worst, -np.inf)
    partner = np.argmax(worst, axis=1)
    keep = valid[np.arange(len(seeds)), partner]
    pairs = np.stack([seeds[keep], partner[keep]], axis=1).astype(np.int64)
    angles = np.degrees(np.arccos(np.clip(worst[keep, partner[keep]], -1.0, 1.0)))
    order = np.argsort(angles, kind="stable")
    return pairs[order], angles[order]


def approaches_about(line: np.ndarray, n: int) -> np.ndarray:
    """(n, 3) unit approach directions orthogonal to ``line``, evenly spaced, the first the most downward."""
    v = line / np.linalg.norm(line)
    down = np.array([0.0, 0.0, -1.0])
    e1 = down - (down @ v) * v
    if np.linalg.norm(e1) < 1e-6:  # vertical closing line: any horizontal start
        e1 = np.cross(v, [1.0, 0.0, 0.0])
        if np.linalg.norm(e1) < 1e-6:
            e1 = np.cross(v, [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(v, e1)
    phi = 2.0 * np.pi * np.arange(n) / n
    return np.cos(phi)[:, None] * e1 + np.sin(phi)[:, None] * e2


def tilt_deg(approaches: np.ndarray) -> np.ndarray:
    """Angle between each approach (..., 3) and world -Z, degrees in [0, 180]."""
    return np.degrees(np.arccos(np.clip(-approaches[..., 2], -1.0, 1.0)))


def plan_antipodal(req: PlanRequest) -> PlanResult:
    """Plan one grasp by antipodal sampling; see the module doc.

    Raises
    ------
    NoFeasibleGrasp
        No antipodal pair within the stroke, or every candidate collides with the cloud or the support.
    """
    _check_params(req)
    pl, gr = req.planner, req.gripper
    points = np.asarray(req.points, dtype=np.float64)
    normals = np.asarray(req.normals, dtype=np.float64)
    normals = normals / np.linalg.norm(normals, axis=1, keepdims=True)
    pool = np.flatnonzero(req.area_mask) if pl.sample_area_only else np.arange(len(points))
    if len(pool) == 0:
        raise NoFeasibleGrasp("antipodal: no point to sample contacts from (empty grasping area)")
    rng = np.random.default_rng(req.seed)
    seeds = rng.choice(pool, size=min(int(pl.n_candidates), len(pool)), replace=False)
    pairs, angles = antipodal_pairs(
        points,
        normals,
        seeds,
        pl.friction_coef,
        gr.max_width_m - 2.0 * pl.width_clearance_m,
        req.area_mask if pl.sample_area_only else None,
    )
    if len(pairs) == 0:
        raise NoFeasibleGrasp(
            f"antipodal: none of {len(seeds)} sampled contacts has a partner inside the friction cone "
            f"(mu = {pl.friction_coef}) within the stroke {gr.max_width_m} m"
        )

    need = pl.min_contacts_in_area
    best, rejected, examined, n_ok, best_share = _search(req, points, normals, pairs, angles, need)
    if best is None and need > 0 and (share := fallback_share(req, best_share)) is not None:
        need = share
        best, _, examined, n_ok, _ = _search(req, points, normals, pairs, angles, need)
    if best is None:
        raise NoFeasibleGrasp(
            f"antipodal: all {examined * int(pl.n_approach)} candidates of {len(pairs)} antipodal pairs "
            f"failed: {rejected['n_too_wide']} too wide for the stroke, {rejected['n_below_support']} below "
            f"the support, {rejected['n_collides']} colliding with the cloud"
            + (
                f", {rejected['n_outside_area']} with " + no_grasp_in_area(req, best_share)
                if need > 0
                else ""
            )
        )
    cost, i, pose, width = best
    grasp = Grasp(
        pose=pose,
        width_m=width,
        cost=cost,
        cluster=-1,
        path=int(i),
        n_feasible=n_ok,
        planner=req.planner.name,
        extras={
            "n_pairs": int(len(pairs)),
            "n_examined": int(examined),
            "pair_angle_deg": float(angles[i]),
            **rejected,
            **({"in_area_required": float(need)} if pl.min_contacts_in_area > 0 else {}),
        },
    )
    details = {
        "cloud": points,
        "pairs": pairs,
        "pair_angles_deg": angles,
        "examined": np.int64(examined),
        "best_pair": pairs[i],
        "pose": pose,
        "width": np.float64(width),
    }
    return PlanResult(grasp=grasp, details=details)


def _search(
    req: PlanRequest,
    points: np.ndarray,
    normals: np.ndarray,
    pairs: np.ndarray,
    angles: np.ndarray,
    need: float,
) -> tuple[tuple[float, int, np.ndarray, float] | None, dict[str, int], int, int, float]:
    """Steps 3-6 of the module doc over the (P, 2) ``pairs`` in ascending ``angles``, requiring ``need``
    of each pad's contact in the area (0: not checked): the best (cost, pair, pose, width) or None, the
    rejection counts, the pairs examined, the surviving candidates and the largest in-area share of the
    candidates that passed steps 3-4 (0 if none)."""
    pl = req.planner
    best: tuple[float, int, np.ndarray, float] | None = None  # cost, pair index, pose, width
    rejected = {"n_too_wide": 0, "n_below_support": 0, "n_collides": 0}
    if need > 0:
        rejected["n_outside_area"] = 0
        geometry = GripperGeometry.of(req.gripper)
    examined = n_ok = 0
    best_share = 0.0
    for s in range(0, len(pairs), PAIR_BATCH):
        if best is not None and angles[s] >= best[0]:
            break
        batch = range(s, min(s + PAIR_BATCH, len(pairs)))
        poses, costs, owners = [], [], []
        for i in batch:
            a, b = points[pairs[i, 0]], points[pairs[i, 1]]
            dirs = approaches_about(b - a, int(pl.n_approach))
            centre = (a + b) / 2
            for d in dirs:
                poses.append(frame_from_axes(d, b - a, centre))
            costs.append(angles[i] + pl.approach_tilt_weight * tilt_deg(dirs))
            owners += [i] * len(dirs)
        examined = batch.stop
        placed = place_for_request(req, np.array(poses))
        for key, n in placed.counts().items():
            rejected[key] += n
        ok = placed.ok
        if need > 0:
            share = np.zeros(len(ok))
            if ok.any():
                share[ok] = pad_contacts(
                    points, normals, placed.poses[ok], geometry, pl.contact_band_m, req.area_mask
                )[2]
            ok, n_outside, batch_best = area_test(ok, share, need)
            rejected["n_outside_area"] += n_outside
            best_share = max(best_share, batch_best)
        n_ok += int(ok.sum())
        cost = np.where(ok, np.concatenate(costs), np.inf)
        j = int(np.argmin(cost))
        if np.isfinite(cost[j]) and (best is None or cost[j] < best[0]):
            best = (float(cost[j]), owners[j], placed.poses[j], float(placed.widths_m[j]))
    return best, rejected, examined, n_ok, best_share
