"""The planner's view of a trial or a clutter scene at planning time (``perception.*``): the simulator hands
this module the scene as it is (each object's mesh at its true pose, the support and the floor) and gets back
the pose the planner sees and, when a camera is rendered, what the camera saw (:func:`perceive` for one
object, :func:`perceive_scene` for a clutter scene).

``perception.source=truth``: the true pose plus ``perception.noise`` (the paper's experiments; no
camera unless the planner reads it). ``depth``: the camera renders the scene and the pose is registered
from its cloud, from a prior (the noisy true pose) or globally (``perception.registration.prior=none``).
"""

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from graspexp.config import JobConfig
from graspexp.config.plugins import get_plugin
from graspexp.core.bodies import FLOOR_HALF_SIZE_M
from graspexp.core.geometry import pose_error
from graspexp.core.seeding import rng_for
from graspexp.datasets.model import ObjectModel
from graspexp.perception import Observation
from graspexp.perception.camera import BoxBody, MeshBody

TARGET_ID = 1
"""The object id of the (single) object of a collab or bin trial in the camera's id images."""


@dataclass(frozen=True)
class Perceived:
    """The planner's view of one trial.

    pose : (4, 4) world pose of the object the planner is given. prior : (4, 4) the noisy true pose (the
    registration's start with ``perception.source=depth``). observation : what the camera saw, or None.
    registration : the :class:`graspexp.perception.registration.Registration`, or None. errors : pose
    errors of the registered pose against the truth (``trans_mm``, ``rot_deg``, ``adds_mm``) when a
    registration ran. failure : why no pose could be registered, when the planner plans on the pose
    (:func:`plans_on_pose`; "": one was, none was asked for, or the planner plans from the camera's cloud);
    then ``pose`` is not the object's and nothing may be planned on it (:attr:`ok`).
    """

    pose: np.ndarray
    prior: np.ndarray
    observation: Observation | None = None
    registration: object | None = None
    errors: dict[str, float] = field(default_factory=dict)
    failure: str = ""

    @property
    def ok(self) -> bool:
        """Whether ``pose`` may be planned on (the registration, if any, passed its checks)."""
        return not self.failure


class RegistrationFailed(ValueError):
    """``perception.source=depth`` registered no pose of the object (:attr:`Perceived.failure`): a plan
    without a simulated trial (``graspexp plan``, the planner bench) refuses with this one line."""


def perceived_pose(
    true_pose: np.ndarray, trans_mm: float, rot_deg: float, rng: np.random.Generator
) -> np.ndarray:
    """The pose the planner sees: Gaussian translation (std ``trans_mm``) and a rotation about a random axis
    by a Gaussian angle (std ``rot_deg``) about the object's origin. Zero noise returns the pose unchanged."""
    if trans_mm == 0 and rot_deg == 0:
        return true_pose.copy()
    dR, trans = pose_error(rng, trans_mm, rot_deg)
    out = true_pose.copy()
    out[:3, :3] = dR @ true_pose[:3, :3]
    out[:3, 3] += trans
    return out


def wants_camera(cfg: JobConfig) -> bool:
    """Whether the trial renders the camera: ``perception.source=depth``, or a planner that reads it."""
    return cfg.perception.source == "depth" or get_plugin(cfg.planner.name).plugin.needs_observation


def plans_on_pose(cfg: JobConfig) -> bool:
    """Whether the planner plans on the object's pose (its model's cloud at that pose, the neighbours' at
    theirs): every planner but those that read the camera's output (``needs_observation``: ``antipodal_view``,
    ``vgn``), which plan from what the camera saw and say themselves when it saw too little. With
    ``perception.source=depth``, a failed registration stops the first kind only (``registration_failed``);
    the second is not told a pose it would not use (its trials record the failure's fitness, no pose
    error)."""
    return not get_plugin(cfg.planner.name).plugin.needs_observation


def scene_bodies(
    model: ObjectModel, true_pose: np.ndarray, table_z: float, support_half_m: tuple[float, float] | None
) -> tuple[list[MeshBody], list[BoxBody]]:
    """The camera's scene: the object's mesh at its true pose (id :data:`TARGET_ID`), the support box
    (top at ``table_z``, half sizes ``support_half_m``; None once removed) and the floor (top z = 0)."""
    return [MeshBody(model.mesh, true_pose, TARGET_ID)], support_boxes(table_z, support_half_m)


def support_boxes(table_z: float, support_half_m: tuple[float, float] | None) -> list[BoxBody]:
    """The floor (top z = 0) and the support box (top at ``table_z``, half sizes ``support_half_m``, m; None:
    no support) as the camera sees them (id 0)."""
    fx, fy, fz = FLOOR_HALF_SIZE_M
    boxes = [BoxBody(np.array([-fx, -fy, -2 * fz]), np.array([fx, fy, 0.0]))]
    if support_half_m is not None:
        hx, hy = support_half_m
        boxes.append(BoxBody(np.array([-hx, -hy, 0.0]), np.array([hx, hy, table_z])))
    return boxes


