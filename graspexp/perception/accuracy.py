"""Registration accuracy and cost, measured: one object at seeded poses on the support, seen by the
camera, its pose registered from a prior (or globally), the error and the time of each step recorded.
``python -m graspexp bench.registration`` prints it per object."""

import time
from dataclasses import dataclass

import numpy as np

from graspexp.config.perception import PerceptionConfig
from graspexp.core.geometry import make_pose, pose_error, random_rotation
from graspexp.core.seeding import rng_for
from graspexp.datasets.model import ObjectModel
from graspexp.perception.camera import BoxBody, MeshBody
from graspexp.perception.observe import estimate_pose, observe
from graspexp.perception.registration import pose_errors

SUPPORT_HALF_M = 0.15
"""Half size of the support box the bench places the object on (the collab box), m."""


@dataclass(frozen=True)
class Attempt:
    """One registration: its errors (mm, deg, ADD-S mm), fitness, and per step the CPU time of this process
    (all threads) and the wall time, s: ``depth`` (render, noise, cloud, the target's normals),
    ``registration``."""

    trans_mm: float
    rot_deg: float
    adds_mm: float
    fitness: float
    depth_cpu_s: float
    depth_wall_s: float
    registration_cpu_s: float
    registration_wall_s: float


def resting_pose(model: ObjectModel, table_z: float, rng: np.random.Generator) -> np.ndarray:
    """(4, 4) a uniformly random orientation, centred over the support, lowest point on its top (not a
    settled pose: enough to measure registration, which physics does not change)."""
    R = random_rotation(rng)
    v = model.mesh.vertices @ R.T
    lo, hi = v.min(axis=0), v.max(axis=0)
    return make_pose(R, np.array([-(lo[0] + hi[0]) / 2, -(lo[1] + hi[1]) / 2, table_z - lo[2]]))


def registration_attempts(
    cfg: PerceptionConfig,
    model: ObjectModel,
    n: int,
    seed: int,
    *,
    prior_mm: float,
    prior_deg: float,
    table_z: float = 0.1,
) -> list[Attempt]:
    """``n`` registrations of ``model`` at seeded poses, each from a prior ``prior_mm`` / ``prior_deg``
    (Gaussian std, as ``perception.noise``) off the truth, or globally with
    ``cfg.registration.prior == "none"``. A first, untimed frame builds the mesh's ray-casting index (once
    per object in a run, as in trials)."""
    support = BoxBody(
        np.array([-SUPPORT_HALF_M, -SUPPORT_HALF_M, 0.0]), np.array([SUPPORT_HALF_M, SUPPORT_HALF_M, table_z])
    )
    warm = resting_pose(model, table_z, rng_for(seed, model.name, "warm-up"))
    observe(cfg, [MeshBody(model.mesh, warm, 1)], [support], table_z, 1, rng=rng_for(seed, "warm-up"))  # BVH
    out = []
    for i in range(n):
        truth = resting_pose(model, table_z, rng_for(seed, model.name, i, "pose"))
        c0, w0 = time.process_time(), time.perf_counter()
        obs = observe(
            cfg,
            [MeshBody(model.mesh, truth, 1)],
            [support],
            table_z,
            1,
            rng=rng_for(seed, model.name, i, "camera"),
        )
        obs.target()  # the normals registration reads (estimated once, kept by the observation)
        c1, w1 = time.process_time(), time.perf_counter()
        prior = None
        if cfg.registration.prior != "none":
            dR, dt = pose_error(rng_for(seed, model.name, i, "prior"), prior_mm, prior_deg)
            prior = make_pose(dR @ truth[:3, :3], truth[:3, 3] + dt)
        reg = estimate_pose(
            cfg, obs, model.points, model.normals, prior, rng=rng_for(seed, model.name, i, "reg")
        )
        e = pose_errors(reg.pose, truth, model.points)
        out.append(
            Attempt(
                e["trans_mm"],
                e["rot_deg"],
                e["adds_mm"],
                reg.fitness,
                c1 - c0,
                w1 - w0,
                reg.cpu_s,
                reg.wall_s,
            )
        )
    return out
