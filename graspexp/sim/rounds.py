"""A clutter-removal round (``mode=pile``/``packed``): place, settle, then grasp one object at a time.

The protocol of VGN (Breyer et al., CoRL 2020; ethz-asl/vgn ``experiments/clutter_removal.py``) and GIGA
(Jiang et al., RSS 2021): each round ``mode.objects_per_round`` objects are dropped into a box that is
lifted away (pile) or stood upright side by side (packed); once they rest, objects outside the workspace
are taken away and the rest count as placed. Each attempt plans (every object's model at its perceived
pose; the planner sees the others as obstacles; ``mode.pick_order`` chooses the target), executes the grasp
exactly as a ``bin`` trial does (:func:`graspexp.sim.trial.execute_grasp`: approach, close, pull back, lift,
hold; gripper-table contact fails it; touching a neighbour is allowed and recorded) and scores it. A held
object is taken away; the others stay where the attempt left them and settle. The round ends when no
object is left, the planner finds no grasp, or ``mode.max_consecutive_failures`` attempts in a row fail.

The single-object rules hold for the heap too (:class:`graspexp.core.rounds.RoundEnd`): a round that placed
nothing is ``nothing_placed``, not ``cleared``; a heap still moving when ``sim.settle_max_s`` runs out (after
the placing or after an attempt; an object that left the table is taken away, not waited for) is never
planned on: the round ends ``not_at_rest``, its last row (not executed) naming the object moving fastest.

With ``perception.source=depth``, an object whose registration fails
(:func:`graspexp.perception.registration.failure`) is no target of a planner that plans on poses
(:func:`graspexp.perception.scene_view.plans_on_pose`; one that plans from the camera's cloud plans as
usual): the planner plans for the others, and the object stays on the table, looked at again at the next
attempt. With a prior it stays their obstacle at that prior (the pose estimator's output the registration
started from); without one (``perception.registration.prior=none``) the planner knows nothing of it. When
no object left can be registered, the attempt's row (not executed) records ``registration_failed`` for the
first of them and the round ends ``no_grasp``.
"""

import dataclasses
import time
from dataclasses import dataclass, field

import numpy as np

from graspexp.config import JobConfig
from graspexp.core.bodies import clutter_body
from graspexp.core.geometry import matrix_to_quat_wxyz, transform_points
from graspexp.core.outcome import FailureReason, TrialResult
from graspexp.core.phases import Phase
from graspexp.core.rounds import AttemptResult, RoundEnd, RoundResult
from graspexp.core.seeding import derive_seed, rng_for
from graspexp.perception.scene_view import ScenePerceived, perceive_scene, slot_id
from graspexp.planning.grasp import Grasp
from graspexp.planning.request import Neighbour, PlanRequest
from graspexp.planning.scene import ScenePlanner, SceneRequest, TargetPlan, timed
from graspexp.sim.round_scene import RoundObject, clutter_scene
from graspexp.sim.round_sim import RoundSim, fastest_body, settle_all
from graspexp.sim.scene_types import SceneType, scene_type
from graspexp.sim.trial import LogSink, NullRecorder, QualityFn, TrialFailed, execute_grasp, grasp_record

MOVED_M = 0.01
"""A neighbour whose origin ended farther than this from where it was before an attempt was moved by it, m."""
NO_PLAN = float("nan")
"""The planning times of an attempt row no plan was made for (a moving heap, nothing registered): NaN, left out
of the latency percentiles."""
PLANNING_MODE = "bin"
"""What a planner is told the mode is (:attr:`PlanRequest.mode`): the table under a clutter round is the
bin's, so the paper's Eq. (2)-(3) score the paths."""


@dataclass
class RoundContext:
    """Inputs of one round. ``round_seed`` derives every random draw of the round."""

    cfg: JobConfig
    objects: list[RoundObject]
    """The drawn objects, by slot (body ``object_<slot>``)."""
    round: int
    round_seed: int
    recorder: LogSink = field(default_factory=NullRecorder)
    scene: object | None = None
    """The round's Foxglove scene (:func:`graspexp.record.scene.round_scene`); None: no /scene messages."""
    plan_scene: ScenePlanner = field(kw_only=True)
    """Plans the scene's grasps (the runner passes :func:`graspexp.planning.plan_scene`; a per-object planner
    through :func:`graspexp.planning.scene.per_object`)."""
    quality: QualityFn = field(kw_only=True)


