"""``optimal_plus``: the paper's candidates and cost, then the tests a grasp needs to hold in physics.

The paper's steps are reused unchanged (:func:`graspexp.planning.optimal.paper_candidates`): grasping
area, main axis, K-means clusters, M Fibonacci-sphere paths per cluster, support-plane test and cost
Eq. (1)-(3). Its paths are then examined in ascending cost, in batches of :data:`PATH_BATCH`; each path
is tried at several depths along its approach, and every try is checked as follows (each term has a
``planner`` key, graspexp/config/planner/optimal_plus.py):

1. **Opening and grasp point from the geometry** (``opening``). The grasp point moves along the closing
   axis to the middle of the object's section between the pads and the opening is that section plus
   ``2 width_clearance_m`` (``section``), or at least the paper's ``2 r_k (1 + width_margin)``
   (``cluster``). Wider than the stroke: rejected.
2. **Swept-volume collision** of both fingers and the palm with the cloud and the support along the whole
   straight approach (:func:`graspexp.planning.collision.place_grasps`, margin ``collision_margin_m``).
3. **Pad contacts** (``depth_offsets_m``, ``rolls_deg``, ``min_pad_depth_m``, ``pad_depth_target_m``,
   ``friction_coef``, ``min_contacts_in_area``): the grasp frame is rolled about the approach by each of ``rolls_deg`` and its
   point moved along the approach by each offset; a try is kept only when both pads' contacts are
   centred at least ``min_pad_depth_m`` behind the fingertips, their surface normals lie inside the
   friction cone about the closing axis and at least ``min_contacts_in_area`` of each pad's contact
   points are grasping-area points (:func:`graspexp.planning.stability.pad_contacts`). Per path the
   first roll with a passing try is taken, and in it the try whose shallower pad depth reaches
   ``pad_depth_target_m`` with the smallest move (else the deepest).
4. **Gravity arm** (``com_weight``): the path's cost is multiplied by ``1 + com_weight * a / D``, with
   ``a`` the arm of gravity about the closing axis (:func:`graspexp.planning.stability.gravity_arm_m`;
   centre of mass = the cloud's solid-hull centroid) and ``D`` the diagonal of the cloud's box.
5. **Pose noise** (``noise_trans_mm``, ``noise_rot_deg``, ``noise_samples``, ``noise_min_pass``): the
   first ``shortlist`` passing paths are re-checked (collision with zero margin and pad depth) with the
   cloud moved by ``noise_samples`` motions drawn from the estimator's error about the object's
   origin; the paths passing in at least ``noise_min_pass`` of them (else those passing most often)
   compete.
6. **Choice** (``choose_by``, ``edge_clearance_m``): ``cost``: the smallest cost of 4 wins;
   ``edge_clearance``: the path whose fingers keep the most room from the object beside their side and
   tip faces wins (:func:`graspexp.planning.stability.pad_edge_excess_m`: how far the object reaches past
   either pad's contact plane within ``edge_clearance_m`` of them, counted from 0 so every path clear of
   it ties), ties to the smallest cost of 4. The paper's cost ranks the paths the shortlist is drawn from;
   within it, the grasp whose pads, not their edges, meet the object.

7. **Area fallback** (``fallback_contacts_in_area``, ``fallback_modes``): in the modes listed, when no
   path passes 1-3, the search is repeated requiring only the largest in-area share any try reached
   (the grasp touching the area most), if that share is at least ``fallback_contacts_in_area``;
   ``extras["in_area_required"]`` records the share required (``min_contacts_in_area`` when no
   fallback was needed).

Examination stops once ``shortlist`` paths pass 1-3. ``Grasp.n_feasible`` counts them; ``extras`` holds
``K``, ``M``, ``n_examined``, the rejections (``n_too_wide``, ``n_below_support``, ``n_collides``,
``n_weak_contact``, ``n_outside_area``), ``in_area_required``, ``pad_depth_m``, ``gravity_arm_m``,
``depth_offset_m``, ``noise_pass``, ``com_factor`` and ``edge_excess_m``. ``details`` is an
:class:`graspexp.planning.details.OptimalPlusDetails`: the paper's intermediates (``costs`` are the paper's,
inf where removed by the plane test), ``com`` and the ``shortlist`` of the S passing paths
(:mod:`graspexp.run.bench.shortlist` simulates each of them).
"""

import dataclasses
from dataclasses import dataclass

