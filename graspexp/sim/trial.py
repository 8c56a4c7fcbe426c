"""The trial protocol (paper IV-A, IV-C, IV-D): drop, settle, plan, approach, close, then
remove the box and hold (collab) or pull back and lift (bin). Staged checks stop at the first failure.

The trial knows nothing of how a grasp is planned or scored: the caller passes the planner and the quality
check (:class:`TrialContext` ``plan`` and ``quality``), and the log it writes to (:class:`LogSink`).
"""

import dataclasses
import time
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import Any, Protocol

import numpy as np
import sapien
import trimesh
from omegaconf import DictConfig, OmegaConf

from graspexp.config import JobConfig
from graspexp.core.bodies import FINGER_NAMES, SUPPORT_NAME
from graspexp.core.geometry import (
    make_pose,
    matrix_to_quat_wxyz,
    random_rotation,
    transform_points,
    yaw_rotation,
)
from graspexp.core.outcome import FailureReason, TrialResult
from graspexp.core.phases import Phase
from graspexp.core.seeding import plan_seed, rng_for
from graspexp.datasets.model import ObjectModel
from graspexp.perception import Observation
from graspexp.perception.scene_view import Perceived, perceive
from graspexp.planning.grasp import Grasp, NoFeasibleGrasp
from graspexp.planning.request import PlanRequest, PlanResult
from graspexp.sim.contacts import SupportTouch, contact_records, finger_forces
from graspexp.sim.gripper import Gripper, build_gripper
from graspexp.sim.scene import TrialScene, build_scene


class TrialFailed(Exception):
    """Raised inside a trial at the first failed check; carries the reason."""

    def __init__(self, reason: FailureReason, detail: str = ""):
        super().__init__(f"{reason.value}: {detail}" if detail else reason.value)
        self.reason = reason
        self.detail = detail


class LogSink(Protocol):
    """What a trial writes to its log (:class:`graspexp.record.TrialWriter` is one); times ``t_s`` are sim
    time, s. ``active`` False: the trial skips gathering the per-step messages (transforms, contacts)."""

    active: bool

    def scene(self, t_s: float, entities: Sequence[Any]) -> None: ...
    def delete_entities(self, t_s: float, ids: Sequence[str]) -> None: ...
    def transforms(
        self, t_s: float, frames: Mapping[str, tuple[Sequence[float], Sequence[float]]]
    ) -> None: ...
    def contacts(self, t_s: float, contacts: Sequence[Mapping[str, Any]]) -> None: ...
    def grasp(self, t_s: float, grasp: Mapping[str, Any]) -> None: ...
    def phase(self, t_s: float, name: str, info: Mapping[str, Any] | None = None) -> None: ...
    def result(self, t_s: float, result: Mapping[str, Any]) -> None: ...
    def round_result(self, t_s: float, result: Mapping[str, Any]) -> None: ...
    def perception(
        self, t_s: float, observation: Observation, poses: Mapping[str, np.ndarray], info: Mapping[str, Any]
    ) -> None: ...


class NullRecorder:
    """The :class:`LogSink` of a trial that is not logged: every message is dropped. Subclasses that keep
    some messages set ``active = True``, so the trial gathers them."""

    active = False

    def scene(self, t_s: float, entities: Sequence[Any]) -> None:
        pass

    def delete_entities(self, t_s: float, ids: Sequence[str]) -> None:
        pass

    def transforms(self, t_s: float, frames: Mapping[str, tuple[Sequence[float], Sequence[float]]]) -> None:
        pass

    def contacts(self, t_s: float, contacts: Sequence[Mapping[str, Any]]) -> None:
        pass

    def grasp(self, t_s: float, grasp: Mapping[str, Any]) -> None:
        pass

    def phase(self, t_s: float, name: str, info: Mapping[str, Any] | None = None) -> None:
        pass

    def result(self, t_s: float, result: Mapping[str, Any]) -> None:
        pass

    def round_result(self, t_s: float, result: Mapping[str, Any]) -> None:
        pass

    def perception(
        self, t_s: float, observation: Observation, poses: Mapping[str, np.ndarray], info: Mapping[str, Any]
    ) -> None:
        pass


