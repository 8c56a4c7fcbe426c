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
   modes (the plane is the box top in collab mode, the table top in bin mode; Fig. 8); in a clutter round
   (``req.neighbours``) so are the paths that pass through another object (III-D's reason;
   :func:`.paths.clear_of`, ``planner.neighbour_voxel_m``);
6. cost Eq. (1) (collab) or Eq. (2)-(3) (bin) of every remaining path (:mod:`.cost`); removed paths
   cost ``inf``;
7. paths are taken in ascending cost (stable order: cluster-major, then path index) and the first that
   passes every test switched on wins; with none on (as printed) that is the path of least cost.
   ``planner.section_fit``: the object's section between the pads (:func:`.pose.slab_spans_m`, extent
   ``y_hi - y_lo``) fits its opening ``w_k = clip(2 r_k (1 + width_margin), min_width, max_width)``;
   ``planner.swept_check``: the fingers and palm opened to the path's width, swept from the sphere point
   to the grasp pose, meet no cloud point and, where ``req.support_blocks_gripper``, stay above the
   support, and in a clutter round meet no neighbour's point, between the pads included
   (:mod:`.collision`, :func:`.collision.neighbour_hits`, margin 0; ``extras["n_collides"]``); ``planner.min_contacts_in_area``
   > 0: at least that share of each pad's contact points are grasping-area points
   (:func:`.stability.pad_contacts`; ``extras["n_outside_area"]``, ``extras["in_area_required"]``).
   Checking lazily in cost order picks exactly the argmin over the paths passing every test; examined
   paths that fail get cost ``inf`` and ``feasible`` False, unexamined ones keep their table verdict.
   If none passes (all were then examined): the cheapest path whose section fits the stroke
   ``max_width`` (and passes the other tests) is taken with its opening widened to
   ``clip(section (1 + width_margin), min_width, max_width)`` (``extras["widened"]``); in the modes of
   ``planner.fallback_modes`` the area rule is relaxed to the largest share reached, if at least
   ``planner.fallback_contacts_in_area`` (:mod:`.area_rule`). Otherwise :class:`NoFeasibleGrasp`
   names the test: "object wider than the gripper ...", the swept check, or the grasping area;
8. pose per Fig. 9 and opening width ``w_k`` (:mod:`.pose`); the origin is ``c_k``
   (``planner.grasp_point: centre``) or ``c_k`` moved along the closing axis Y to the middle of the
   section (``section_middle``; ``extras["centre_shift_m"]``), since the pads close symmetrically.

``Grasp.n_feasible`` is the number of paths still ``feasible`` after step 7. ``details`` is an
:class:`graspexp.planning.details.OptimalDetails` (every intermediate, with shapes and units)."""

from collections.abc import Callable
from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np

from graspexp.core.geometry import make_pose
from graspexp.core.seeding import derive_seed
from graspexp.grippers import GripperGeometry
from graspexp.planning.area_rule import area_test, fallback_share, no_grasp_in_area
from graspexp.planning.cells import CellCloud, cell_cloud
from graspexp.planning.clusters import Clusters, choose_k, elongation, main_axis, max_radii_m, segment
from graspexp.planning.collision import lowest_z, neighbour_hits
from graspexp.planning.cost import all_path_costs
from graspexp.planning.details import OptimalDetails
from graspexp.planning.grasp import Grasp, NoFeasibleGrasp
from graspexp.planning.paths import above_support, approach_directions, clear_of
from graspexp.planning.pose import grasp_rotation, grasp_rotations, opening_widths_m, slab_spans_m
from graspexp.planning.request import PlanRequest, PlanResult
from graspexp.planning.stability import pad_contacts

NAME = "optimal"
LITERAL_NAME = "optimal_literal"
"""The same function under the preset that reads the paper as printed (conf/planner/optimal_literal.yaml)."""

WIDTH_CHECK_BATCHES = (1, 8, 32)
"""Paths checked per batch by the lazy section test of step 7: the cheapest alone (it fits about half
the time on the Table 1 objects), then the next 8 (about 90 % cumulative), then 32 at a time."""
MAX_SPECULATIVE_PATHS = 256
"""The batches of :data:`WIDTH_CHECK_BATCHES` are tested in fewer array passes: the first ones together
(1 + 8 + 32 paths), then as many as were examined before, up to this many (among neighbours every path may
be examined); their tests are kept batch by batch up to the first with a passing path, so the result is
that of one batch at a time, and a pass costs far more than the paths it tests."""


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

    @cached_property
    def cells(self) -> CellCloud:
        """``points`` sorted into cubes (:func:`graspexp.planning.cells.cell_cloud`) for the swept check."""
        return cell_cloud(self.points)


def paper_candidates(req: PlanRequest, planner: str, cluster_length_m: float | None = None) -> Candidates:
    """Grasping area -> main axis -> K-means -> Fibonacci paths -> support test -> cost, as in section III,
    among a clutter round's neighbours (:func:`among_neighbours`) when the request has any.
    ``planner`` and ``cluster_length_m`` as in :func:`target_candidates`."""
    cand = target_candidates(req, planner, cluster_length_m)
    return among_neighbours(req, cand, planner) if req.neighbours else cand


def target_candidates(req: PlanRequest, planner: str, cluster_length_m: float | None = None) -> Candidates:
    """:func:`paper_candidates` for the target alone (its neighbours, if any, not looked at).

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
    source = pose_axis_source(pl, area)
    axes = {name: main_axis(points if name == "object" else area) for name in {pl.main_axis, source}}
    axis, pose_axis = axes[pl.main_axis], axes[source]
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
    return Candidates(points, mask, axis, pose_axis, clusters, directions, feasible, costs)