def run_round(ctx: RoundContext) -> RoundResult:
    """Run one round; never raises for a physical failure (each attempt's reason is in its row)."""
    cfg = ctx.cfg
    wall0, cpu0 = time.perf_counter(), time.process_time()
    res = RoundResult(
        dataset=cfg.dataset.name,
        mode=cfg.mode.name,
        planner=cfg.planner.name,
        round=ctx.round,
        seed=ctx.round_seed,
        drawn=[o.model.name for o in ctx.objects],
        placed=[],
        removed=[],
        end=RoundEnd.ERROR.value,
    )
    timings = dict.fromkeys(("build", "settle", "plan", "quality", "execute", "log", "physics"), 0.0)
    kind = scene_type(cfg.mode.scene)
    ts = clutter_scene(cfg.mode, cfg)
    kind.fixtures(ts, cfg)
    sim = RoundSim(ts, cfg, ctx.recorder, timings)
    if ctx.scene is not None:
        ctx.recorder.scene(0.0, ctx.scene.static)
    try:
        moving = _place(ctx, sim, kind)
        res.placed = sorted(ts.bodies)
        if not moving:
            sim.phase(Phase.SETTLED, {"placed": res.placed})
        res.end = (_attempts(ctx, sim, res, moving) if res.placed else RoundEnd.NOTHING_PLACED).value
    except TrialFailed as e:  # the scene itself went unstable while settling
        res.error = str(e)
        sim.phase(Phase.FAILED, {"reason": e.reason.value, "detail": str(e)})
    res.wall_s, res.cpu_s = time.perf_counter() - wall0, time.process_time() - cpu0
    res.sim_time_s = sim.t
    sim.phase(Phase.ROUND_END, {"end": res.end, "removed": res.removed})
    return res


def _place(ctx: RoundContext, sim: RoundSim, kind: SceneType) -> list[str]:
    """Bring the drawn objects onto the table as the scene type does, settle, and take away every object
    outside the workspace or off the table; the objects left that were still moving when ``sim.settle_max_s``
    ran out (:func:`_settle`)."""
    sim.phase(Phase.DROP, {"objects": [o.model.name for o in ctx.objects]})
    kind.place(sim, ctx.objects, rng_for(ctx.round_seed, "place"))
    return _settle(ctx, sim)


def _settle(ctx: RoundContext, sim: RoundSim) -> list[str]:
    """Let the scene come to rest (:func:`graspexp.sim.round_sim.settle_all`), take away every object outside
    the workspace or off the table, and return the bodies left that had not come to rest ([]: the heap the
    planner looks at rests; one that rolled off the table and still moves on the floor is taken away, not
    waited for)."""
    moving = settle_all(sim)
    _take_away_outside(ctx, sim)
    return [b for b in moving if b in sim.ts.bodies]


def _take_away_outside(ctx: RoundContext, sim: RoundSim) -> list[str]:
    """Remove the objects whose centre of mass is outside the workspace or that fell off the table (VGN's
    ``remove_objects_outside_roi``); their names."""
    ts, mode = sim.ts, ctx.cfg.mode
    wx, wy = mode.workspace_half_size_m
    below = ts.table_z - ctx.cfg.sim.fell_below_m
    gone = []
    for name, (entity, body) in list(ts.bodies.items()):
        com = (entity.pose * body.cmass_local_pose).p
        if abs(com[0]) > wx or abs(com[1]) > wy or com[2] < below:
            gone.append(name)
            _remove(ctx, sim, name)
    if gone:
        sim.phase(Phase.TAKEN_AWAY, {"bodies": gone})
    return gone


def _remove(ctx: RoundContext, sim: RoundSim, name: str) -> None:
    sim.ts.remove_body(name)
    if ctx.scene is not None:
        ctx.recorder.delete_entities(sim.log_t, ctx.scene.bodies[name])