PlanFn = Callable[[PlanRequest], PlanResult]
"""A planner: the grasp for a request (raises :class:`NoFeasibleGrasp` when there is none)."""
QualityFn = Callable[[trimesh.Trimesh, Grasp], float]
"""Physics-free quality of a grasp on a mesh in the same frame: the smallest force-closure friction
coefficient (inf or NaN when none)."""


@dataclass
class TrialContext:
    """Inputs of one trial. ``trial_seed`` derives every random draw of the trial."""

    cfg: JobConfig
    """The resolved job config as plain dataclasses (``OmegaConf.to_object``): fast attribute access."""
    model: ObjectModel
    hulls: list[np.ndarray]
    trial: int
    trial_seed: int
    recorder: LogSink = field(default_factory=NullRecorder)
    scene: object | None = None
    """The object's Foxglove scene for the log (:func:`graspexp.record.object_scene`, built once per object);
    None: no /scene messages."""
    plan: PlanFn = field(kw_only=True)
    """Plans the grasp (the runner passes :func:`graspexp.planning.plan`)."""
    quality: QualityFn = field(kw_only=True)
    """Scores the planned grasp without physics (the runner passes :func:`graspexp.quality.fc_min_mu`)."""


def plain_config(cfg: DictConfig) -> JobConfig:
    """The composed job config as dataclass instances (attribute access in the step loop must be cheap)."""
    return OmegaConf.to_object(cfg)


def drop_pose(
    model: ObjectModel, rot: str, table_z: float, gap_m: float, rng: np.random.Generator
) -> np.ndarray:
    """(4,4) world pose at release: rotated (about Z for ``z``, uniformly for ``xyz``), centred over the
    support, lowest point ``gap_m`` above the support plane."""
    R = yaw_rotation(rng.uniform(0.0, 2.0 * np.pi)) if rot == "z" else random_rotation(rng)
    v = model.mesh.vertices @ R.T
    lo, hi = v.min(axis=0), v.max(axis=0)
    t = np.array([-(lo[0] + hi[0]) / 2, -(lo[1] + hi[1]) / 2, table_z + gap_m - lo[2]])
    return make_pose(R, t)


F32_DOT_REL_ERROR = 1e-6
"""Bound on the relative difference between numpy's float32 ``v.dot(v)`` of a float32 3-vector (products
and sums rounded to float32, or summed in float64, then rounded) and the float64 sum of squares of the same
components (at most about 4 x 2^-24 = 2.4e-7 for nonnegative terms). A float64 sum below a limit by more than
this is below it in float32 too, so only a speed near a limit needs the float32 products."""


