"""The physics of a clutter round: :class:`RoundSim` steps a scene of several objects (the trial protocol's
:class:`graspexp.sim.trial.TrialSim` on the current target) and :func:`settle_all` lets them come to rest."""

import numpy as np

from graspexp.config import JobConfig
from graspexp.core.phases import Phase
from graspexp.sim.contacts import gripper_touches
from graspexp.sim.round_scene import ClutterScene
from graspexp.sim.trial import LogSink, TrialSim


class RoundSim(TrialSim):
    """:class:`TrialSim` over several objects: logs every object's pose, checks the target's speed, and at every
    log tick (whether or not recorded) notes which neighbours the gripper touches."""

    def __init__(self, ts: ClutterScene, cfg: JobConfig, recorder: LogSink, timings: dict[str, float]):
        super().__init__(ts, cfg, recorder, timings)
        self.touched: set[str] = set()

    def track(self, name: str) -> None:
        """Make body ``name`` the target: the speed check and the finger forces follow it."""
        self.ts.target(name)
        body = self.ts.object_body
        self._velocities = (body.get_linear_velocity, body.get_angular_velocity)
        self._last_velocities = None

    def frames(self) -> dict[str, tuple[np.ndarray, np.ndarray]]:
        out = {}
        for name, (entity, _) in self.ts.bodies.items():
            p = entity.pose
            out[name] = (p.p, p.q)
        if self.gripper is not None:
            for link in (self.gripper.palm, *self.gripper.fingers):
                lp = link.entity_pose
                out[link.name] = (lp.p, lp.q)
        return out

    def steps_n(self, n: int, moves: list | None = None) -> None:
        done = 0
        while done < n:
            k = min(self.log_every, n - done)
            super().steps_n(k, None if moves is None else moves[done : done + k])
            done += k
            if self.gripper is not None:
                self.touched |= gripper_touches(self._contacts(), self.ts.object_entity.name)

    def release_gripper(self) -> None:
        """Take the gripper out of the scene after an attempt."""
        if self.gripper is not None:
            for link in self.gripper.articulation.links:
                self.ts.scene.remove_entity(link.entity)
        self.gripper, self._links, self.touch = None, None, None


def fastest_body(sim: RoundSim, names: list[str]) -> tuple[str, float, float]:
    """Of the bodies ``names``, the one moving fastest now (by linear speed, then angular): (name, speed m/s,
    angular speed rad/s)."""
    best = ("", -1.0, -1.0)
    for name in names:
        body = sim.ts.bodies[name][1]
        v, w = np.asarray(body.get_linear_velocity(), float), np.asarray(body.get_angular_velocity(), float)
        speed = (float(np.linalg.norm(v)), float(np.linalg.norm(w)))
        if speed > best[1:]:
            best = (name, *speed)
    return best


def settle_all(sim: RoundSim) -> list[str]:
    """Step until every object rests (both settle speeds for ``sim.settle_hold_s``, after
    ``sim.settle_min_s``) or ``sim.settle_max_s`` runs out; the bodies that had not rested for
    ``sim.settle_hold_s`` when it ran out ([]: all came to rest). The heap rests once its least still body
    has rested long enough: each body's count of still steps is kept only to name the moving ones."""
    cfg = sim.cfg.sim
    bodies = [(name, b) for name, (_, b) in sim.ts.bodies.items()]
    if not bodies:
        return []
    sim.track(next(iter(sim.ts.bodies)))
    linear_sq, angular_sq = cfg.settle_linear_mps**2, cfg.settle_angular_radps**2
    min_steps, hold = int(cfg.settle_min_s / sim.dt), max(1, round(cfg.settle_hold_s / sim.dt))
    still = [0] * len(bodies)  # consecutive steps each body spent below both speeds
    with sim.timed("settle"):
        for i in range(int(cfg.settle_max_s / sim.dt)):
            sim.step()
            for k, (_, body) in enumerate(bodies):
                v, w = body.get_linear_velocity(), body.get_angular_velocity()
                still[k] = 0 if v.dot(v) >= linear_sq or w.dot(w) >= angular_sq else still[k] + 1
            if i + 1 >= min_steps and min(still) >= hold:
                return []
    moving = [name for (name, _), n in zip(bodies, still, strict=True) if n < hold]
    sim.phase(Phase.SETTLE_TIMEOUT, {"cap_s": cfg.settle_max_s, "moving": moving})
    return moving