def _attempts(ctx: RoundContext, sim: RoundSim, res: RoundResult, moving: list[str]) -> RoundEnd:
    """Grasp until the table is clear, no grasp is found, the failure limit, or a heap still moving before an
    attempt (``moving``: the bodies that were after the placing); each attempt's row into ``res.attempts``."""
    cfg, ts = ctx.cfg, sim.ts
    failures = 0
    attempt = 0
    while ts.bodies:
        if moving:  # never planned on a moving heap (a single-object trial's not_at_rest)
            res.attempts.append(_not_at_rest(ctx, sim, attempt, moving))
            return RoundEnd.NOT_AT_REST
        seed = derive_seed(ctx.round_seed, "attempt", attempt)
        row, grasp = _plan_scene(ctx, sim, attempt, seed)
        if grasp is None:
            res.attempts.append(row)
            return RoundEnd.NO_GRASP
        name = clutter_body(row.slot)
        before = {b: ts.pose_of(b)[:3, 3] for b in ts.bodies if b != name}
        sim.track(name)
        sim.touched, sim.touched_support = set(), False
        t0 = time.perf_counter()
        trial_res = TrialResult(cfg.dataset.name, row.target, cfg.mode.name, cfg.rot.name, cfg.planner.name,
                                ctx.round, seed, False, None)  # fmt: skip
        try:
            with sim.timed("execute"):
                execute_grasp(sim, grasp, trial_res, ctx.scene)
            row.success = True
        except TrialFailed as e:
            row.reason = e.reason.value
            sim.phase(Phase.FAILED, {"reason": e.reason.value, "detail": str(e), "target": name})
        row.slip_m, row.touched_support = trial_res.slip_m, sim.touched_support
        row.touched_neighbours = sorted(sim.touched - {name})
        sim.release_gripper()
        if row.success:
            _remove(ctx, sim, name)
            res.removed.append(name)
        sim.phase(
            Phase.ATTEMPT_END,
            {"attempt": attempt, "target": name, "success": row.success, "reason": row.reason},
        )
        moving = _settle(ctx, sim)
        row.moved_neighbours = sorted(
            b
            for b, p in before.items()
            if b in ts.bodies and np.linalg.norm(ts.pose_of(b)[:3, 3] - p) > MOVED_M
        )
        row.execute_s, row.sim_time_s = time.perf_counter() - t0, sim.t
        res.attempts.append(row)
        failures = 0 if row.success else failures + 1
        attempt += 1
        if failures >= cfg.mode.max_consecutive_failures:
            return RoundEnd.FAILURE_LIMIT
    return RoundEnd.CLEARED


def _not_at_rest(ctx: RoundContext, sim: RoundSim, attempt: int, moving: list[str]) -> AttemptResult:
    """The row of an attempt not made because bodies ``moving`` had not come to rest when ``sim.settle_max_s``
    ran out: not executed, reason ``not_at_rest``, its target the one moving fastest now (logged with its
    speeds)."""
    cfg = ctx.cfg
    name, speed, spin = fastest_body(sim, moving)
    slot = int(name.rsplit("_", 1)[1])
    sim.phase(Phase.FAILED, {"reason": FailureReason.NOT_AT_REST.value, "target": name, "moving": moving,
                             "speed_mps": speed, "angular_radps": spin, "cap_s": cfg.sim.settle_max_s,
                             "detail": "the heap was still moving when sim.settle_max_s ran out"})  # fmt: skip
    return AttemptResult(
        round=ctx.round, attempt=attempt, target=ctx.objects[slot].model.name, slot=slot, executed=False,
        success=False, reason=FailureReason.NOT_AT_REST.value, pick_order=cfg.mode.pick_order,
        n_left=len(sim.ts.bodies), n_planned=0, plan_s=NO_PLAN, plan_cpu_s=NO_PLAN, sim_time_s=sim.t,
    )  # fmt: skip


@dataclass(frozen=True)
class _Seen:
    """One object of the scene as the planner sees it: its slot, perceived (4, 4) world pose and (N, 3) world
    cloud (its model's points at that pose), m."""

    slot: int
    pose: np.ndarray
    points: np.ndarray


