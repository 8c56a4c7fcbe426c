"""``mode.scene=packed``: the objects stood upright (their own +Z up, random yaw) side by side, after the
idea of VGN's and GIGA's ``generate_packed`` (ethz-asl/vgn ``src/vgn/simulation.py``), in one of two ways
(``mode.packed_placement``):

- ``gap`` (the default): at random places in the workspace that keep a gap between their footprints
  (:func:`packed_poses`); an object that finds no place in :data:`PLACE_TRIES` tries is left out;
- ``vgn``: as VGN's and GIGA's code places them (:func:`place_vgn`): a fixed number of attempts in all, each
  at a random place near the workspace centre, an object that touches another taken away again.

Either way each object is first scaled by ``mode.object_scale``
(:func:`graspexp.sim.object_scale.scale_round_objects`)."""

from collections.abc import Sequence

import numpy as np
import sapien

from graspexp.config import JobConfig
from graspexp.config.mode import ClutterModeConfig
from graspexp.core.bodies import clutter_body
from graspexp.core.geometry import make_pose, yaw_rotation
from graspexp.datasets.model import ObjectModel
from graspexp.sim.object_scale import scale_round_objects
from graspexp.sim.round_scene import ClutterScene, RoundObject, add_clutter_object
from graspexp.sim.round_sim import RoundSim, settle_all
from graspexp.sim.scene_types import register

PLACE_TRIES = 200
"""Random places tried per object of a packed scene before it is left out of the round (``gap``)."""


@register("packed")
class Packed:
    """Side by side, upright (:func:`packed_poses` or :func:`place_vgn`); no fixture."""

    def fixtures(self, ts: ClutterScene, cfg: JobConfig) -> None:
        pass

    def place(self, sim: RoundSim, objects: Sequence[RoundObject], rng: np.random.Generator) -> None:
        cfg = sim.cfg
        scale_round_objects(objects, cfg.mode, rng)
        if cfg.mode.packed_placement == "vgn":
            place_vgn(sim, objects, rng)
            return
        poses = packed_poses([o.model for o in objects], cfg.mode, float(cfg.rot.drop_height_m), rng)
        for slot, (obj, pose) in enumerate(zip(objects, poses, strict=True)):
            if pose is not None:
                add_clutter_object(sim.ts, clutter_body(slot), obj.model, obj.shape, pose, cfg)


def packed_poses(
    models: list[ObjectModel], mode: ClutterModeConfig, gap_m: float, rng: np.random.Generator
) -> list[np.ndarray | None]:
    """Upright (the model's own +Z up, random yaw) places in the workspace whose footprints keep
    ``mode.placement_gap_m`` apart: each footprint is the model's x-y bounding rectangle turned by the yaw
    (separating-axis test), lying wholly inside ``mode.workspace_half_size_m``; the lowest point ``gap_m``
    above the table. Placed in slot order; None for an object that found no place in :data:`PLACE_TRIES`
    tries (left out: a round of large objects places fewer)."""
    ws = np.asarray(mode.workspace_half_size_m, dtype=float)
    placed: list[
        tuple[np.ndarray, np.ndarray, np.ndarray]
    ] = []  # (centre (2,), axes (2, 2) columns, half (2,))
    out: list[np.ndarray | None] = [None] * len(models)
    bounds = [(m.mesh.vertices.min(axis=0), m.mesh.vertices.max(axis=0)) for m in models]
    for i in range(len(models)):
        lo, hi = bounds[i]
        mid, half = (lo + hi)[:2] / 2, (hi - lo)[:2] / 2
        for _ in range(PLACE_TRIES):
            R = yaw_rotation(rng.uniform(0.0, 2.0 * np.pi))
            axes = R[:2, :2]
            reach = np.abs(axes) @ half  # (2,) half extents of the turned rectangle's bounding box
            room = ws - reach
            if np.any(room < 0):
                continue
            centre = rng.uniform(-room, room)
            if all(_apart(centre, axes, half, *other, mode.placement_gap_m) for other in placed):
                placed.append((centre, axes, half))
                t = np.zeros(3)
                t[:2] = centre - axes @ mid
                t[2] = float(mode.support_height_m) + gap_m - lo[2]
                out[i] = make_pose(R, t)
                break
    return out