class TrialSim:
    """Steps one trial's scene, keeps sim time, checks stability and table touches, logs at a fixed rate.

    Between log ticks a step does only the physics step, the arm's drive targets computed before the run
    (:meth:`run`), the object's speed check (two velocity reads; numpy's float32 dot products only near a
    limit, see :data:`F32_DOT_REL_ERROR`) and, while :meth:`watch_support` is on, the gripper-support
    contact check.
    """

    def __init__(
        self,
        ts: TrialScene,
        cfg: JobConfig,
        recorder: LogSink,
        timings: dict[str, float],
        log_offset_s: float = 0.0,
    ):
        self.ts, self.cfg, self.rec, self.timings = ts, cfg, recorder, timings
        self.dt = float(cfg.sim.timestep_s)
        self.steps = 0
        self.log_offset_s = log_offset_s
        """Added to the sim time of everything logged: a re-drop's scene starts at t = 0 again, and its log
        continues after the earlier drops' (one clock per log, so a reader's time order is the trial's)."""
        self.log_every = max(1, round(1.0 / (cfg.sim.log_rate_hz * self.dt)))
        self.gripper: Gripper | None = None
        self._links: list | None = None
        self.touch: SupportTouch | None = None
        self.touched_support = False
        self.max_speed_sq = float(cfg.sim.max_speed_mps) ** 2
        self.max_angular_speed_sq = float(cfg.sim.max_angular_speed_radps) ** 2
        self.recording = recorder.active
        self._next_log = self.log_every if self.recording else -1
        self._physx_step = ts.scene.physx_system.step
        self._contacts = ts.scene.physx_system.get_contacts
        body = ts.object_body  # None in a clutter scene before its first object (clutter.RoundSim.track)
        self._velocities = None if body is None else (body.get_linear_velocity, body.get_angular_velocity)
        self._last_velocities: tuple[np.ndarray, np.ndarray] | None = None
        self._surely_v = self.max_speed_sq * (1.0 - F32_DOT_REL_ERROR)
        self._surely_w = self.max_angular_speed_sq * (1.0 - F32_DOT_REL_ERROR)

    def watch_support(self, gripper: Gripper) -> None:
        """From now on a gripper link touching the support fails the trial (COLLISION_SUPPORT)."""
        support = self.ts.support.find_component_by_type(sapien.physx.PhysxRigidStaticComponent)
        self.touch = SupportTouch(support, [gripper.palm, *gripper.fingers])

    @property
    def speed_sq(self) -> tuple[float, float]:
        """The object's squared linear (m^2/s^2) and angular (rad^2/s^2) speed after the last step (float32
        dot products of the velocities PhysX reports); (0, 0) before the first step."""
        if self._last_velocities is None:
            return 0.0, 0.0
        v, w = self._last_velocities
        return v.dot(v), w.dot(w)

    @property
    def t(self) -> float:
        """Sim time of the scene, s (steps x dt)."""
        return self.steps * self.dt

    def run(self, seconds: float, arm: Callable[[np.ndarray], np.ndarray] | None = None) -> None:
        """Step for ``seconds`` of sim time. ``arm``: step fractions s (n,) = (i + 1) / n -> the gripper's TCP
        offsets (n, 3) in the grasp frame, m; each is driven before its step (all computed before stepping)."""
        n = max(1, int(round(seconds / self.dt)))
        moves = None if arm is None else self.gripper.arm_moves(arm(np.arange(1, n + 1) / n))
        self.steps_n(n, moves)

    def step(self) -> None:
        """One physics step with its checks (:meth:`steps_n`)."""
        self.steps_n(1)

    def steps_n(self, n: int, moves: list | None = None) -> None:
        """Take ``n`` physics steps; ``moves[i]``: the (drive-target setter, value) pairs applied before step i.

        After each step: the object's speed check, the gripper-support check while :meth:`watch_support` is
        on, and a log tick every ``log_every`` steps while recording. The bound methods and limits are locals:
        this is the loop every physics step of a trial goes through."""
        perf, physx_step, contacts, touch = time.perf_counter, self._physx_step, self._contacts, self.touch
        linear, angular = self._velocities
        surely_v, surely_w = self._surely_v, self._surely_w
        physics = 0.0
        try:
            for i in range(n):
                if moves is not None:
                    for set_target, value in moves[i]:
                        set_target(value)
                t0 = perf()
                physx_step()
                physics += perf() - t0
                self.steps += 1
                v, w = self._last_velocities = linear(), angular()
                x, y, z = v.tolist()
                a, b, c = w.tolist()
                if not (x * x + y * y + z * z <= surely_v and a * a + b * b + c * c < surely_w):
                    self._check_speed()  # near a limit, or past it, or NaN: the float32 check decides
                if touch is not None and touch(contacts()):
                    self.touched_support = True
                    if self.recording:
                        self.log()
                    raise TrialFailed(
                        FailureReason.COLLISION_SUPPORT, f"gripper touched the support at t={self.t:.3f} s"
                    )
                if self.steps == self._next_log:
                    self._next_log += self.log_every
                    self.log()
        finally:
            self.timings["physics"] += physics

    def _check_speed(self) -> None:
        """Raise SIM_UNSTABLE when the object moves or spins faster than the limits (NaN fails too)."""
        vv, ww = self.speed_sq
        if not (vv <= self.max_speed_sq and ww < self.max_angular_speed_sq):  # NaN fails every comparison
            raise TrialFailed(
                FailureReason.SIM_UNSTABLE, f"object speed {float(vv) ** 0.5:.3g} m/s at t={self.t:.3f} s"
            )

    def frames(self) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        """World poses (position (3,) m, quaternion wxyz (4,)) of the logged frames."""
        p = self.ts.object_entity.pose
        out = {"object": (p.p, p.q)}
        if self.gripper is not None:
            if self._links is None:
                self._links = [(link.name, link) for link in (self.gripper.palm, *self.gripper.fingers)]
            for name, link in self._links:
                lp = link.entity_pose
                out[name] = (lp.p, lp.q)
        return out

    @property
    def log_t(self) -> float:
        """The log's time of now, s (:attr:`log_offset_s` + sim time)."""
        return self.log_offset_s + self.t

    def log(self) -> None:
        t0 = time.perf_counter()
        self.rec.transforms(self.log_t, self.frames())
        self.rec.contacts(self.log_t, contact_records(self._contacts(), self.dt))
        self.timings["log"] += time.perf_counter() - t0

    @contextmanager
    def timed(self, name: str) -> Iterator[None]:
        """Add the wall time of the block to ``timings[name]``, less the time spent logging in it."""
        t0, log0 = time.perf_counter(), self.timings["log"]
        try:
            yield
        finally:
            self.timings[name] += time.perf_counter() - t0 - (self.timings["log"] - log0)

    def phase(self, phase: Phase, info: dict | None = None) -> None:
        """Log the start of ``phase`` (with ``info``) at the current sim time."""
        t0 = time.perf_counter()
        self.rec.phase(self.log_t, phase.value, info or {})
        self.timings["log"] += time.perf_counter() - t0