def _plan_scene(
    ctx: RoundContext, sim: RoundSim, attempt: int, seed: int
) -> tuple[AttemptResult, Grasp | None]:
    """Plan the next grasp of the scene (``mode.pick_order``); the attempt's row and the grasp (None: none
    found on any object, or none could be registered). Every object is seen at its perceived pose
    (``perception.noise``); with ``perception.source=depth`` only the registered ones are targets (module
    doc)."""
    cfg, ts = ctx.cfg, sim.ts
    slots = {name: int(name.rsplit("_", 1)[1]) for name in ts.bodies}
    view = perceive_scene(
        cfg, {s: (ctx.objects[s].model, ts.pose_of(name)) for name, s in slots.items()}, ts.table_z, seed
    )
    obstacles = {} if cfg.perception.registration.prior == "none" else view.priors
    seen = {
        name: _Seen(slot, pose, transform_points(pose, ctx.objects[slot].model.points))
        for name, slot in slots.items()
        if (pose := view.poses.get(slot, obstacles.get(slot))) is not None
    }
    unregistered = {name: view.failed[slot] for name, slot in slots.items() if slot not in view.poses}
    order = sorted(b for b in seen if b not in unregistered)
    if not order:
        return _none_registered(ctx, sim, attempt, view, unregistered), None
    if cfg.mode.pick_order == "top_most":
        order.sort(key=lambda b: -float(seen[b].points[:, 2].max()))
    half = np.asarray(cfg.mode.workspace_half_size_m, dtype=np.float64)
    workspace_xy = np.stack([-half, half])  # about the support's centre, world x = y = 0
    scene_req = SceneRequest(
        tuple(_request(ctx, ts.table_z, seen, name, seed, view, workspace_xy) for name in order),
        tuple(slot_id(seen[name].slot) for name in order),
        first_found=cfg.mode.pick_order == "top_most",
        observation=view.observation,
    )
    with sim.timed("plan"):
        found, wall, cpu = timed(ctx.plan_scene, scene_req)
    n = len(found.plans)
    first = seen[order[0]].slot
    row = AttemptResult(
        round=ctx.round, attempt=attempt, target=ctx.objects[first].model.name, slot=first, executed=False,
        success=False, reason=FailureReason.NO_FEASIBLE_GRASP.value, pick_order=cfg.mode.pick_order,
        n_left=len(seen), n_planned=n, plan_s=wall, plan_cpu_s=cpu, sim_time_s=sim.t,
    )  # fmt: skip
    _pose_errors(row, view.errors.get(first))
    chosen = min((tp for tp in found.plans if tp.grasp is not None), key=_preference, default=None)
    unseen = {"unregistered": unregistered} if unregistered else {}
    if chosen is None:
        _log_camera(ctx, sim, view, order[0], first)
        sim.phase(Phase.PLAN, {"attempt": attempt, "found": False, "n_planned": n, **unseen})
        return row, None
    name, grasp = order[chosen.index], chosen.grasp
    slot = seen[name].slot
    _log_camera(ctx, sim, view, name, slot)
    row.target, row.slot, row.executed, row.reason = ctx.objects[slot].model.name, slot, True, None
    row.grasp_cost, row.grasp_width_m, row.n_feasible = grasp.cost, grasp.width_m, grasp.n_feasible
    _pose_errors(row, view.errors.get(slot))
    sim.phase(Phase.PLAN, {"attempt": attempt, "target": name, "object": row.target, "n_planned": n,
                           "pick_order": cfg.mode.pick_order, "plan_s": wall, **unseen})  # fmt: skip
    ctx.recorder.grasp(sim.log_t, {**grasp_record(grasp), "target": name})
    return row, grasp


