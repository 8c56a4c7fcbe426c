"""``optimal_plus``: the paper's planner (:mod:`.optimal`) with three general weaknesses fixed.

Same grasping area, main axis, K-means clusters, Fibonacci-sphere paths, support-plane test and cost
Eq. (1)-(3) as ``optimal`` (its building blocks are reused unchanged). Then:

1. **Centre-of-mass preference.** Each cluster's costs are multiplied by
   ``1 + planner.com_weight * |c_k - g| / D``, where ``g`` is the centroid of the cloud (the centre of
   mass of a uniform shell, the best estimate a surface cloud gives) and ``D`` the diagonal of the
   cloud's axis-aligned box, m/m. A grasp near the centre of mass resists the gravity torque that
   makes off-centre grasps rotate and slip once the support goes (collab) or during the lift (bin).
2. **Opening from the geometry, not only from r_k.** The grasp point slides along the closing axis
   to the middle of the object's section between the pads (the cloud points within the finger width
   and span), and the opening is ``max(2 r_k (1 + width_margin), section + 2 width_clearance_m)``:
   ``2 r_k`` under-estimates the section of round or elongated clusters, and the pads close
   symmetrically about the grasp point, so the paper's opening about an off-centre cluster centre can
   land a finger on the object. Above the stroke, the path is rejected.
3. **Swept-volume collision check.** Each path is checked, in ascending cost, with the finger and palm
   boxes swept along the straight approach against the cloud and against the support plane
   (:func:`graspexp.planning.collision.place_for_request`; a grasp whose boxes would dip below the plane is
   first moved back along the approach, by at most 80 % of the fingertip reach). The paper only tests
   the path's start point against the plane, so the palm can hit the object (e.g. a tall object
   grasped low from above) and the fingertips the table.

The cheapest path that passes wins. ``Grasp.n_feasible`` counts the passing paths among those examined
(examination stops at the first pass after a batch). ``details`` holds the same keys as ``optimal``
where they apply (``cloud``, ``area_mask``, ``labels``, ``centers``, ``radii``, ``main_axis``,
``directions``, ``costs`` (K, M; inf where removed by the plane test), ``best``, ``pose``, ``width``)
plus ``com`` (3,) and ``com_factor`` (K,).
"""

import numpy as np

from graspexp.planning.collision import place_for_request
from graspexp.planning.grasp import Grasp, NoFeasibleGrasp
from graspexp.planning.optimal import paper_candidates
from graspexp.planning.pose import grasp_rotations, opening_widths_m
from graspexp.planning.request import PlanRequest, PlanResult

NAME = "optimal_plus"

PATH_BATCH = 32
"""Paths checked together, in ascending cost."""


def com_factors(
    centers_m: np.ndarray, points_m: np.ndarray, com_weight: float
) -> tuple[np.ndarray, np.ndarray]:
    """Cost factors ``1 + w |c_k - g| / D`` (fix 1 of the module doc) and the centroid ``g`` (3,)."""
    g = points_m.mean(axis=0)
    size = float(np.linalg.norm(points_m.max(axis=0) - points_m.min(axis=0)))
    dist = np.linalg.norm(centers_m - g, axis=1)
    return 1.0 + com_weight * dist / max(size, 1e-9), g


def plan_optimal_plus(req: PlanRequest) -> PlanResult:
    """Plan one grasp with the paper's strategy plus the fixes of the module doc.

    Raises
    ------
    NoFeasibleGrasp
        Empty grasping area; every path crosses the support plane; or every remaining path is too wide,
        below the support or colliding with the cloud.
    """
    pl, gr = req.planner, req.gripper
    if pl.com_weight < 0:
        raise ValueError(f"planner.com_weight={pl.com_weight!r} is invalid: expected a non-negative number")
    cand = paper_candidates(req, NAME)
    points, axis, directions, feasible = cand.points, cand.axis, cand.directions, cand.feasible
    centers, radii = cand.clusters.centers_m, cand.clusters.radii_m
    k, m = cand.costs.shape
    factors, com = com_factors(centers, points, pl.com_weight)
    costs = factors[:, None] * cand.costs
    openings = opening_widths_m(radii, pl.width_margin, gr)

    order = np.argsort(costs, axis=None, kind="stable")[: int(feasible.sum())]
    rejected = {"n_too_wide": 0, "n_below_support": 0, "n_collides": 0}
    best = None
    n_ok = examined = 0
    for s in range(0, len(order), PATH_BATCH):
        ks, ps = np.unravel_index(order[s : s + PATH_BATCH], (k, m))
        poses = np.tile(np.eye(4), (len(ks), 1, 1))
        poses[:, :3, :3] = grasp_rotations(directions[ks, ps], cand.pose_axis)
        poses[:, :3, 3] = centers[ks]
        placed = place_for_request(req, poses, min_widths_m=openings[ks])
        examined += len(ks)
        for key, n in placed.counts().items():
            rejected[key] += n
        n_ok += int(placed.ok.sum())
        if placed.ok.any():
            j = int(np.argmax(placed.ok))  # the batch is in ascending cost
            best = (
                int(ks[j]),
                int(ps[j]),
                placed.poses[j],
                float(placed.widths_m[j]),
                float(placed.lift_m[j]),
            )
            break
    if best is None:
        raise NoFeasibleGrasp(
            f"optimal_plus: all {examined} paths above the support failed: {rejected['n_too_wide']} too "
            f"wide for the stroke {gr.max_width_m} m, {rejected['n_below_support']} below the support, "
            f"{rejected['n_collides']} with fingers or palm colliding with the cloud"
        )
    kb, pb, pose, width, lift = best
    grasp = Grasp(
        pose=pose,
        width_m=width,
        cost=float(costs[kb, pb]),
        cluster=kb,
        path=pb,
        n_feasible=n_ok,
        planner=NAME,
        extras={
            "K": k,
            "M": m,
            "n_examined": examined,
            "lift_m": lift,
            "com_factor": float(factors[kb]),
            **rejected,
        },
    )
    details = {
        "cloud": points,
        "area_mask": cand.area_mask,
        "labels": cand.clusters.labels,
        "centers": centers,
        "radii": radii,
        "main_axis": axis,
        "directions": directions,
        "costs": costs,
        "com": com,
        "com_factor": factors,
        "best": np.array([kb, pb]),
        "pose": pose,
        "width": np.float64(width),
    }
    return PlanResult(grasp=grasp, details=details)