def _settle(sim: TrialSim) -> tuple[bool, bool]:
    """Step until the object rests (below both settle speeds for ``settle_hold_s``), falls below the
    support, or the time cap ``settle_max_s``; (on the support, at rest: False when the cap ran out first)."""
    cfg = sim.cfg.sim
    body = sim.ts.object_body
    min_steps = int(cfg.settle_min_s / sim.dt)
    below_z = sim.ts.table_z - cfg.fell_below_m
    linear_sq, angular_sq = cfg.settle_linear_mps**2, cfg.settle_angular_radps**2
    hold_steps = max(1, round(cfg.settle_hold_s / sim.dt))
    still = 0  # consecutive steps below both speeds
    for _ in range(int(cfg.settle_max_s / sim.dt)):
        sim.step()
        if body.get_entity_pose().p[2] < below_z:
            return False, False
        vv, ww = sim.speed_sq
        still = still + 1 if vv < linear_sq and ww < angular_sq else 0
        if sim.steps >= min_steps and still >= hold_steps:
            return _on_support(sim.ts, sim.cfg), True
    return _on_support(sim.ts, sim.cfg), False


def _on_support(ts: TrialScene, cfg: JobConfig) -> bool:
    """The object's lowest point is at the support top and its centre of mass is over the support."""
    lo = ts.object_body.compute_global_aabb_tight()[0]
    com = (ts.object_entity.pose * ts.object_body.cmass_local_pose).p
    hx, hy = cfg.mode.support_half_size_m
    tolerance = cfg.sim.on_support_tolerance_m
    return bool(lo[2] > ts.table_z - tolerance and abs(com[0]) <= hx and abs(com[1]) <= hy)


def _check_gripper_stable(sim: TrialSim, gripper: Gripper) -> None:
    """Raise SIM_UNSTABLE when a gripper link's pose is not finite or it moves faster than
    ``sim.max_speed_mps``: a failure to hold that the physics, not the grasp, caused (an extreme setting)."""
    for link in (gripper.palm, *gripper.fingers):
        pose, v = link.entity_pose, np.asarray(link.get_linear_velocity(), dtype=float)
        if not (np.all(np.isfinite(pose.p)) and np.all(np.isfinite(pose.q)) and v.dot(v) <= sim.max_speed_sq):
            raise TrialFailed(
                FailureReason.SIM_UNSTABLE,
                f"gripper link {link.name} at {np.round(pose.p, 3).tolist()} m, speed {float(v.dot(v)) ** 0.5:.3g} m/s",
            )