def perceive(
    cfg: JobConfig, model: ObjectModel, true_pose: np.ndarray, table_z: float, trial_seed: int
) -> Perceived:
    """The planner's view at planning time (module doc); every draw seeded from ``trial_seed``."""
    noise = cfg.perception.noise
    prior = perceived_pose(true_pose, noise.trans_mm, noise.rot_deg, rng_for(trial_seed, "noise"))
    if not wants_camera(cfg):
        return Perceived(pose=prior, prior=prior)
    from graspexp.perception.observe import estimate_pose, observe
    from graspexp.perception.registration import pose_errors

    meshes, boxes = scene_bodies(model, true_pose, table_z, tuple(cfg.mode.support_half_size_m))
    obs = observe(cfg.perception, meshes, boxes, table_z, TARGET_ID, rng=rng_for(trial_seed, "camera"))
    if cfg.perception.source != "depth":
        return Perceived(pose=prior, prior=prior, observation=obs)
    start = None if cfg.perception.registration.prior == "none" else prior
    reg = estimate_pose(
        cfg.perception, obs, model.points, model.normals, start, rng=rng_for(trial_seed, "registration")
    )
    errors = pose_errors(reg.pose, true_pose, model.points)
    failure = reg.failure if plans_on_pose(cfg) else ""
    return Perceived(
        pose=reg.pose, prior=prior, observation=obs, registration=reg, errors=errors, failure=failure
    )


def slot_id(slot: int) -> int:
    """The object id of clutter slot ``slot`` (body ``object_<slot>``) in the camera's id images: ``slot + 1``
    (id 0 is the background and the support)."""
    return slot + 1


@dataclass(frozen=True)
class ScenePerceived:
    """The planner's view of a clutter scene before one attempt.

    poses : slot -> (4, 4) world pose the planner is given for that object; a slot whose registration
    failed has none when the planner plans on poses (:func:`plans_on_pose`; it is in ``failed``). priors : slot -> (4, 4) the noisy true pose (the registration's
    start; ``poses`` itself without ``perception.source=depth``). observation : what the camera saw of the
    whole scene (every object, id :func:`slot_id`), ``target_id`` unset (0): each plan request gets a copy
    naming its target; None without a camera. errors : slot -> pose errors of the registered pose
    (``trans_mm``, ``rot_deg``, ``adds_mm``; NaN for a failed slot) and its ``fitness``; empty unless
    ``perception.source=depth``. failed : slot -> why no pose of it was registered
    (:attr:`graspexp.perception.registration.Registration.failure`).
    """

    poses: dict[int, np.ndarray]
    priors: dict[int, np.ndarray]
    observation: Observation | None = None
    errors: dict[int, dict[str, float]] = field(default_factory=dict)
    failed: dict[int, str] = field(default_factory=dict)


def perceive_scene(
    cfg: JobConfig,
    objects: dict[int, tuple[ObjectModel, np.ndarray]],
    table_z: float,
    seed: int,
) -> ScenePerceived:
    """The planner's view of the clutter scene ``objects`` (slot -> (model, true (4, 4) world pose)) over the
    support at ``table_z``: each pose the noisy truth (``perception.noise``, drawn per slot from ``seed``);
    with a camera (:func:`wants_camera`) one observation of every object at its true pose, and with
    ``perception.source=depth`` each object's pose registered from it (its own points only: what its
    neighbours hide is missing) from its noisy prior, as :func:`perceive` does for one object; an object
    whose registration fails its checks is in ``failed``, and gets no pose when the planner plans on poses."""
    noise = cfg.perception.noise
    priors = {
        slot: perceived_pose(true, noise.trans_mm, noise.rot_deg, rng_for(seed, "noise", slot))
        for slot, (_, true) in objects.items()
    }
    if not wants_camera(cfg):
        return ScenePerceived(priors, priors)
    from graspexp.perception.observe import estimate_pose, observe
    from graspexp.perception.registration import pose_errors

    meshes = [MeshBody(model.mesh, true, slot_id(slot)) for slot, (model, true) in objects.items()]
    boxes = support_boxes(table_z, tuple(cfg.mode.support_half_size_m))
    obs = observe(cfg.perception, meshes, boxes, table_z, 0, rng=rng_for(seed, "camera"))
    if cfg.perception.source != "depth":
        return ScenePerceived(priors, priors, obs)
    poses, errors, failed = {}, {}, {}
    on_pose = plans_on_pose(cfg)
    for slot, (model, true) in objects.items():
        start = None if cfg.perception.registration.prior == "none" else priors[slot]
        reg = estimate_pose(
            cfg.perception,
            dataclasses.replace(obs, target_id=slot_id(slot)),
            model.points,
            model.normals,
            start,
            rng=rng_for(seed, "registration", slot),
        )
        if reg.ok or not on_pose:
            poses[slot] = reg.pose
        if reg.ok:
            errors[slot] = {**pose_errors(reg.pose, true, model.points), "fitness": reg.fitness}
        else:
            failed[slot] = reg.failure
            errors[slot] = {
                **dict.fromkeys(("trans_mm", "rot_deg", "adds_mm"), np.nan),
                "fitness": reg.fitness,
            }
    return ScenePerceived(poses, priors, obs, errors, failed)