def among_neighbours(req: PlanRequest, cand: Candidates, planner: str) -> Candidates:
    """``cand`` (planned for the target alone) with the paths through a clutter round's other objects removed
    (step 5, III-D's rule for the support; :func:`.paths.clear_of`, ``planner.neighbour_voxel_m``): not
    feasible, cost inf. A path's cost depends on that path only, so these are the costs planned among the
    neighbours. Raises NoFeasibleGrasp when every path is removed."""
    pl = req.planner
    clusters = cand.clusters
    clear = clear_of(
        clusters.centers_m, clusters.radii_m, cand.directions, pl.sphere_radius_m, req.neighbour_points,
        pl.neighbour_voxel_m,
    )  # fmt: skip
    feasible = cand.feasible & clear
    if not feasible.any():
        k, m = feasible.shape
        raise NoFeasibleGrasp(
            f"{planner}: every one of the {k * m} paths passes through the support or another object"
        )
    return replace(cand, feasible=feasible, costs=np.where(feasible, cand.costs, np.inf))


def paper_details(
    req: PlanRequest, cand: Candidates, best: tuple[int, int], pose: np.ndarray, width_m: float
) -> dict:
    """The fields of :class:`graspexp.planning.details.PaperDetails` for the chosen path ``best`` (k, p)
    with grasp ``pose`` (4, 4) and opening ``width_m`` (m)."""
    return {
        "cloud": cand.points,
        "area_mask": cand.area_mask,
        "labels": cand.clusters.labels,
        "centers": cand.clusters.centers_m,
        "radii": cand.clusters.radii_m,
        "main_axis": cand.axis,
        "pose_axis": cand.pose_axis,
        "directions": cand.directions,
        "feasible": cand.feasible,
        "costs": cand.costs,
        "best": np.array(best),
        "pose": pose,
        "width": width_m,
        "mode": req.mode,
        "table_z": float(req.table_z),
        "sphere_radius": float(req.planner.sphere_radius_m),
        "gripper_max_width": float(req.gripper.max_width_m),
    }