def grasp_record(grasp: Grasp) -> dict:
    return {
        "pose": grasp.pose.tolist(),
        "width_m": grasp.width_m,
        "cost": grasp.cost,
        "cluster": grasp.cluster,
        "path": grasp.path,
        "planner": grasp.planner,
        "n_feasible": grasp.n_feasible,
        "touches_neighbours": grasp.touches_neighbours,
        "approach": grasp.approach.tolist(),
        **{k: v for k, v in grasp.extras.items() if isinstance(v, (int, float, str))},
    }


def run_trial(ctx: TrialContext) -> TrialResult:
    """Run one trial; never raises for a physical failure (the reason is in the result)."""
    cfg = ctx.cfg
    res = TrialResult(
        dataset=cfg.dataset.name,
        object=ctx.model.name,
        mode=cfg.mode.name,
        rot=cfg.rot.name,
        planner=cfg.planner.name,
        trial=ctx.trial,
        seed=ctx.trial_seed,
        success=False,
        reason=None,
    )
    timings = dict.fromkeys(("build", "settle", "plan", "quality", "execute", "log", "physics"), 0.0)
    sim: TrialSim | None = None
    try:
        sim = _drop_until_on_support(ctx, res, timings)
        if not res.at_rest:
            raise TrialFailed(FailureReason.NOT_AT_REST, "still moving when sim.settle_max_s ran out")
        with sim.timed("plan"):
            grasp = _plan(ctx, sim, res)
        res.grasp_cost, res.grasp_width_m, res.n_feasible = grasp.cost, grasp.width_m, grasp.n_feasible
        with sim.timed("quality"):
            res.fc_min_mu = _force_closure_mu(ctx, sim, grasp)
        with sim.timed("execute"):
            execute_grasp(sim, grasp, res, ctx.scene)
        res.success = True
    except TrialFailed as e:
        res.reason, res.detail = e.reason.value, e.detail
        if sim is not None:
            sim.phase(Phase.FAILED, {"reason": e.reason.value, "detail": str(e)})
    if sim is not None:
        res.touched_support = sim.touched_support
        res.sim_time_s, res.steps = sim.t, sim.steps
    res.timings_s = timings
    ctx.recorder.result(sim.log_t if sim else 0.0, res.to_dict())
    return res


def _drop_until_on_support(ctx: TrialContext, res: TrialResult, timings: dict) -> TrialSim:
    cfg = ctx.cfg
    log_offset_s = 0.0
    for attempt in range(cfg.sim.max_redrops + 1):
        rng = rng_for(ctx.trial_seed, "drop", attempt)
        t0 = time.perf_counter()
        pose = drop_pose(ctx.model, cfg.rot.name, cfg.mode.support_height_m, cfg.rot.drop_height_m, rng)
        ts = build_scene(ctx.hulls, ctx.model.mass_kg, pose, cfg.mode, cfg.sim, ctx.model.friction)
        timings["build"] += time.perf_counter() - t0
        sim = TrialSim(ts, cfg, ctx.recorder, timings, log_offset_s)
        if attempt == 0 and ctx.scene is not None:
            ctx.recorder.scene(0.0, ctx.scene.static)
        sim.phase(Phase.DROP, {"attempt": attempt})
        with sim.timed("settle"):
            on_support, at_rest = _settle(sim)
        if on_support:
            res.at_rest = at_rest
            if at_rest:
                sim.phase(Phase.SETTLED, {"redrops": attempt})
            else:  # never planned on a moving object: a failure class of its own
                speed, spin = (float(v) ** 0.5 for v in sim.speed_sq)
                info = {
                    "redrops": attempt,
                    "speed_mps": speed,
                    "angular_radps": spin,
                    "cap_s": cfg.sim.settle_max_s,
                }
                sim.phase(Phase.SETTLE_TIMEOUT, info)
            return sim
        res.redrops = attempt + 1
        log_offset_s = sim.log_t + sim.dt
    raise TrialFailed(FailureReason.FELL_OFF_SUPPORT, f"{cfg.sim.max_redrops + 1} drops fell off the support")


