"""A fresh physics-only SAPIEN scene per trial: the support and the dropped object.

World frame: z up, metres. The support is a static box on the floor (z = 0) whose top is the plane
z = h (``mode.support_height_m``); the floor (a thin box: PhysX makes no contact between an SDF triangle
mesh and a plane) touches the object only. Collision filtering uses SAPIEN's groups: two shapes collide when
``(A[0] & B[1]) or (A[1] & B[0])``; the bits below say what each body is and what it touches.
"""

from dataclasses import dataclass

import numpy as np
import sapien

from graspexp.config import ModeConfig, SimConfig
from graspexp.core.bodies import FLOOR_HALF_SIZE_M, GROUND_NAME, OBJECT_NAME, SUPPORT_NAME
from graspexp.core.geometry import matrix_to_quat_wxyz, quat_wxyz_to_matrix
from graspexp.sim.shape import CollisionShape

OBJECT_BIT, SUPPORT_BIT, GRIPPER_BIT, GROUND_BIT = 1, 2, 4, 8


def configure_physx(cfg: SimConfig) -> None:
    """Global PhysX settings; must run before each scene is created."""
    sapien.physx.set_scene_config(
        gravity=np.array([0.0, 0.0, -9.81]),
        enable_tgs=bool(cfg.enable_tgs),
        enable_enhanced_determinism=True,
        cpu_workers=0,
    )
    sapien.physx.set_body_config(
        solver_position_iterations=int(cfg.solver_position_iterations),
        solver_velocity_iterations=int(cfg.solver_velocity_iterations),
        sleep_threshold=0.0,
    )
    sapien.physx.set_shape_config(
        contact_offset=float(cfg.contact_offset_m), rest_offset=float(cfg.rest_offset_m)
    )
    sapien.physx.set_sdf_config(
        spacing=float(cfg.sdf_spacing_m), subgrid_size=6, num_threads_for_construction=1
    )


def set_groups(component: sapien.physx.PhysxRigidBaseComponent, member: int, collides_with: int) -> None:
    """Give every collision shape of ``component`` the membership and mask bits."""
    for shape in component.get_collision_shapes():
        shape.set_collision_groups([member, collides_with, 0, 0])


@dataclass
class TrialScene:
    """The live scene of one trial and handles to its bodies."""

    scene: sapien.Scene
    object_entity: sapien.Entity
    object_body: sapien.physx.PhysxRigidDynamicComponent
    support: sapien.Entity | None
    table_z: float

    def object_pose(self) -> np.ndarray:
        """(4,4) world pose of the object frame."""
        p = self.object_entity.pose
        T = np.eye(4)
        T[:3, :3] = quat_wxyz_to_matrix(p.q)
        T[:3, 3] = p.p
        return T

    def remove_support(self) -> None:
        if self.support is not None:
            self.scene.remove_entity(self.support)
            self.support = None


def build_scene(
    shape: CollisionShape,
    mass_kg: float,
    drop_pose: np.ndarray,
    mode: ModeConfig,
    sim: SimConfig,
    friction: float | None = None,
) -> TrialScene:
    """Create the scene with the support and the object at ``drop_pose`` ((4,4), world, m).

    The object is one dynamic body with ``shape``'s collision parts (convex hulls, or one SDF triangle
    mesh); its total mass is ``mass_kg``; its surface's Coulomb friction is ``friction`` (static and dynamic)
    if given (an object's sidecar), else ``sim.object_static_friction`` / ``sim.object_dynamic_friction``.
    In collab mode the support collides with the object only (paper IV-A); in bin mode also with the gripper.
    """
    scene, support = base_scene(mode, sim)
    entity, body = add_object(scene, shape, mass_kg, drop_pose, sim, friction, OBJECT_NAME, OBJECT_MASK)
    h = float(mode.support_height_m)
    return TrialScene(scene=scene, object_entity=entity, object_body=body, support=support, table_z=h)


