"""The paper's optimal grasping strategy (section III), as one pure function of a :class:`PlanRequest`.

Every choice the paper leaves open is a ``planner`` config key (graspexp/config/planner/optimal.py says which
sentence each rests on); the presets ``optimal`` (this project's reading) and ``optimal_literal`` (the
paper as printed) differ only in those keys. Steps (the cloud arrives already transformed by the
object pose: world frame, metres):

1. grasping area = ``points[area_mask]`` (III-A); empty -> :class:`NoFeasibleGrasp`;
2. main axes = first principal components of the object cloud or the area (III-D, Fig. 7;
   :mod:`.clusters`): ``planner.main_axis`` for alpha and the K rule, ``planner.pose_axis`` for the
   grasp frame's X;
3. K from ``planner.k`` or the ``auto`` rule; seeded K-means -> centres ``c_k``, radii ``r_k``
   (``planner.cluster_radius``: max or RMS distance; III-B, Fig. 5);
   ``random_state = derive_seed(req.seed, "kmeans", planner.seed)``;
4. ``M`` Fibonacci-sphere paths per centre, radius ``planner.sphere_radius_m`` (III-C, Fig. 6);
5. paths whose sphere point lies below ``z = table_z + planner.table_clearance_m`` are removed, in both
   modes (the plane is the box top in collab mode, the table top in bin mode; Fig. 8);
6. cost Eq. (1) (collab) or Eq. (2)-(3) (bin) of every remaining path (:mod:`.cost`); removed paths
   cost ``inf``;
7. ``planner.section_fit`` false: the path of least cost wins (as printed). True: paths are taken in
   ascending cost (stable order: cluster-major, then path index) and the first whose object section
   between the pads (:func:`.pose.slab_spans_m`, extent ``y_hi - y_lo``) fits its opening
   ``w_k = clip(2 r_k (1 + width_margin), min_width, max_width)`` wins. Checking lazily in cost order
   picks exactly the argmin over the paths passing both tests; examined paths that fail get cost ``inf``
   and ``feasible`` False, unexamined ones keep their table verdict. If no path's section fits its
   ``w_k`` (all were then examined), the cheapest path whose section fits the stroke ``max_width`` is
   taken and the opening is widened to ``clip(section (1 + width_margin), min_width, max_width)``
   (``extras["widened"]``); if none fits the stroke either:
   ``NoFeasibleGrasp("object wider than the gripper ...")``;
8. pose per Fig. 9 and opening width ``w_k`` (:mod:`.pose`); the origin is ``c_k``
   (``planner.grasp_point: centre``) or ``c_k`` moved along the closing axis Y to the middle of the
   section (``section_middle``; ``extras["centre_shift_m"]``), since the pads close symmetrically.

``Grasp.n_feasible`` is the number of paths still ``feasible`` after step 7. ``details`` holds ``cloud``,
``area_mask``, ``labels`` (K-means label of each area point), ``centers``, ``radii`` (m), ``main_axis``,
``pose_axis``, ``directions`` (K, M, 3), ``feasible`` (K, M), ``costs`` (K, M; inf where infeasible),
``section_width`` (K, M; m, nan where not examined), ``section_span`` (K, M, 2; [y_lo, y_hi] about c_k,
m), ``best`` (k, p), ``pose``, ``width``, ``mode``, ``table_z``, ``sphere_radius`` and
``gripper_max_width``."""

from dataclasses import dataclass, replace

import numpy as np

from graspexp.config import GripperConfig
from graspexp.geometry import make_pose
from graspexp.planning.clusters import Clusters, choose_k, main_axis, max_radii_m, segment
from graspexp.planning.cost import all_path_costs
from graspexp.planning.grasp import Grasp, NoFeasibleGrasp
from graspexp.planning.paths import above_support, approach_directions
from graspexp.planning.pose import grasp_rotation, grasp_rotations, opening_widths_m, slab_spans_m
from graspexp.planning.request import PlanRequest, PlanResult
from graspexp.seeding import derive_seed

NAME = "optimal"
LITERAL_NAME = "optimal_literal"
"""The same function under the preset that reads the paper as printed (conf/planner/optimal_literal.yaml)."""

WIDTH_CHECK_BATCHES = (1, 8, 32)
"""Paths checked per batch by the lazy section test of step 7: the cheapest alone (it fits about half
the time on the Table 1 objects), then the next 8 (about 90 % cumulative), then 32 at a time."""


def kmeans_random_state(seed: int, planner_seed: int) -> int:
    """Seed of the K-means generator (``numpy.random.default_rng``) of one plan."""
    return derive_seed(seed, "kmeans", planner_seed)


