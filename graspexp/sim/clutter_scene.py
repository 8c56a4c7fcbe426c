"""The scene of a clutter-removal round: the table, several objects and (``mode=pile``) the box they are
dropped into; where each object starts (a pile's drop, a packed scene's upright places).

Protocol sources: VGN (Breyer et al., CoRL 2020; ethz-asl/vgn ``generate_pile``/``remove_objects_outside_roi``)
and GIGA (Jiang et al., RSS 2021) drop random poses into a box that is then removed (pile) or stand objects
upright at random places that do not overlap (packed); objects outside the workspace are taken away.
"""

from dataclasses import dataclass, field

import numpy as np
import sapien

from graspexp.config import JobConfig, ModeConfig
from graspexp.core.bodies import TRAY_NAME
from graspexp.core.geometry import make_pose, quat_wxyz_to_matrix, random_rotation, yaw_rotation
from graspexp.datasets.model import ObjectModel
from graspexp.sim.scene import (
    CLUTTER_OBJECT_MASK,
    OBJECT_BIT,
    SUPPORT_BIT,
    TrialScene,
    add_object,
    base_scene,
    set_groups,
)
from graspexp.sim.shape import CollisionShape

TRAY_WALL_M = 0.01
"""Thickness of the tray's walls, m (static boxes: any thickness stops an object; 1 cm keeps PhysX's
contact offset inside the wall)."""
PLACE_TRIES = 200
"""Random places tried per object of a packed scene before it is left out of the round."""


@dataclass
class ClutterScene(TrialScene):
    """A round's live scene. ``object_entity``/``object_body`` are the current target's (the trial protocol's
    single-object code runs on them); ``bodies`` holds every object still in the scene, by body name."""

    bodies: dict[str, tuple[sapien.Entity, sapien.physx.PhysxRigidDynamicComponent]] = field(
        default_factory=dict
    )
    tray: list[sapien.Entity] = field(default_factory=list)

    def target(self, name: str) -> None:
        """Make body ``name`` the object the protocol grasps."""
        self.object_entity, self.object_body = self.bodies[name]

    def pose_of(self, name: str) -> np.ndarray:
        """(4,4) world pose of body ``name``."""
        p = self.bodies[name][0].pose
        return make_pose(quat_wxyz_to_matrix(p.q), p.p)

    def remove_body(self, name: str) -> None:
        """Take body ``name`` out of the scene (a held object, or one that left the workspace)."""
        entity, _ = self.bodies.pop(name)
        self.scene.remove_entity(entity)

    def remove_tray(self) -> None:
        for wall in self.tray:
            self.scene.remove_entity(wall)
        self.tray = []


def clutter_scene(mode: ModeConfig, cfg: JobConfig) -> ClutterScene:
    """The table (and for ``pile`` the tray) without objects; :func:`add_clutter_object` adds them."""
    scene, support = base_scene(mode, cfg.sim)
    ts = ClutterScene(scene, None, None, support, float(mode.support_height_m))
    if mode.name == "pile":
        ts.tray = _tray(scene, mode, cfg)
    return ts


def add_clutter_object(
    ts: ClutterScene, name: str, model: ObjectModel, shape: CollisionShape, pose: np.ndarray, cfg: JobConfig
) -> None:
    """Add object ``model`` as body ``name`` at ``pose`` ((4,4) world); it collides with the others too."""
    entity, body = add_object(
        ts.scene, shape, model.mass_kg, pose, cfg.sim, model.friction, name, CLUTTER_OBJECT_MASK
    )
    if cfg.mode.sleep_threshold > 0:  # else PhysX's body default of the whole sim: never asleep
        body.sleep_threshold = float(cfg.mode.sleep_threshold)
    ts.bodies[name] = (entity, body)
    if ts.object_entity is None:
        ts.target(name)


def _tray(scene: sapien.Scene, mode: ModeConfig, cfg: JobConfig) -> list[sapien.Entity]:
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
    model: ObjectModel, mode: ModeConfig, heap_top_z: float, rng: np.random.Generator
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


def packed_poses(
    models: list[ObjectModel], mode: ModeConfig, gap_m: float, rng: np.random.Generator
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