import numpy as np

from graspexp.core.geometry import transform_points
from graspexp.core.seeding import rng_for
from graspexp.grippers import GripperGeometry
from graspexp.planning.area_rule import area_test, fallback_share, no_grasp_in_area
from graspexp.planning.collision import cloud_hits, neighbour_hits, place_for_request
from graspexp.planning.details import Candidate, OptimalPlusDetails, Shortlist
from graspexp.planning.friction import cone_cosine
from graspexp.planning.grasp import Grasp, NoFeasibleGrasp
from graspexp.planning.optimal import Candidates, among_neighbours, paper_details, target_candidates
from graspexp.planning.pose import grasp_rotations, opening_widths_m
from graspexp.planning.request import PlanRequest, PlanResult
from graspexp.planning.stability import (
    gravity_arm_m,
    pad_contacts,
    pad_edge_excess_m,
    pose_perturbations,
    volume_centroid_m,
)

NAME = "optimal_plus"

PATH_BATCH = 16
"""Paths examined together, in ascending paper cost: the search stops after the batch in which
``shortlist`` paths have passed."""
MAX_CHUNK = 256
"""Most paths whose tries are evaluated in one array pass (:class:`_Tries`), a multiple of
:data:`PATH_BATCH`. The chunks double up to it, so at most half of a search's placements are ahead of its
end; a search of every path (a clutter round's target that no path clears of its neighbours) makes
7 passes over about 750 paths, where chunks of 64 made 14, each with a fixed cost of numpy calls."""


def _check_params(pl) -> None:
    if pl.com_weight < 0:
        raise ValueError(f"planner.com_weight={pl.com_weight!r} is invalid: expected a non-negative number")
    for key, example in (("depth_offsets_m", "[0.0]"), ("rolls_deg", "[0.0]")):
        if not getattr(pl, key):
            raise ValueError(f"planner.{key} is empty: give at least one value, e.g. {example}")


def plan_optimal_plus(req: PlanRequest) -> PlanResult:
    """Plan one grasp with the paper's candidates and the checks of the module doc. In a clutter round, when
    no grasp clears the neighbours and ``planner.neighbour_fallback`` is on, the grasp planned for the target
    alone (touching a neighbour is allowed; :attr:`Grasp.touches_neighbours`). Both searches read one
    :class:`_TryTable`: a try is placed and tested once.

    Raises
    ------
    NoFeasibleGrasp
        Empty grasping area; every path crosses the support plane; or no path passes checks 1-3.
    """
    pl, gr = req.planner, req.gripper
    _check_params(pl)
    geometry = GripperGeometry.of(gr)
    length = geometry.finger_width_m if pl.cluster_length == "finger_width" else None
    alone = target_candidates(req, NAME, cluster_length_m=length)
    if pl.opening == "cluster":  # (K,) smallest openings, m: the paper's 2 r_k rule
        floors = opening_widths_m(alone.clusters.radii_m, pl.width_margin, gr)
    else:
        floors = np.zeros(len(alone.clusters.radii_m))
    table = _TryTable(req, alone, geometry, floors)
    com = volume_centroid_m(alone.points)
    if not req.neighbours:
        return _plan(req, alone, table, com)
    try:
        result = _plan(req, among_neighbours(req, alone, NAME), table, com)
    except NoFeasibleGrasp:
        if not pl.neighbour_fallback:
            raise
        result = _plan(dataclasses.replace(req, neighbours=()), alone, table, com)
        return dataclasses.replace(result, grasp=dataclasses.replace(result.grasp, touches_neighbours=True))
    return result