def pose_axis_source(pl, area_m: np.ndarray) -> str:
    """Which cloud's main axis the grasp frame's X follows: ``object`` or ``area`` (``planner.pose_axis``;
    ``area_if_elongated``: the area's when its :func:`.clusters.elongation` reaches
    ``planner.pose_axis_min_elongation``)."""
    if pl.pose_axis != "area_if_elongated":
        return str(pl.pose_axis)
    return "area" if elongation(area_m) >= pl.pose_axis_min_elongation else "object"


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
    """Plan one grasp with the paper's strategy; see the module doc for the steps and ``details``.

    Raises
    ------
    NoFeasibleGrasp
        Empty grasping area; every path crosses the support plane; or no remaining path passes the
        tests of step 7 even after its fallbacks.
    """
    cand = paper_candidates(req, req.planner.name)
    pl, gr = req.planner, req.gripper
    centers, radii = cand.clusters.centers_m, cand.clusters.radii_m
    feasible, costs = cand.feasible, cand.costs  # narrowed in place below: the details' record
    k, m = costs.shape
    openings = opening_widths_m(radii, pl.width_margin, gr)  # (K,) m
    tests = PathTests.empty(k, m)
    best, best_rotation, need = _choose_path(req, cand, openings, tests)
    examined = ~np.isnan(tests.section)
    widened = bool(pl.section_fit and tests.section[best] > openings[best[0]])
    limits = gr.max_width_m if widened else openings[:, None]
    too_wide = examined & (tests.section > limits) if pl.section_fit else np.zeros_like(examined)
    collides = examined & ~too_wide & ~tests.free
    outside = examined & ~too_wide & ~collides & (tests.share < need)
    n_too_wide, n_collides, n_outside = (int((feasible & t).sum()) for t in (too_wide, collides, outside))
    feasible &= ~(too_wide | collides | outside)
    costs[~feasible] = np.inf
    spans, section = tests.spans, tests.section

    kb, pb = best
    slab_extent = float(section[kb, pb])
    pose = make_pose(best_rotation, centers[kb])
    shift_m = float(_centre_shifts_m(pl, spans[kb, pb][None])[0])
    pose[:3, 3] += shift_m * pose[:3, 1]  # pads close symmetrically about the origin (pose.py doc)
    width = float(_opened_widths_m(pl, gr, section[kb, pb][None], openings[kb][None])[0])
    grasp = Grasp(
        pose=pose,
        width_m=width,
        cost=float(costs[kb, pb]),
        cluster=kb,
        path=pb,
        n_feasible=int(feasible.sum()),
        planner=req.planner.name,
        touches_neighbours=bool(tests.relaxed[0]) if req.neighbours else False,
        extras={
            "K": k,
            "M": m,
            "n_too_wide": n_too_wide,
            "slab_extent_m": slab_extent,
            "centre_shift_m": shift_m,
            "widened": widened,
            **({"n_collides": n_collides} if pl.swept_check else {}),
            **({"n_outside_area": n_outside, "in_area_required": float(need)} if need > 0 else {}),
        },
    )
    details = OptimalDetails(
        **paper_details(req, cand, (kb, pb), pose, width),
        section_width=section,
        section_span=spans,
        contact_share=tests.share,
    )
    return PlanResult(grasp=grasp, details=details)


@dataclass(frozen=True)
class PathTests:
    """Step 7's tests of the paths examined (nan / True where not examined), each (K, M) unless noted.

    spans : (K, M, 2) [y_lo, y_hi] of the object's section between the pads about c_k, m; section : its
    extent, m; share : the smaller pad's share of contact points in the grasping area; free : the opened
    gripper's swept fingers and palm clear of the cloud and of a blocking support (and of a clutter round's
    neighbours); alone : the same without the neighbours; relaxed : (1,) whether ``free`` was relaxed to
    ``alone`` (``planner.neighbour_fallback``)."""

    spans: np.ndarray
    section: np.ndarray
    share: np.ndarray
    free: np.ndarray
    alone: np.ndarray
    relaxed: np.ndarray

    def keep(self, other: "PathTests", ks: np.ndarray, ps: np.ndarray) -> None:
        """Copy ``other``'s tests of the paths ``(ks, ps)`` (B,) into these, in place (not ``relaxed``)."""
        for name in ("spans", "section", "share", "free", "alone"):
            getattr(self, name)[ks, ps] = getattr(other, name)[ks, ps]

    @classmethod
    def empty(cls, k: int, m: int) -> "PathTests":
        return cls(
            np.full((k, m, 2), np.nan),
            np.full((k, m), np.nan),
            np.full((k, m), np.nan),
            np.ones((k, m), bool),
            np.ones((k, m), bool),
            np.zeros(1, bool),
        )


