"""The live scene of a clutter-removal round: the table, the objects on it by body name, and the fixtures
its scene type adds (a pile's box, :mod:`graspexp.sim.scene_types`)."""

from dataclasses import dataclass, field

import numpy as np
import sapien

from graspexp.config import JobConfig, ModeConfig
from graspexp.core.geometry import make_pose, quat_wxyz_to_matrix
from graspexp.datasets.model import ObjectModel
from graspexp.sim.scene import CLUTTER_OBJECT_MASK, TrialScene, add_object, base_scene
from graspexp.sim.shape import CollisionShape


@dataclass(frozen=True)
class RoundObject:
    """One drawn object of a round: its model and collision shape."""

    model: ObjectModel
    shape: CollisionShape


@dataclass
class ClutterScene(TrialScene):
    """A round's live scene. ``object_entity``/``object_body`` are the current target's (the trial protocol's
    single-object code runs on them); ``bodies`` holds every object still in the scene, by body name."""

    bodies: dict[str, tuple[sapien.Entity, sapien.physx.PhysxRigidDynamicComponent]] = field(
        default_factory=dict
    )
    fixtures: list[sapien.Entity] = field(default_factory=list)
    """Static bodies the scene type added for placing the objects (a pile's box walls)."""

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

    def remove_fixtures(self) -> None:
        """Take the scene type's fixtures away (a pile's box, once the heap rests)."""
        for entity in self.fixtures:
            self.scene.remove_entity(entity)
        self.fixtures = []


def clutter_scene(mode: ModeConfig, cfg: JobConfig) -> ClutterScene:
    """The table without objects or fixtures; the scene type adds its fixtures, :func:`add_clutter_object`
    the objects."""
    scene, support = base_scene(mode, cfg.sim)
    return ClutterScene(scene, None, None, support, float(mode.support_height_m))


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