def _plan(ctx: TrialContext, sim: TrialSim, res: TrialResult) -> Grasp:
    cfg = ctx.cfg
    true_pose = sim.ts.object_pose()
    seen = perceive(cfg, ctx.model, true_pose, sim.ts.table_z, ctx.trial_seed)
    if seen.observation is not None:
        _record_perception(ctx, sim, res, seen, true_pose)
    if not seen.ok:  # never planned on the prior or the identity the registration was left at
        raise TrialFailed(FailureReason.REGISTRATION_FAILED, seen.failure)
    req = PlanRequest(
        points=transform_points(seen.pose, ctx.model.points),
        normals=ctx.model.normals @ seen.pose[:3, :3].T,
        area_mask=ctx.model.area_mask,
        object_pose=seen.pose,
        table_z=sim.ts.table_z,
        mode=cfg.mode.name,
        gripper=cfg.gripper,
        planner=cfg.planner,
        cost=cfg.cost,
        seed=plan_seed(ctx.trial_seed),
        support_blocks_gripper=bool(cfg.mode.support_collides_with_gripper),
        observation=seen.observation,
    )
    try:
        grasp = ctx.plan(req).grasp
    except NoFeasibleGrasp as e:
        raise TrialFailed(FailureReason.NO_FEASIBLE_GRASP, str(e)) from None
    sim.phase(Phase.PLAN)
    ctx.recorder.grasp(sim.log_t, grasp_record(grasp))
    return grasp


def _record_perception(
    ctx: TrialContext, sim: TrialSim, res: TrialResult, seen: Perceived, true_pose: np.ndarray
) -> None:
    """The camera's frames, cloud and poses into the log; the pose errors and timings into the result."""
    reg = seen.registration
    if reg is not None:
        if reg.ok:  # a failed registration registered no pose: its errors stay NaN
            res.pose_trans_err_mm = seen.errors["trans_mm"]
            res.pose_rot_err_deg = seen.errors["rot_deg"]
            res.pose_adds_mm = seen.errors["adds_mm"]
        res.registration_fitness = reg.fitness
        res.registration_cpu_s = reg.cpu_s
    if sim.recording:
        poses = {"object_true": true_pose, "object_prior": seen.prior}
        if reg is not None:
            poses["object_estimated"] = reg.pose
        info = {"source": ctx.cfg.perception.source, **seen.errors}
        if reg is not None:
            info.update(method=reg.method, fitness=reg.fitness, rmse_m=reg.rmse_m, estimated_pose=reg.pose)
        frames = {v.name: v.world_from_camera for v in seen.observation.views} | poses
        sim.rec.transforms(
            sim.log_t, {k: (T[:3, 3], matrix_to_quat_wxyz(T[:3, :3])) for k, T in frames.items()}
        )
        ctx.recorder.perception(sim.log_t, seen.observation, poses, info)


def _force_closure_mu(ctx: TrialContext, sim: TrialSim, grasp: Grasp) -> float:
    """Force-closure friction of the planned grasp on the object's true pose (the grasp is moved into the
    object frame, so the mesh's ray-cast index is built once per object, not per trial); logged on /grasp."""
    T = sim.ts.object_pose()
    in_object = dataclasses.replace(grasp, pose=np.linalg.inv(T) @ grasp.pose)
    mu = ctx.quality(ctx.model.mesh, in_object)
    mu = mu if np.isfinite(mu) else float("nan")
    ctx.recorder.phase(sim.log_t, Phase.QUALITY.value, {"fc_min_mu": mu})
    return mu


def _held(sim: TrialSim, grasp: Grasp) -> dict[str, float]:
    target = sim.ts.object_entity.name
    return finger_forces(sim.ts.scene.get_contacts(), sim.dt, grasp.pose[:3, 1], target)


def _grasp_point_on_object(gripper: Gripper, ts: TrialScene) -> np.ndarray:
    """(3,) the TCP in the object frame, m: it moves only when the fingers slide over the object (a
    swing about the grasp point, which leaves the object held, does not count as slip)."""
    return (np.linalg.inv(ts.object_pose()) @ gripper.tcp_pose())[:3, 3]


def _along_z(z: np.ndarray) -> np.ndarray:
    """(n, 3) TCP offsets (0, 0, z) in the grasp frame from z (n,), m."""
    return np.stack([np.zeros_like(z), np.zeros_like(z), z], axis=1)