def _choose_path(
    req: PlanRequest, cand: Candidates, openings: np.ndarray, tests: PathTests
) -> tuple[tuple[int, int], np.ndarray, float]:
    """Step 7: the cheapest path passing the section test (``planner.section_fit``), the swept check
    (``planner.swept_check``) and the area rule (``planner.min_contacts_in_area``), examined lazily in
    cost order; with none of them, the least cost. Fills ``tests`` for the paths examined, in place.
    Returns the (cluster, path) chosen, its (3, 3) rotation and the in-area share required.
    """
    pl, gr = req.planner, req.gripper
    directions, costs = cand.directions, cand.costs
    k, m = costs.shape
    need = float(pl.min_contacts_in_area)
    order = np.argsort(costs, axis=None, kind="stable")[: int(cand.feasible.sum())]
    bounds = np.cumsum([0, *WIDTH_CHECK_BATCHES])
    last = WIDTH_CHECK_BATCHES[-1]
    bounds = np.r_[bounds[bounds < len(order)], np.arange(bounds[-1], len(order), last), len(order)]
    scratch = PathTests.empty(k, m)
    b = 0
    while b < len(bounds) - 1:
        # tested together: the first batches (up to the size of the last), then as many as were examined
        # before (at most MAX_SPECULATIVE_PATHS); kept batch by batch up to the first with a passing path
        reach = max(min(2 * bounds[b], bounds[b] + MAX_SPECULATIVE_PATHS), sum(WIDTH_CHECK_BATCHES))
        end = min(max(int(np.searchsorted(bounds, reach, "right")) - 1, b + 1), len(bounds) - 1)
        chunk = order[bounds[b] : bounds[end]]
        ks, ps = np.unravel_index(chunk, (k, m))
        rots = grasp_rotations(directions[ks, ps], cand.pose_axis)
        passing = _test_batch(req, cand, openings, scratch, ks, ps, rots)
        fit = np.flatnonzero(passing)
        if len(fit):  # kept up to the end of the batch of the first passing path
            i = int(fit[0])
            upto = bounds[np.searchsorted(bounds, bounds[b] + i, "right")] - bounds[b]
            tests.keep(scratch, ks[:upto], ps[:upto])
            return (int(ks[i]), int(ps[i])), rots[i], need
        tests.keep(scratch, ks, ps)
        b = end
    # Every path above the support was examined and none passed. Fallbacks: a section that fits the
    # stroke (opened to the section), then, in pl.fallback_modes, the largest in-area share reached.
    section, share = tests.section, tests.share
    fits_stroke = cand.feasible & ((section <= gr.max_width_m) | (not pl.section_fit))
    if not fits_stroke.any():
        raise NoFeasibleGrasp(
            f"object wider than the gripper: on all {len(order)} paths above the support the object's "
            f"section between the pads exceeds gripper.max_width_m = {gr.max_width_m} m"
        )
    clear = fits_stroke & tests.free
    if not clear.any() and req.neighbours and pl.neighbour_fallback:  # touching a neighbour is allowed
        tests.free[:] = tests.alone
        tests.relaxed[0] = True
        clear = fits_stroke & tests.free
    if not clear.any():
        raise NoFeasibleGrasp(
            f"{pl.name}: on all {len(order)} paths above the support whose section fits the stroke the "
            "opened gripper's swept fingers or palm meet the object or the support"
            + (" or another object" if req.neighbours else "")
            + " (planner.swept_check)"
        )
    ok = clear
    if need > 0:
        ok, _, best_share = area_test(clear, share, need)
        if not ok.any():
            fallback = fallback_share(req, best_share)
            if fallback is None:
                raise NoFeasibleGrasp(
                    f"{pl.name}: every one of the {len(order)} paths above the support whose section fits "
                    "the stroke and whose swept gripper is clear has " + no_grasp_in_area(req, best_share)
                )
            need = fallback
            ok = area_test(clear, share, need)[0]
    fits = ok & (section <= openings[:, None]) if pl.section_fit else ok
    flat = int(np.argmin(np.where(fits if fits.any() else ok, costs, np.inf)))
    best = (flat // m, flat % m)
    return best, grasp_rotation(directions[best], cand.pose_axis), need


def _test_batch(
    req: PlanRequest,
    cand: Candidates,
    openings: np.ndarray,
    tests: PathTests,
    ks: np.ndarray,
    ps: np.ndarray,
    rots: np.ndarray,
) -> np.ndarray:
    """Run step 7's tests on the (B,) paths ``(ks, ps)`` with (B, 3, 3) rotations ``rots``, filling
    ``tests``; returns (B,) whether each passes every test switched on."""
    pl, gr = req.planner, req.gripper
    points, centers = cand.points, cand.clusters.centers_m
    spans = slab_spans_m(points, centers[ks], rots, gr)
    extent = spans[:, 1] - spans[:, 0]
    tests.spans[ks, ps], tests.section[ks, ps] = spans, extent
    ok = extent <= openings[ks] if pl.section_fit else np.ones(len(ks), dtype=bool)
    poses = np.tile(np.eye(4), (len(ks), 1, 1))
    poses[:, :3, :3], poses[:, :3, 3] = rots, centers[ks]
    if pl.min_contacts_in_area > 0:  # contacts do not depend on the shift along the closing axis
        normals = np.asarray(req.normals, dtype=np.float64)
        geometry = GripperGeometry.of(gr)
        share = pad_contacts(points, normals, poses, geometry, pl.contact_band_m, cand.area_mask)[2]
        tests.share[ks, ps] = share
        ok &= share >= pl.min_contacts_in_area
    if pl.swept_check:
        poses[:, :3, 3] += _centre_shifts_m(pl, spans)[:, None] * rots[:, :, 1]
        widths = _opened_widths_m(pl, gr, extent, openings[ks])
        free = np.ones(len(ks), dtype=bool)
        if req.support_blocks_gripper:  # first: most paths that fail, fail here (69 % of those tested in
            # the clutter benchmark's scenes), and the cloud is swept only where the support is clear
            free = lowest_z(poses, gr, widths, pl.sphere_radius_m) >= req.table_z
        _sweep_free(free, lambda: cand.cells, poses, gr, widths, pl.sphere_radius_m, between_pads=False)
        if req.neighbours:  # only a path clear of the target and the support may be clear of them all
            tests.alone[ks, ps] = free
            _sweep_free(free, lambda: req.neighbour_cells, poses, gr, widths, pl.sphere_radius_m)
        tests.free[ks, ps] = free
        ok &= free
    return ok


def _sweep_free(
    free: np.ndarray,
    cells: Callable[[], CellCloud],
    poses: np.ndarray,
    gr,
    widths: np.ndarray,
    sweep_m: float,
    **kw,
) -> None:
    """Clear ``free`` (B,) bool, in place, where the gripper of a grasp still free (poses (B, 4, 4), openings
    ``widths`` (B,) m) swept ``sweep_m`` meets a point of the :class:`CellCloud` ``cells()`` gives
    (:func:`.collision.neighbour_hits`, margin 0, ``kw`` its other keywords), called only when some grasp is
    still free: a cloud is cubed on first use."""
    if free.any():
        free[free] = ~neighbour_hits(
            cells(), poses[free], gr, widths[free], sweep_m=sweep_m, margin_m=0.0, **kw
        )


def _centre_shifts_m(pl, spans: np.ndarray) -> np.ndarray:
    """(B,) move of the grasp point from c_k along the closing axis Y, m, for (B, 2) section spans: to the
    section's middle (``planner.grasp_point: section_middle``) or none (``centre``)."""
    return spans.mean(axis=1) if pl.grasp_point == "section_middle" else np.zeros(len(spans))


def _opened_widths_m(pl, gr, extent_m: np.ndarray, openings_m: np.ndarray) -> np.ndarray:
    """(B,) opening of paths with (B,) section extents and (B,) cluster openings w_k, m: w_k, or with
    ``planner.section_fit`` a section wider than w_k opened to ``clip(section (1 + width_margin))``."""
    if not pl.section_fit:
        return openings_m
    widened = np.clip(extent_m * (1.0 + pl.width_margin), gr.min_width_m, gr.max_width_m)
    return np.where(extent_m <= openings_m, openings_m, widened)