def base_scene(mode: ModeConfig, sim: SimConfig) -> tuple[sapien.Scene, sapien.Entity]:
    """A new scene (PhysX configured from ``sim``) with the floor and the support (top at
    ``mode.support_height_m``; collides with the gripper where ``mode.support_collides_with_gripper``)."""
    configure_physx(sim)
    scene = sapien.Scene([sapien.physx.PhysxCpuSystem()])
    scene.set_timestep(float(sim.timestep_s))
    h = float(mode.support_height_m)

    support_mat = sapien.physx.PhysxMaterial(sim.support_friction, sim.support_friction, 0.0)
    ground = scene.create_actor_builder()  # the floor under the support: catches objects that fall off
    ground.add_box_collision(
        sapien.Pose([0.0, 0.0, -FLOOR_HALF_SIZE_M[2]]), half_size=FLOOR_HALF_SIZE_M, material=support_mat
    )
    floor = ground.build_static(GROUND_NAME)
    set_groups(floor.find_component_by_type(sapien.physx.PhysxRigidStaticComponent), GROUND_BIT, OBJECT_BIT)
    builder = scene.create_actor_builder()
    hx, hy = mode.support_half_size_m
    builder.add_box_collision(half_size=[hx, hy, h / 2], material=support_mat)
    builder.set_initial_pose(sapien.Pose([0.0, 0.0, h / 2]))
    support = builder.build_static(SUPPORT_NAME)
    support_mask = OBJECT_BIT | (GRIPPER_BIT if mode.support_collides_with_gripper else 0)
    set_groups(
        support.find_component_by_type(sapien.physx.PhysxRigidStaticComponent), SUPPORT_BIT, support_mask
    )
    return scene, support


OBJECT_MASK = SUPPORT_BIT | GRIPPER_BIT | GROUND_BIT
"""What a lone object collides with (collab, bin)."""
CLUTTER_OBJECT_MASK = OBJECT_MASK | OBJECT_BIT
"""What an object of a clutter round collides with: the others too."""


def add_object(
    scene: sapien.Scene,
    shape: CollisionShape,
    mass_kg: float,
    pose: np.ndarray,
    sim: SimConfig,
    friction: float | None,
    name: str,
    mask: int,
) -> tuple[sapien.Entity, sapien.physx.PhysxRigidDynamicComponent]:
    """Add one dynamic object body named ``name`` at ``pose`` ((4,4), world, m) colliding with ``mask``
    (:func:`build_scene` says what its shape, mass and friction are)."""
    static, dynamic = (
        (sim.object_static_friction, sim.object_dynamic_friction)
        if friction is None
        else (friction, friction)
    )
    obj_mat = sapien.physx.PhysxMaterial(static, dynamic, 0.0)
    body = sapien.physx.PhysxRigidDynamicComponent()
    for part in _object_shapes(shape, obj_mat):
        part.set_density(1000.0)
        body.attach(part)
    if len(body.get_collision_shapes()) != len(shape.parts):
        raise RuntimeError(
            f"PhysX dropped {len(shape.parts) - len(body.get_collision_shapes())} of "
            f"{len(shape.parts)} collision parts"
        )
    entity = sapien.Entity()
    entity.name = name
    entity.add_component(body)
    entity.pose = sapien.Pose(pose[:3, 3], matrix_to_quat_wxyz(pose[:3, :3]))
    scene.add_entity(entity)
    body.mass = float(mass_kg)
    body.angular_damping = float(sim.object_angular_damping)
    set_groups(body, OBJECT_BIT, mask)
    return entity, body


def cook_shape(shape: CollisionShape, sim: SimConfig) -> None:
    """Cook the object's PhysX shapes as :func:`add_object` will (after :func:`configure_physx`): a mesh read
    from its file is cooked with its SDF once per process and SDF setting (about 15-20 ms for a
    2,000-vertex YCB mesh) and reused by the later scenes."""
    configure_physx(sim)
    _object_shapes(shape, sapien.physx.PhysxMaterial(0.5, 0.5, 0.0))


def _object_shapes(
    shape: CollisionShape, material: sapien.physx.PhysxMaterial
) -> list[sapien.physx.PhysxCollisionShape]:
    """PhysX shapes of the object's collision parts (object frame, metres)."""
    one = np.ones(3, dtype=np.float32)
    if shape.convex:
        return [
            sapien.physx.PhysxCollisionShapeConvexMesh(vertices=v, scale=one, material=material)
            for v, _ in shape.parts
        ]
    # from the file: SAPIEN cooks it (SDF included) once per process and reuses it, at any scale
    scale = one if shape.file_scale == 1.0 else np.full(3, shape.file_scale, dtype=np.float32)
    return [sapien.physx.PhysxCollisionShapeTriangleMesh(str(shape.mesh_file), scale, material, sdf=True)]
