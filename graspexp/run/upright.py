"""One object standing upright on the support, planned once: what ``graspexp.tools.plan``, ``graspexp.tools.figures``
and the planner bench show (no simulation; the object is not dropped).

The pose is the identity rotation translated so that the mesh's lowest point sits on
``z = mode.support_height_m`` (x = y = 0). The plan's seed is the runner's for trial
:data:`UPRIGHT_TRIAL` (:func:`graspexp.core.seeding.plan_seed`). :func:`resting_pose` and
:func:`posed_request` place it turned instead, with another trial's seed (``bench.plan_grasps``).

A job that renders the depth camera (``perception.source=depth``, or a planner that reads it) gets the
camera's observation of the object on the support and, with ``perception.source=depth``, the pose
registered from it, as a trial does (:func:`graspexp.perception.scene_view.perceive`, with that trial's
seed); a registration that fails its checks raises
:class:`~graspexp.perception.scene_view.RegistrationFailed` (nothing is planned on the prior or the identity).
"""

import dataclasses
import time
from dataclasses import dataclass
from typing import Any

import numpy as np
from omegaconf import DictConfig, OmegaConf

from graspexp.core.seeding import plan_seed, trial_seed
from graspexp.datasets import ObjectModel
from graspexp.planning.registry import plan
from graspexp.planning.request import PlanRequest, PlanResult

UPRIGHT_TRIAL = 0
"""The trial index whose planner seed an upright plan uses."""


@dataclass(frozen=True)
class PlannedObject:
    """One object placed upright on the support and its plan."""

    model: ObjectModel
    """Object frame."""
    object_pose: np.ndarray
    """(4,4) world pose of the object frame."""
    request: PlanRequest
    result: PlanResult
    plan_ms: float
    """Wall time of the planner call, ms."""


def upright_pose(model: ObjectModel, support_height_m: float) -> np.ndarray:
    """(4,4) identity rotation, translated so the mesh's lowest point is on ``z = support_height_m`` (m)."""
    pose = np.eye(4)
    pose[2, 3] = support_height_m - float(np.min(model.mesh.vertices[:, 2]))
    return pose


def resting_pose(model: ObjectModel, rotation: np.ndarray, support_height_m: float) -> np.ndarray:
    """(4,4) world pose of ``model`` turned by the (3,3) ``rotation``, its mesh's box centred on x = y = 0
    and its lowest point on ``z = support_height_m`` (m)."""
    v = model.mesh.vertices @ np.asarray(rotation).T
    pose = np.eye(4)
    pose[:3, :3] = rotation
    pose[:2, 3] = -(v[:, :2].min(axis=0) + v[:, :2].max(axis=0)) / 2
    pose[2, 3] = support_height_m - float(np.min(v[:, 2]))
    return pose


def upright_request(cfg: Any, model: ObjectModel) -> PlanRequest:
    """The planning request for ``model`` standing upright on the support of job config ``cfg``."""
    return posed_request(cfg, model, upright_pose(model, float(cfg.mode.support_height_m)), UPRIGHT_TRIAL)


def posed_request(cfg: Any, model: ObjectModel, pose: np.ndarray, trial: int) -> PlanRequest:
    """The planning request for ``model`` at the (4,4) world ``pose`` on the support of job config ``cfg``,
    with the planner seed of trial ``trial``: seen without error, or through the camera (module doc; raises
    :class:`~graspexp.perception.scene_view.RegistrationFailed` when no pose could be registered)."""
    req = PlanRequest(
        points=model.points @ pose[:3, :3].T + pose[:3, 3],
        normals=model.normals @ pose[:3, :3].T,
        area_mask=np.asarray(model.area_mask, dtype=bool),
        object_pose=pose,
        table_z=float(cfg.mode.support_height_m),
        mode=str(cfg.mode.name),
        gripper=OmegaConf.to_object(cfg.gripper),
        planner=OmegaConf.to_object(cfg.planner),
        cost=OmegaConf.to_object(cfg.cost),
        seed=plan_seed(trial_seed(cfg, model.name, trial)),
        support_blocks_gripper=bool(cfg.mode.support_collides_with_gripper),
    )
    from graspexp.perception.scene_view import RegistrationFailed, perceive, wants_camera

    if not wants_camera(cfg):
        return req
    plain = OmegaConf.to_object(cfg) if isinstance(cfg, DictConfig) else cfg
    seen = perceive(plain, model, pose, req.table_z, trial_seed(cfg, model.name, trial))
    if not seen.ok:
        raise RegistrationFailed(f"registration_failed: {seen.failure}")
    return dataclasses.replace(
        req,
        points=model.points @ seen.pose[:3, :3].T + seen.pose[:3, 3],
        normals=model.normals @ seen.pose[:3, :3].T,
        object_pose=seen.pose,
        observation=seen.observation,
    )


def plan_upright(cfg: Any, model: ObjectModel) -> PlannedObject:
    """Place ``model`` upright on the support and plan with the configured planner (raises
    :class:`~graspexp.planning.NoFeasibleGrasp`, :class:`~graspexp.planning.UnknownPlanner` or
    :class:`~graspexp.perception.scene_view.RegistrationFailed`)."""
    req = upright_request(cfg, model)
    start = time.perf_counter()
    result = plan(req)
    plan_ms = (time.perf_counter() - start) * 1e3
    return PlannedObject(
        model=model, object_pose=req.object_pose, request=req, result=result, plan_ms=plan_ms
    )