def _apart(
    c1: np.ndarray,
    a1: np.ndarray,
    h1: np.ndarray,
    c2: np.ndarray,
    a2: np.ndarray,
    h2: np.ndarray,
    gap_m: float,
) -> bool:
    """Whether two turned rectangles (centre (2,), unit axes as columns (2, 2), half sizes (2,)) are at least
    ``gap_m`` apart along some axis of either (separating-axis test)."""
    d = c2 - c1
    for axis in (*a1.T, *a2.T):
        r1 = np.abs(a1.T @ axis) @ h1
        r2 = np.abs(a2.T @ axis) @ h2
        if abs(d @ axis) >= r1 + r2 + gap_m:
            return True
    return False


def place_vgn(sim: RoundSim, objects: Sequence[RoundObject], rng: np.random.Generator) -> None:
    """VGN's and GIGA's packed placement (``mode.packed_placement=vgn``; their ``generate_packed``,
    ethz-asl/vgn ``src/vgn/simulation.py``): ``mode.packed_attempts`` attempts in all, until every object is
    placed. Each attempt takes the first object still waiting (slot order; a rejected one waits again behind
    the others: VGN draws a new object from its set at each attempt, a round here has its drawn objects),
    stands it upright at a yaw uniform in [0, 2 pi) with its origin uniform within
    ``mode.packed_centre_half_m`` of the workspace centre in x and y, its lowest point ``rot.drop_height_m``
    above the table, and takes one physics step: if it then has a contact with another object (a contact
    point PhysX reports: within twice ``sim.contact_offset_m``), it is taken away again and the others are
    put back as they were before the step (VGN restores its saved state), else every object settles before
    the next attempt. Draws per attempt: x, y, yaw. SAPIEN 3.0.3's CPU PhysX reports no contact between two
    closed triangle meshes (``sim.collision_method=mesh``, collided by their SDFs), nor do they push each
    other apart: with a convex decomposition (``coacd``, as ``protocol=giga``/``vgn`` set) every pair is seen."""
    ts, cfg = sim.ts, sim.cfg
    mode = cfg.mode
    half = float(mode.packed_centre_half_m)
    z_low = float(mode.support_height_m) + float(cfg.rot.drop_height_m)
    waiting = list(range(len(objects)))
    rejected = False
    for _ in range(int(mode.packed_attempts)):
        if not waiting:
            break
        slot = waiting.pop(0)
        obj = objects[slot]
        x, y = rng.uniform(-half, half), rng.uniform(-half, half)
        R = yaw_rotation(rng.uniform(0.0, 2.0 * np.pi))
        lowest = float(np.asarray(obj.model.mesh.vertices)[:, 2].min())
        pose = make_pose(R, np.array([x, y, z_low - lowest]))
        before = {name: _state(entity, body) for name, (entity, body) in ts.bodies.items()}
        name = clutter_body(slot)
        add_clutter_object(ts, name, obj.model, obj.shape, pose, cfg)
        ts.scene.physx_system.step()  # the probe step: not logged, not counted in the sim time
        rejected = _touches_object(ts, name)
        if rejected:
            _take_back(ts, name, before)
            waiting.append(slot)
        else:
            settle_all(sim)
    if rejected:  # step once more: PhysX's contact list still names the removed body until the next step
        settle_all(sim)


def _state(
    entity: sapien.Entity, body: sapien.physx.PhysxRigidDynamicComponent
) -> tuple[sapien.Pose, np.ndarray, np.ndarray]:
    return entity.pose, body.get_linear_velocity().copy(), body.get_angular_velocity().copy()


def _touches_object(ts: ClutterScene, name: str) -> bool:
    """Whether body ``name`` has a contact point with another object of the scene after the last step."""
    body = ts.bodies[name][1]
    others = {b for n, (_, b) in ts.bodies.items() if n != name}
    for contact in ts.scene.physx_system.get_contacts():
        b0, b1 = contact.bodies
        if ((b0 is body and b1 in others) or (b1 is body and b0 in others)) and len(contact.points):
            return True
    return False


def _take_back(ts: ClutterScene, name: str, before: dict) -> None:
    """Remove body ``name`` and put every other object back at its pose and velocity of ``before``."""
    if ts.object_entity is ts.bodies[name][0]:
        ts.object_entity, ts.object_body = None, None  # the next object added becomes the target
    ts.remove_body(name)
    for other, (pose, v, w) in before.items():
        entity, body = ts.bodies[other]
        entity.pose = pose
        body.set_linear_velocity(v)
        body.set_angular_velocity(w)
