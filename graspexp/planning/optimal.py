"""The paper's optimal grasping strategy (section III), as one pure function of a :class:`PlanRequest`.

Steps (the cloud arrives already transformed by the object pose: world frame, metres):

1. grasping area = ``points[area_mask]`` (III-A); empty -> :class:`NoFeasibleGrasp`;
2. main axis = first principal component of the area (III-D, Fig. 7; :mod:`.clusters`);
3. K from ``planner.k`` or the ``auto`` rule; seeded K-means -> centres ``c_k``, RMS radii ``r_k``
   (III-B, Fig. 5); ``random_state = derive_seed(req.seed, "kmeans", planner.seed) mod 2^32``;
4. ``M`` Fibonacci-sphere paths per centre, radius ``planner.sphere_radius_m`` (III-C, Fig. 6);
5. paths whose sphere point lies below ``z = table_z + planner.table_clearance_m`` are removed, in both
   modes (the plane is the box top in collab mode, the table top in bin mode; Fig. 8);
6. cost Eq. (1) (collab) or Eq. (2)-(3) (bin) of every remaining path (:mod:`.cost`); removed paths
   cost ``inf``;
7. paths are taken in ascending cost (stable order: cluster-major, then path index) and the first
   whose pads' sweep fits the gripper (:func:`.pose.slab_extents_m` <= ``max_width_m``) wins. Checking
   lazily in cost order picks exactly the argmin over paths passing both tests; the paths found too
   wide get cost ``inf`` and ``feasible`` False, the unexamined ones keep their table verdict;
8. pose per Fig. 9 and opening width from ``r_k`` (:mod:`.pose`).

``Grasp.n_feasible`` counts the paths that survive step 5 minus those found too wide in step 7.
"""

import numpy as np

from graspexp.planning.clusters import choose_k, main_axis, segment
from graspexp.planning.cost import cluster_costs
from graspexp.planning.grasp import Grasp, NoFeasibleGrasp
from graspexp.planning.paths import above_support, approach_directions
from graspexp.planning.pose import grasp_pose, grasp_rotations, opening_width_m, slab_extents_m
from graspexp.planning.request import PlanRequest, PlanResult
from graspexp.seeding import derive_seed

NAME = "optimal"

WIDTH_CHECK_BATCH = 16
"""Paths checked per batch by the lazy wider-than-gripper test (after the cheapest one alone)."""


def kmeans_random_state(seed: int, planner_seed: int) -> int:
    """sklearn ``random_state`` for the K-means of one plan (fits sklearn's 32-bit range)."""
    return derive_seed(seed, "kmeans", planner_seed) % (2**32)


def plan_optimal(req: PlanRequest) -> PlanResult:
    """Plan one grasp with the paper's strategy; see the module doc for the steps and ``details`` keys.

    Raises
    ------
    NoFeasibleGrasp
        Empty grasping area; every path crosses the support plane; or every remaining path finds the
        object wider than the gripper's stroke.
    """
    points = np.asarray(req.points, dtype=np.float64)
    mask = np.asarray(req.area_mask, dtype=bool)
    if points.ndim != 2 or points.shape[1] != 3:
        raise ValueError(f"points has shape {points.shape}: expected (N, 3)")
    if mask.shape != (len(points),):
        raise ValueError(f"area_mask has shape {mask.shape}: expected ({len(points)},)")
    if req.mode not in ("collab", "bin"):
        raise ValueError(f"mode={req.mode!r} is invalid: expected one of collab, bin")
    area = points[mask]
    if len(area) == 0:
        raise NoFeasibleGrasp("the grasping area is empty: no point of the cloud is in area_mask")

    pl, gr = req.planner, req.gripper
    axis = main_axis(area)
    k = choose_k(pl.k, pl.k_max, area, axis, gr.max_width_m)
    clusters = segment(area, k, random_state=kmeans_random_state(req.seed, pl.seed))
    centers, radii = clusters.centers_m, clusters.radii_m
    k = len(centers)
    m = int(pl.m)

    directions = approach_directions(centers, m)  # (K, M, 3)
    feasible = above_support(centers, directions, pl.sphere_radius_m, req.table_z, pl.table_clearance_m)
    if not feasible.any():
        raise NoFeasibleGrasp(
            f"every one of the {k * m} paths starts below the support plane z = "
            f"{req.table_z + pl.table_clearance_m:.4f} m (sphere radius {pl.sphere_radius_m} m)"
        )
    n_table_ok = int(feasible.sum())

    costs = np.full((k, m), np.inf)
    for j in range(k):
        ok = feasible[j]
        if ok.any():
            costs[j, ok] = cluster_costs(
                points,
                centers[j],
                radii[j],
                directions[j, ok],
                axis,
                req.mode,
                req.table_z,
                gr.max_width_m,
                req.cost,
            )

    order = np.argsort(costs, axis=None, kind="stable")[:n_table_ok]
    best = None
    slab_extent = 0.0
    n_too_wide = 0
    start, size = 0, 1  # the cheapest path nearly always fits: check it alone, then in batches
    while best is None and start < len(order):
        batch = order[start : start + size]
        start, size = start + len(batch), WIDTH_CHECK_BATCH
        ks, ps = np.unravel_index(batch, (k, m))
        extents = np.empty(len(batch))
        for kk in np.unique(ks):
            sel = ks == kk
            rots = grasp_rotations(directions[kk, ps[sel]], axis)
            extents[sel] = slab_extents_m(points, centers[kk], rots, gr)
        for kk, pp, ext in zip(ks, ps, extents, strict=True):
            if ext > gr.max_width_m:
                feasible[kk, pp] = False
                costs[kk, pp] = np.inf
                n_too_wide += 1
            else:
                best, slab_extent = (int(kk), int(pp)), float(ext)
                break
    if best is None:
        raise NoFeasibleGrasp(
            f"object wider than the gripper: on all {n_table_ok} paths above the support the object's "
            f"section between the pads exceeds gripper.max_width_m = {gr.max_width_m} m"
        )

    kb, pb = best
    pose = grasp_pose(centers[kb], directions[kb, pb], axis)
    width = opening_width_m(float(radii[kb]), pl.width_margin, gr)
    grasp = Grasp(
        pose=pose,
        width_m=width,
        cost=float(costs[kb, pb]),
        cluster=kb,
        path=pb,
        n_feasible=n_table_ok - n_too_wide,
        planner=NAME,
        extras={"K": k, "M": m, "n_too_wide": n_too_wide, "slab_extent_m": slab_extent},
    )
    details = {
        "cloud": points,
        "area_mask": mask,
        "labels": clusters.labels,
        "centers": centers,
        "radii": radii,
        "main_axis": axis,
        "directions": directions,
        "feasible": feasible,
        "costs": costs,
        "best": np.array([kb, pb]),
        "pose": pose,
        "width": np.float64(width),
        "mode": np.str_(req.mode),
        "table_z": np.float64(req.table_z),
        "sphere_radius": np.float64(pl.sphere_radius_m),
        "gripper_max_width": np.float64(gr.max_width_m),
    }
    return PlanResult(grasp=grasp, details=details)