def _plan(req: PlanRequest, cand: Candidates, table: "_TryTable", com: np.ndarray) -> PlanResult:
    """:func:`plan_optimal_plus` over the paths of ``cand``, with the request's neighbours as obstacles (none:
    one object); ``com`` (3,) the cloud's centre of mass, world m."""
    pl, gr, geometry = req.planner, req.gripper, table.geometry
    points = cand.points
    k, m = cand.costs.shape
    size = max(float(np.linalg.norm(points.max(axis=0) - points.min(axis=0))), 1e-9)
    tries = _Tries(table, cand, bool(req.neighbours))
    passed, rejected, examined, best_share = _search_paths(pl, tries, pl.min_contacts_in_area)
    in_area_required = pl.min_contacts_in_area
    if not passed and (share := fallback_share(req, best_share)) is not None:  # step 6 of the module doc
        in_area_required = share
        passed = _search_paths(pl, tries, share)[0]
    if not passed:
        raise NoFeasibleGrasp(
            f"optimal_plus: all {examined} paths above the support failed at every depth: "
            f"{rejected['n_too_wide']} tries too wide for the stroke {gr.max_width_m} m, "
            f"{rejected['n_below_support']} below the support, {rejected['n_collides']} colliding with the "
            f"cloud, {rejected['n_weak_contact']} with a pad contact shallower than {pl.min_pad_depth_m} m "
            f"or outside the friction cone, {rejected['n_outside_area']} with "
            + no_grasp_in_area(req, best_share)
        )
    passed = passed[: pl.shortlist]
    poses = np.stack([c.pose for c in passed])
    widths = np.array([c.width_m for c in passed])
    arms = gravity_arm_m(poses, com)
    factors = 1.0 + pl.com_weight * arms / size
    costs = np.array([cand.costs[c.cluster, c.path] for c in passed]) * factors
    noise_pass = _noise_pass(req, points, poses, widths, geometry, in_area_required)
    robust = noise_pass >= min(pl.noise_min_pass, noise_pass.max())
    excess = pad_edge_excess_m(points, poses, geometry, pl.edge_clearance_m)
    j = pick_shortlisted(pl.choose_by, costs, robust, excess)
    chosen = passed[j]
    kb, pb, pose, width = chosen.cluster, chosen.path, chosen.pose, chosen.width_m
    grasp = Grasp(
        pose=pose,
        width_m=width,
        cost=float(costs[j]),
        cluster=kb,
        path=pb,
        n_feasible=len(passed),
        planner=NAME,
        extras={
            "K": k,
            "M": m,
            "n_examined": examined,
            **rejected,
            "in_area_required": float(in_area_required),
            "pad_depth_m": chosen.pad_depth_m,
            "depth_offset_m": chosen.depth_offset_m,
            "roll_deg": chosen.roll_deg,
            "gravity_arm_m": float(arms[j]),
            "com_factor": float(factors[j]),
            "noise_pass": float(noise_pass[j]),
            "edge_excess_m": float(excess[j]),
        },
    )
    details = OptimalPlusDetails(
        **paper_details(req, cand, (kb, pb), pose, width),
        com=com,
        shortlist=Shortlist(
            poses=poses,
            widths=widths,
            costs=costs,
            robust=robust,
            edge_excess_m=excess,
            pad_depth_m=np.array([c.pad_depth_m for c in passed]),
        ),
    )
    return PlanResult(grasp=grasp, details=details)


def pick_shortlisted(choose_by: str, costs: np.ndarray, robust: np.ndarray, excess_m: np.ndarray) -> int:
    """Step 6 of the module doc: the index of the grasp among (S,) shortlisted paths with costs ``costs``
    (step 4), noise-robust flags ``robust`` (step 5, at least one set) and edge excesses ``excess_m``, m."""
    if choose_by == "edge_clearance":
        room = np.where(robust, np.maximum(excess_m, 0.0), np.inf)
        robust = robust & (room == room.min())
    return int(np.argmin(np.where(robust, costs, np.inf)))


@dataclass(frozen=True)
class _Batch:
    """Steps 1-3 of the module doc, all but the area test, for the tries of P paths (a whole number of
    :data:`PATH_BATCH` es, the last maybe short).

    ks, ps : (P,) cluster and path of each path, paths : (P,) its row in ``poses`` and ``widths_m``, the
    table's (:class:`_TryTable`) placed tries (step 2), (n, R * O, 4, 4) and (n, R * O), roll (R)-major,
    then depth offset (O); too_wide, below_support, collides, placed_ok : (P * R * O,) bool, path-major,
    then roll, then depth offset: each try's first failed check of step 2 and whether it passed
    step 2; held : (P * R * O,) bool, the placed tries passing step 3 but for the area test; depth_m, share
    : (P * R * O,) pad depth, m (-inf where not placed) and in-area share (0 where not placed)."""

    ks: np.ndarray
    ps: np.ndarray
    paths: np.ndarray
    poses: np.ndarray
    widths_m: np.ndarray
    too_wide: np.ndarray
    below_support: np.ndarray
    collides: np.ndarray
    placed_ok: np.ndarray
    held: np.ndarray
    depth_m: np.ndarray
    share: np.ndarray