@dataclass(frozen=True)
class Candidates:
    """Steps 1-6 of the paper's strategy for one request: everything before a path is chosen.

    points : (N, 3) world m; area_mask : (N,) bool; axis : (3,) unit main axis of alpha and the K rule
    (``planner.main_axis``); pose_axis : (3,) unit axis the grasp frame's X follows (``planner.pose_axis``);
    clusters : K-means result, ``radii_m`` as ``planner.cluster_radius`` defines r_k;
    directions : (K, M, 3) unit approach directions; feasible : (K, M) above the support;
    costs : (K, M) Eq. (1) or (2)-(3), inf where infeasible.
    """

    points: np.ndarray
    area_mask: np.ndarray
    axis: np.ndarray
    pose_axis: np.ndarray
    clusters: Clusters
    directions: np.ndarray
    feasible: np.ndarray
    costs: np.ndarray


def paper_candidates(req: PlanRequest, planner: str, cluster_length_m: float | None = None) -> Candidates:
    """Grasping area -> main axis -> K-means -> Fibonacci paths -> support test -> cost, as in section III.

    ``planner`` names the caller in error messages. ``cluster_length_m``: the length along the main axis
    that ``k: auto`` gives each cluster, m (None: ``planner.auto_k_stroke_fraction`` of the stroke). Raises NoFeasibleGrasp for an empty area or when every
    path starts below the support plane; ValueError for malformed inputs.
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
        raise NoFeasibleGrasp(f"{planner}: the grasping area is empty: no point of the cloud is in area_mask")

    pl, gr = req.planner, req.gripper
    axes = {name: main_axis(points if name == "object" else area) for name in {pl.main_axis, pl.pose_axis}}
    axis = axes[pl.main_axis]
    if cluster_length_m is None:
        k = choose_k(pl.k, pl.k_max, area, axis, gr.max_width_m, pl.auto_k_stroke_fraction)
    else:
        k = choose_k(pl.k, pl.k_max, area, axis, cluster_length_m, 1.0)
    clusters = segment(area, k, random_state=kmeans_random_state(req.seed, pl.seed))
    if pl.cluster_radius == "max":
        clusters = replace(clusters, radii_m=max_radii_m(area, clusters))
    elif pl.cluster_radius != "rms":
        raise ValueError(f"planner.cluster_radius={pl.cluster_radius!r} is invalid: expected one of max, rms")
    centers = clusters.centers_m
    k, m = len(centers), int(pl.m)

    directions = approach_directions(centers, m)  # (K, M, 3)
    feasible = above_support(centers, directions, pl.sphere_radius_m, req.table_z, pl.table_clearance_m)
    if not feasible.any():
        raise NoFeasibleGrasp(
            f"{planner}: every one of the {k * m} paths starts below the support plane z = "
            f"{req.table_z + pl.table_clearance_m:.4f} m (sphere radius {pl.sphere_radius_m} m)"
        )
    costs = path_costs(req, points, axis, clusters, directions, feasible)
    return Candidates(points, mask, axis, axes[pl.pose_axis], clusters, directions, feasible, costs)


def path_costs(
    req: PlanRequest,
    points: np.ndarray,
    axis: np.ndarray,
    clusters: Clusters,
    directions: np.ndarray,
    feasible: np.ndarray,
) -> np.ndarray:
    """(K, M) Eq. (1) or (2)-(3) of every path above the support, inf elsewhere (step 6).

    points : (N, 3) world m; axis : (3,) main axis; directions : (K, M, 3); feasible : (K, M) bool.
    """
    return all_path_costs(
        points,
        clusters.centers_m,
        clusters.radii_m,
        directions,
        feasible,
        axis,
        req.mode,
        req.table_z,
        req.gripper.max_width_m,
        req.cost,
    )


def plan_optimal(req: PlanRequest) -> PlanResult:
    """Plan one grasp with the paper's strategy; see the module doc for the steps and ``details`` keys.

    Raises
    ------
    NoFeasibleGrasp
        Empty grasping area; every path crosses the support plane; or every remaining path finds the
        object wider than the gripper's stroke.
    """
    cand = paper_candidates(req, req.planner.name)
    pl, gr = req.planner, req.gripper
    points, mask, clusters = cand.points, cand.area_mask, cand.clusters
    centers, radii, directions, feasible, costs = (
        clusters.centers_m,
        clusters.radii_m,
        cand.directions,
        cand.feasible,
        cand.costs,
    )
    k, m = costs.shape
    openings = opening_widths_m(radii, pl.width_margin, gr)  # (K,) m
    spans = np.full((k, m, 2), np.nan)  # [y_lo, y_hi] of the section between the pads (nan: not examined)
    section = np.full((k, m), np.nan)  # its extent, m
    if pl.section_fit:
        best, best_rotation, widened = _cheapest_fitting(cand, openings, spans, section, gr)
    else:  # the printed argmin of the cost over the paths above the support
        flat = int(np.argmin(costs))
        best, widened = (flat // m, flat % m), False
        best_rotation = grasp_rotation(directions[best], cand.pose_axis)
        spans[best] = slab_spans_m(points, centers[best[0]], best_rotation[None], gr)[0]
        section[best] = spans[best][1] - spans[best][0]
    if not pl.section_fit:
        fits = feasible
    elif widened:
        fits = feasible & (section <= gr.max_width_m)
    else:  # unexamined paths keep their table verdict
        fits = feasible & ~(section > openings[:, None])
    n_too_wide = int((feasible & ~fits).sum())
    feasible &= fits
    costs[~feasible] = np.inf

    kb, pb = best
    slab_extent = float(section[kb, pb])
    pose = make_pose(best_rotation, centers[kb])
    shift_m = float(spans[kb, pb].mean()) if pl.grasp_point == "section_middle" else 0.0
    pose[:3, 3] += shift_m * pose[:3, 1]  # pads close symmetrically about the origin (pose.py doc)
    width = float(openings[kb])
    if widened:
        width = float(np.clip(slab_extent * (1.0 + pl.width_margin), gr.min_width_m, gr.max_width_m))
    grasp = Grasp(
        pose=pose,
        width_m=width,
        cost=float(costs[kb, pb]),
        cluster=kb,
        path=pb,
        n_feasible=int(feasible.sum()),
        planner=req.planner.name,
        extras={
            "K": k,
            "M": m,
            "n_too_wide": n_too_wide,
            "slab_extent_m": slab_extent,
            "centre_shift_m": shift_m,
            "widened": widened,
        },
    )
    details = {
        "cloud": points,
        "area_mask": mask,
        "labels": clusters.labels,
        "centers": centers,
        "radii": radii,
        "main_axis": cand.axis,
        "pose_axis": cand.pose_axis,
        "directions": directions,
        "feasible": feasible,
        "costs": costs,
        "section_width": section,
        "section_span": spans,
        "best": np.array([kb, pb]),
        "pose": pose,
        "width": np.float64(width),
        "mode": np.str_(req.mode),
        "table_z": np.float64(req.table_z),
        "sphere_radius": np.float64(pl.sphere_radius_m),
        "gripper_max_width": np.float64(gr.max_width_m),
    }
    return PlanResult(grasp=grasp, details=details)


def _cheapest_fitting(
    cand: Candidates, openings: np.ndarray, spans: np.ndarray, section: np.ndarray, gr: GripperConfig
) -> tuple[tuple[int, int], np.ndarray, bool]:
    """Step 7 with ``planner.section_fit``: the cheapest path whose section fits its opening.

    Fills ``spans`` (K, M, 2) and ``section`` (K, M) for the paths examined, in place. Returns the
    (cluster, path) chosen, its (3, 3) rotation and whether the fallback (open to the section) was taken.
    """
    points, centers, directions, costs = cand.points, cand.clusters.centers_m, cand.directions, cand.costs
    k, m = costs.shape
    order = np.argsort(costs, axis=None, kind="stable")[: int(cand.feasible.sum())]
    start, n_batches = 0, 0
    while start < len(order):
        size = WIDTH_CHECK_BATCHES[min(n_batches, len(WIDTH_CHECK_BATCHES) - 1)]
        batch = order[start : start + size]
        start, n_batches = start + len(batch), n_batches + 1
        ks, ps = np.unravel_index(batch, (k, m))
        rots = grasp_rotations(directions[ks, ps], cand.pose_axis)
        spans[ks, ps] = slab_spans_m(points, centers[ks], rots, gr)
        extent = spans[ks, ps, 1] - spans[ks, ps, 0]
        section[ks, ps] = extent
        fit = np.flatnonzero(extent <= openings[ks])
        if len(fit):
            return (int(ks[fit[0]]), int(ps[fit[0]])), rots[fit[0]], False
    # Fallback: no section fits its r_k opening; every path above the support was examined. Keep those
    # whose section fits the stroke and open to the section plus margin.
    fits = cand.feasible & (section <= gr.max_width_m)
    if not fits.any():
        raise NoFeasibleGrasp(
            f"object wider than the gripper: on all {len(order)} paths above the support the object's "
            f"section between the pads exceeds gripper.max_width_m = {gr.max_width_m} m"
        )
    flat = int(np.argmin(np.where(fits, costs, np.inf)))
    best = (flat // m, flat % m)
    return best, grasp_rotation(directions[best], cand.pose_axis), True