def _none_registered(
    ctx: RoundContext, sim: RoundSim, attempt: int, view: ScenePerceived, unregistered: dict[str, str]
) -> AttemptResult:
    """The row of an attempt whose camera registered no object left (``unregistered``: body -> why): not
    executed, reason ``registration_failed``, its target the first of them (its fitness, no pose error)."""
    cfg = ctx.cfg
    name = sorted(unregistered)[0]
    slot = int(name.rsplit("_", 1)[1])
    row = AttemptResult(
        round=ctx.round, attempt=attempt, target=ctx.objects[slot].model.name, slot=slot, executed=False,
        success=False, reason=FailureReason.REGISTRATION_FAILED.value, pick_order=cfg.mode.pick_order,
        n_left=len(sim.ts.bodies), n_planned=0, plan_s=NO_PLAN, plan_cpu_s=NO_PLAN, sim_time_s=sim.t,
    )  # fmt: skip
    _pose_errors(row, view.errors.get(slot))
    _log_camera(ctx, sim, view, name, slot)
    sim.phase(Phase.PLAN, {"attempt": attempt, "found": False, "n_planned": 0, "unregistered": unregistered})
    sim.phase(Phase.FAILED, {"reason": row.reason, "detail": unregistered[name], "target": name})
    return row


def _preference(tp: TargetPlan) -> tuple[bool, float, int]:
    """The order in which the scene's grasps are preferred: one clear of the neighbours first, then the least
    cost (NaN: last), then the target planned first."""
    cost = tp.grasp.cost if np.isfinite(tp.grasp.cost) else np.inf
    return tp.grasp.touches_neighbours, cost, tp.index


def _request(
    ctx: RoundContext,
    table_z: float,
    seen: dict[str, _Seen],
    name: str,
    seed: int,
    view: ScenePerceived,
    workspace_xy: np.ndarray,
) -> PlanRequest:
    """The plan request for body ``name`` of the scene ``seen`` (body -> what the planner sees of it): the
    others are its neighbours, the camera's observation names it the target."""
    cfg = ctx.cfg
    target = seen[name]
    model = ctx.objects[target.slot].model
    return PlanRequest(
        points=target.points,
        normals=model.normals @ target.pose[:3, :3].T,
        area_mask=model.area_mask,
        object_pose=target.pose,
        table_z=table_z,
        mode=PLANNING_MODE,
        gripper=cfg.gripper,
        planner=cfg.planner,
        cost=cfg.cost,
        seed=derive_seed(seed, "plan", target.slot),
        support_blocks_gripper=bool(cfg.mode.support_collides_with_gripper),
        neighbours=tuple(
            Neighbour(o.slot, ctx.objects[o.slot].model.name, o.points, o.pose)
            for b, o in seen.items()
            if b != name
        ),
        observation=None
        if view.observation is None
        else dataclasses.replace(view.observation, target_id=slot_id(target.slot)),
        workspace_xy=workspace_xy,
    )


def _log_camera(ctx: RoundContext, sim: RoundSim, view: ScenePerceived, name: str, slot: int) -> None:
    """What the camera saw before the attempt, into the round log as a trial logs it: the views' frames
    on /tf, depth and id images, the observed cloud, and on /perception the poses of the attempt's target
    ``name`` (the object of ``slot``; the first planned when none was found): true, prior, registered."""
    obs = view.observation
    if obs is None or not sim.recording:
        return
    poses = {"object_true": sim.ts.pose_of(name), "object_prior": view.priors[slot]}
    info: dict = {"source": ctx.cfg.perception.source}
    if slot in view.errors:
        info.update(view.errors[slot])
    if slot in view.errors and slot in view.poses:
        info["estimated_pose"] = view.poses[slot]
    frames = {v.name: v.world_from_camera for v in obs.views}
    sim.rec.transforms(sim.log_t, {k: (T[:3, 3], matrix_to_quat_wxyz(T[:3, :3])) for k, T in frames.items()})
    ctx.recorder.perception(sim.log_t, dataclasses.replace(obs, target_id=slot_id(slot)), poses, info)


def _pose_errors(row: AttemptResult, errors: dict[str, float] | None) -> None:
    """The target's registered-pose errors into its row (``perception.source=depth``; else left NaN)."""
    if errors is not None:
        row.pose_trans_err_mm, row.pose_rot_err_deg = errors["trans_mm"], errors["rot_deg"]
        row.pose_adds_mm, row.registration_fitness = errors["adds_mm"], errors["fitness"]