class _TryTable:
    """The tries of every path of a request (module doc, steps 1-3 but the area test; path-major, then roll
    (R), then depth offset (O)), each placed and tested once, when a search first asks for its path: placed
    against the target and the support (:func:`graspexp.planning.collision.place_for_request` without
    neighbours), then, where that clears, against the neighbours (:func:`graspexp.planning.collision.
    neighbour_hits`), and the pads (step 3) where a search needs them. A search among the neighbours and
    one for the target alone (the fallback) read the same tries; every try's result is that of a
    placement of its own, so it does not depend on which paths were placed with it."""

    def __init__(self, req: PlanRequest, cand: Candidates, geometry: GripperGeometry, floors: np.ndarray):
        pl = req.planner
        self.req, self.cand, self.geometry, self.floors = req, cand, geometry, floors
        self.offsets = np.asarray(pl.depth_offsets_m, dtype=np.float64)
        self.rolls = [_roll(np.deg2rad(r)) for r in pl.rolls_deg]
        n, t = cand.costs.size, len(self.rolls) * len(self.offsets)
        self.done = np.zeros(n, dtype=bool)
        self.poses = np.empty((n, t, 4, 4))
        self.widths, self.lift = np.empty((n, t)), np.empty((n, t))
        self.too_wide, self.below, self.check = (np.empty((n, t), dtype=bool) for _ in range(3))
        self.collides, self.neighbour_hit = np.empty((n, t), dtype=bool), np.zeros((n, t), dtype=bool)
        self.hit_done, self.padded = np.zeros((n, t), dtype=bool), np.zeros((n, t), dtype=bool)
        self.held, self.depth, self.share = np.zeros((n, t), dtype=bool), np.empty((n, t)), np.empty((n, t))

    def place(self, paths: np.ndarray) -> None:
        """Place the tries of the paths ``paths`` (flat indices into the (K, M) costs) not placed yet, against
        the target and the support."""
        new = paths[~self.done[paths]]
        if not len(new):
            return
        req, cand, offsets = self.req, self.cand, self.offsets
        n_roll, n_off = len(self.rolls), len(offsets)
        ks, ps = np.unravel_index(new, cand.costs.shape)
        b, centers = len(ks), cand.clusters.centers_m
        rots = grasp_rotations(cand.directions[ks, ps], cand.pose_axis)  # (B, 3, 3)
        poses = np.tile(np.eye(4), (b, n_roll, n_off, 1, 1))
        for r, roll in enumerate(self.rolls):
            poses[:, r, :, :3, :3] = (rots @ roll)[:, None]
        poses[..., :3, 3] = (
            centers[ks][:, None, None] + offsets[None, None, :, None] * rots[:, None, None, :, 2]
        )
        placed = place_for_request(
            req, poses.reshape(-1, 4, 4), np.repeat(self.floors[ks], n_roll * n_off), neighbours=False
        )
        shape = (b, n_roll * n_off)
        self.poses[new] = placed.poses.reshape(*shape, 4, 4)
        self.widths[new], self.lift[new] = placed.widths_m.reshape(shape), placed.lift_m.reshape(shape)
        self.too_wide[new], self.below[new] = (
            placed.too_wide.reshape(shape),
            placed.below_support.reshape(shape),
        )
        self.check[new] = (~placed.too_wide & ~placed.below_support).reshape(shape)
        self.collides[new] = placed.collides.reshape(shape)
        self.done[new] = True

    def _ok(self, paths: np.ndarray, neighbours: bool) -> tuple[np.ndarray, np.ndarray]:
        """(P, T) collisions and passing tries of the placed paths ``paths``, among the neighbours or not;
        the neighbours and the pads (step 3) tested here where not yet."""
        req = self.req
        if neighbours:
            todo = self.check[paths] & ~self.collides[paths] & ~self.hit_done[paths]
            if todo.any():
                rows, cols = np.nonzero(todo)
                at = (paths[rows], cols)
                self.neighbour_hit[at] = neighbour_hits(
                    req.neighbour_cells, self.poses[at], req.gripper, self.widths[at],
                    sweep_m=req.planner.sphere_radius_m, margin_m=req.planner.collision_margin_m,
                )  # fmt: skip
                self.hit_done[at] = True
        collides = self.collides[paths] | (self.neighbour_hit[paths] if neighbours else False)
        ok = self.check[paths] & ~collides
        todo = ok & ~self.padded[paths]
        if todo.any():
            rows, cols = np.nonzero(todo)
            at = (paths[rows], cols)
            normals = np.asarray(req.normals, dtype=np.float64)
            self.held[at], self.depth[at], self.share[at] = _pads_hold(
                req.planner, self.geometry, self.cand.points, normals, self.cand.area_mask, self.poses[at]
            )
            self.padded[at] = True
        return collides, ok

    def batch(self, paths: np.ndarray, neighbours: bool) -> _Batch:
        """The tries of the paths ``paths`` as a :class:`_Batch`, among the neighbours (their hits are
        collisions) or not: those not placed yet placed, and those not tested yet tested, in one pass."""
        self.place(paths)
        collides, ok = self._ok(paths, neighbours)
        ks, ps = np.unravel_index(paths, self.cand.costs.shape)
        flat = ok.reshape(-1)
        return _Batch(
            ks=ks,
            ps=ps,
            paths=paths,
            poses=self.poses,
            widths_m=self.widths,
            too_wide=self.too_wide[paths].reshape(-1),
            below_support=self.below[paths].reshape(-1),
            collides=(self.check[paths] & collides).reshape(-1),
            placed_ok=flat,
            held=self.held[paths].reshape(-1) & flat,
            depth_m=np.where(flat, self.depth[paths].reshape(-1), -np.inf),
            share=np.where(flat, self.share[paths].reshape(-1), 0.0),
        )