def execute_grasp(sim: TrialSim, grasp: Grasp, res: TrialResult, scene: object | None = None) -> None:
    """Execute ``grasp`` on the scene's target (``sim.ts.object_body``) as the mode's protocol does: approach,
    close, (remove the support,) pull back, lift, hold; the slip and finger forces into ``res``. Raises
    :class:`TrialFailed` with the reason when the grasp does not hold. ``scene``: the Foxglove scene whose
    gripper entities the log gains (None: none)."""
    cfg = sim.cfg
    mode, scfg = cfg.mode, cfg.sim
    ts = sim.ts
    gripper = build_gripper(ts.scene, cfg.gripper, grasp.pose, mode.support_collides_with_gripper)
    sim.gripper = gripper
    if scene is not None:
        sim.rec.scene(sim.log_t, scene.gripper)
    if mode.support_collides_with_gripper:
        sim.watch_support(gripper)
    standoff = float(cfg.planner.sphere_radius_m)
    half = grasp.width_m / 2
    gripper.set_state(np.array([0.0, 0.0, -standoff]), half)

    sim.phase(Phase.APPROACH, {"standoff_m": standoff, "width_m": grasp.width_m})
    sim.run(standoff / scfg.approach_speed_mps, lambda s: _along_z(-standoff * (1 - s)))
    if scfg.approach_settle_s > 0:
        sim.phase(Phase.SETTLE_ARM, {"duration_s": scfg.approach_settle_s})
        sim.run(scfg.approach_settle_s)  # the arm reaches the grasp pose before the fingers close
    sim.phase(Phase.CLOSE)
    gripper.close()
    sim.run(scfg.close_s)
    forces = _held(sim, grasp)
    if min(forces.values()) < scfg.min_finger_force_n:
        res.finger_force_n = [forces[n] for n in FINGER_NAMES]
        _check_gripper_stable(sim, gripper)
        raise TrialFailed(FailureReason.NO_CONTACT, f"finger forces after closing {forces} N")

    grip0 = _grasp_point_on_object(gripper, ts)
    if mode.remove_support_after_grasp:
        sim.phase(Phase.REMOVE_SUPPORT)
        ts.remove_support()
        sim.rec.delete_entities(sim.log_t, [SUPPORT_NAME])
    if mode.pull_back_m > 0:
        sim.phase(Phase.PULL_BACK, {"distance_m": mode.pull_back_m})
        sim.run(mode.pull_back_m / scfg.retract_speed_mps, lambda s: _along_z(-mode.pull_back_m * s))
    if mode.lift_m > 0:
        sim.phase(Phase.LIFT, {"distance_m": mode.lift_m})
        start = np.array([0.0, 0.0, -mode.pull_back_m])
        up = grasp.pose[:3, :3].T @ np.array([0.0, 0.0, mode.lift_m])
        sim.run(mode.lift_m / scfg.retract_speed_mps, lambda s: start + s[:, None] * up)
    sim.phase(Phase.HOLD, {"duration_s": mode.hold_s})
    sim.run(mode.hold_s)
    forces = _held(sim, grasp)
    res.finger_force_n = [forces[n] for n in FINGER_NAMES]
    res.slip_m = float(np.linalg.norm(_grasp_point_on_object(gripper, ts) - grip0))
    n_touching = sum(f >= scfg.min_finger_force_n for f in forces.values())
    if n_touching < len(forces):  # paper IV-C: success = the object is still held by the gripper
        _check_gripper_stable(sim, gripper)
        raise TrialFailed(
            FailureReason.DROPPED,
            f"{n_touching} of {len(forces)} fingers press on the object after the hold "
            f"(finger forces {forces} N, slip {res.slip_m:.3f} m)",
        )
    limit = scfg.slip_threshold_m
    if limit is not None and res.slip_m > limit:
        raise TrialFailed(
            FailureReason.SLIPPED, f"slip {res.slip_m:.4f} m > sim.slip_threshold_m = {limit} m"
        )
    sim.phase(Phase.DONE, {"slip_m": res.slip_m})
