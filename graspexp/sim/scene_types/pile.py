"""``mode.scene=pile``: the objects dropped one after another into a box on the table, each once the earlier
ones rest, then the box lifted away, leaving a heap (VGN's ``generate_pile``, ethz-asl/vgn
``src/vgn/simulation.py``; GIGA's pile scenes)."""

from collections.abc import Sequence

import numpy as np
import sapien

from graspexp.config import JobConfig
from graspexp.config.mode import ClutterModeConfig
from graspexp.core.bodies import TRAY_NAME, clutter_body
from graspexp.core.geometry import make_pose, random_rotation
from graspexp.core.phases import Phase
from graspexp.datasets.model import ObjectModel
from graspexp.sim.object_scale import scale_round_objects
from graspexp.sim.round_scene import ClutterScene, RoundObject, add_clutter_object
from graspexp.sim.round_sim import RoundSim, settle_all
from graspexp.sim.scene import OBJECT_BIT, SUPPORT_BIT, set_groups
from graspexp.sim.scene_types import register

TRAY_WALL_M = 0.01
"""Thickness of the tray's walls, m (static boxes: any thickness stops an object; 1 cm keeps PhysX's
contact offset inside the wall)."""


@register("pile")
class Pile:
    """A heap: the box (``mode.tray_half_size_m``, ``mode.tray_wall_height_m``) is the scene's fixture; each
    object, scaled by ``mode.object_scale`` (:func:`graspexp.sim.object_scale.scale_round_objects`), is
    released at a random orientation over the box (:func:`pile_drop_pose`) and settled before the next; the
    box is then taken away."""

    def fixtures(self, ts: ClutterScene, cfg: JobConfig) -> None:
        ts.fixtures = _tray(ts.scene, cfg.mode, cfg)

    def place(self, sim: RoundSim, objects: Sequence[RoundObject], rng: np.random.Generator) -> None:
        ts, cfg = sim.ts, sim.cfg
        scale_round_objects(objects, cfg.mode, rng)
        for slot, obj in enumerate(objects):
            top = max((ts.bodies[b][1].compute_global_aabb_tight()[1][2] for b in ts.bodies), default=0.0)
            pose = pile_drop_pose(obj.model, cfg.mode, float(top), rng)
            add_clutter_object(ts, clutter_body(slot), obj.model, obj.shape, pose, cfg)
            settle_all(sim)
        sim.phase(Phase.REMOVE_TRAY)
        ts.remove_fixtures()


def _tray(scene: sapien.Scene, mode: ClutterModeConfig, cfg: JobConfig) -> list[sapien.Entity]:
    """Four static walls around ``mode.tray_half_size_m`` on the table, touching the objects only."""
    hx, hy = mode.tray_half_size_m
    h, t, z0 = float(mode.tray_wall_height_m), TRAY_WALL_M, float(mode.support_height_m)
    mat = sapien.physx.PhysxMaterial(cfg.sim.support_friction, cfg.sim.support_friction, 0.0)
    walls = []
    for center, half in (
        ((hx + t / 2, 0.0), (t / 2, hy + t, h / 2)),
        ((-hx - t / 2, 0.0), (t / 2, hy + t, h / 2)),
        ((0.0, hy + t / 2), (hx + t, t / 2, h / 2)),
        ((0.0, -hy - t / 2), (hx + t, t / 2, h / 2)),
    ):
        builder = scene.create_actor_builder()
        builder.add_box_collision(half_size=list(half), material=mat)
        builder.set_initial_pose(sapien.Pose([center[0], center[1], z0 + h / 2]))
        wall = builder.build_static(TRAY_NAME)
        set_groups(
            wall.find_component_by_type(sapien.physx.PhysxRigidStaticComponent), SUPPORT_BIT, OBJECT_BIT
        )
        walls.append(wall)
    return walls


def pile_drop_pose(
    model: ObjectModel, mode: ClutterModeConfig, heap_top_z: float, rng: np.random.Generator
) -> np.ndarray:
    """(4,4) release pose of one object of a pile: uniformly random orientation, centre over a uniform point
    of the tray (inset by the object's half extent, so it starts inside the walls), lowest point
    ``mode.drop_height_m`` above the table or 1 cm above the heap's top ``heap_top_z`` (m), whichever is higher."""
    R = random_rotation(rng)
    v = model.mesh.vertices @ R.T
    lo, hi = v.min(axis=0), v.max(axis=0)
    half = (hi - lo)[:2] / 2
    room = np.maximum(np.asarray(mode.tray_half_size_m, dtype=float) - half, 0.0)
    x, y = rng.uniform(-room, room)
    z_low = max(float(mode.support_height_m) + float(mode.drop_height_m), heap_top_z + 0.01)
    t = np.array([x - (lo[0] + hi[0]) / 2, y - (lo[1] + hi[1]) / 2, z_low - lo[2]])
    return make_pose(R, t)