class _Tries:
    """The tries of the paths of one search (``cand``'s, in ascending cost; module doc, steps 1-3 but the
    area test), read from ``table`` among the neighbours or not (``neighbours``). Paths are placed in chunks
    that grow with the search (:data:`PATH_BATCH` up to :data:`MAX_CHUNK` paths), so a long search makes few
    array passes, and each chunk is read as one :class:`_Batch` of its :data:`PATH_BATCH` es; a fallback
    search (step 7) reads the chunks again."""

    def __init__(self, table: _TryTable, cand: Candidates, neighbours: bool):
        self.table, self.neighbours = table, neighbours
        self.offsets, self.rolls = table.offsets, table.rolls
        self.order = np.argsort(cand.costs, axis=None, kind="stable")[: int(cand.feasible.sum())]
        self.n_batches = -(-len(self.order) // PATH_BATCH)
        self.chunks: dict[int, tuple[int, _Batch]] = {}

    def chunk(self, i: int) -> tuple[int, _Batch]:
        """The chunk of paths starting at the ``i``-th batch of :data:`PATH_BATCH` paths (``i < n_batches``,
        the first batch of a chunk): the batch after its last, and its tries."""
        if i not in self.chunks:
            start = i * PATH_BATCH
            size = min(max(start, PATH_BATCH), MAX_CHUNK)
            paths = self.order[start : start + size]
            self.chunks[i] = (
                min(i + size // PATH_BATCH, self.n_batches),
                self.table.batch(paths, self.neighbours),
            )
        return self.chunks[i]


def _search_paths(pl, tries: _Tries, min_share: float) -> tuple[list[Candidate], dict[str, int], int, float]:
    """Steps 1-3 of the module doc over the paper's paths in ascending cost, in batches of
    :data:`PATH_BATCH`, requiring ``min_share`` of each pad's contact in the area: the passing paths
    (:class:`~graspexp.planning.details.Candidate`, up to ``shortlist``), the rejection counts, the
    number of paths examined and the largest in-area share among the tries that pass everything but the
    area test (0 if none). The batches of a chunk (:meth:`_Tries.chunk`) are tested together and counted
    up to the first batch by which ``shortlist`` paths have passed: as if taken one batch at a time."""
    offsets = tries.offsets
    n_roll, n_off = len(tries.rolls), len(offsets)
    per_path = n_roll * n_off
    by_offset = np.argsort(np.abs(offsets), kind="stable")  # tie-break: the smallest move
    rejected = dict.fromkeys(
        ("n_too_wide", "n_below_support", "n_collides", "n_weak_contact", "n_outside_area"), 0
    )
    passed: list[Candidate] = []
    examined, best_share = 0, 0.0
    n = 0
    while n < tries.n_batches and len(passed) < pl.shortlist:
        n, batch = tries.chunk(n)
        ok = area_test(batch.held, batch.share, min_share)[0]
        passes = ok.reshape(-1, per_path).any(axis=1)  # (P,)
        # the batch by which shortlist paths have passed ends the search: count up to its end
        reached = np.flatnonzero(len(passed) + np.cumsum(passes) >= pl.shortlist)
        b = (
            len(passes)
            if not len(reached)
            else min(len(passes), (int(reached[0]) // PATH_BATCH + 1) * PATH_BATCH)
        )
        t = b * per_path
        examined += b
        _, n_outside, chunk_best = area_test(batch.held[:t], batch.share[:t], min_share)
        for key, flags in (
            ("n_too_wide", batch.too_wide),
            ("n_below_support", batch.below_support),
            ("n_collides", batch.collides),
            ("n_weak_contact", batch.placed_ok & ~batch.held),
        ):
            rejected[key] += int(flags[:t].sum())
        rejected["n_outside_area"] += n_outside
        best_share = max(best_share, chunk_best)
        ok, depth = ok[:t].reshape(b, n_roll, n_off), batch.depth_m[:t].reshape(b, n_roll, n_off)
        # per path: the first roll with a passing try, then the target depth with the smallest move
        for i in np.flatnonzero(passes[:b])[: pl.shortlist - len(passed)]:
            r = int(np.argmax(ok[i].any(axis=1)))
            score = np.where(ok[i, r], np.minimum(depth[i, r], pl.pad_depth_target_m), -np.inf)
            j = int(by_offset[int(np.argmax(score[by_offset]))])
            at = (batch.paths[i], r * n_off + j)
            passed.append(
                Candidate(
                    cluster=int(batch.ks[i]),
                    path=int(batch.ps[i]),
                    pose=batch.poses[at].copy(),
                    width_m=float(batch.widths_m[at]),
                    pad_depth_m=float(depth[i, r, j]),
                    depth_offset_m=float(offsets[j]),
                    roll_deg=float(pl.rolls_deg[r]),
                )
            )
        if b < len(passes):
            break
    return passed, rejected, examined, best_share


def _pads_hold(
    pl,
    geometry: GripperGeometry,
    points: np.ndarray,
    normals: np.ndarray,
    area_mask: np.ndarray,
    poses: np.ndarray,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Step 3 of the module doc for (B, 4, 4) poses: (B,) whether both pads' contacts are at least
    ``min_pad_depth_m`` deep and inside the friction cone of ``friction_coef``, (B,) the depth, m, and
    (B,) the smaller of the two pads' shares of contact points in the grasping area."""
    depth, angle, share = pad_contacts(points, normals, poses, geometry, pl.contact_band_m, area_mask)
    ok = (depth >= pl.min_pad_depth_m) & (np.cos(angle) >= cone_cosine(pl.friction_coef))
    return ok, depth, share


def _roll(angle_rad: float) -> np.ndarray:
    """(3, 3) rotation of a grasp frame about its own approach axis +Z by ``angle_rad``. Written out, not
    :func:`graspexp.core.geometry.yaw_rotation`: its Rodrigues form leaves cos(90 deg) = 0 where this keeps
    6e-17, and the benchmark's grasps were planned with this one."""
    c, s = np.cos(angle_rad), np.sin(angle_rad)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _noise_pass(
    req: PlanRequest,
    points: np.ndarray,
    poses: np.ndarray,
    widths: np.ndarray,
    geometry: GripperGeometry,
    min_share: float,
) -> np.ndarray:
    """(B,) share of the pose-noise draws (module doc, step 5) under which each grasp still passes, with
    ``min_share`` of each pad's contact in the area."""
    pl = req.planner
    if pl.noise_samples == 0 or (pl.noise_trans_mm == 0 and pl.noise_rot_deg == 0):
        return np.ones(len(poses))
    motions = pose_perturbations(
        rng_for(req.seed, "optimal_plus_noise"),
        pl.noise_samples,
        pl.noise_trans_mm,
        pl.noise_rot_deg,
        np.asarray(req.object_pose)[:3, 3],
    )
    normals = np.asarray(req.normals, dtype=np.float64)
    ok = np.zeros(len(poses))
    for motion in motions:
        moved = transform_points(motion, points)
        free = (
            cloud_hits(moved, poses, req.gripper, widths, sweep_m=pl.sphere_radius_m, margin_m=0.0, stop_at=1)
            == 0
        )
        held, _, share = _pads_hold(pl, geometry, moved, normals @ motion[:3, :3].T, req.area_mask, poses)
        ok += free & held & (share >= min_share)
    return ok / len(motions)
