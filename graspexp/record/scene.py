"""The Foxglove 3D scene of a trial (``/scene``, foxglove.SceneUpdate): built once per object, logged per trial.

Entities are ``foxglove.messages.SceneEntity`` objects of the official ``foxglove-sdk`` package. Each
entity is frame-locked to a ``/tf`` frame (``world``, ``object``, ``palm``, ``finger_left``,
``finger_right``) and never expires, so it moves with its frame; its id is the name of the physics body
it draws (e.g. ``support``), which is also the id a later deletion names.
"""

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import trimesh
from foxglove.messages import (
    Color,
    CubePrimitive,
    Point3,
    Pose,
    Quaternion,
    SceneEntity,
    Timestamp,
    TriangleListPrimitive,
    Vector3,
)

from graspexp.config import JobConfig
from graspexp.core.bodies import FINGER_NAMES, OBJECT_NAME, PALM_NAME, SUPPORT_NAME, TRAY_NAME, clutter_body
from graspexp.grippers import LEFT, PALM, RIGHT, GripperGeometry, HandMeshes
from graspexp.record.channels import BODY_NAMES
from graspexp.sim.collision_shapes import hull_meshes

SCENE_DECIMALS = 6
"""Mesh vertices are rounded to this many decimals of a metre (1 um)."""
LOG_MESH_MAX_FACES = 20_000
"""A URDF gripper link is drawn into each trial's log with at most this many triangles (decimated, quadric
error): the log draws the shape, the physics uses its hulls; a 2.6M-face scan would add 36 MB to every log."""
SUPPORT_COLOR = (0.6, 0.45, 0.3, 1.0)
HULL_COLOR = (0.2, 0.4, 0.9, 1.0)
GRIPPER_COLOR = (0.5, 0.5, 0.5, 1.0)


def _rgba(color: Sequence[float]) -> Color:
    c = [float(v) for v in np.asarray(color, dtype=float).reshape(-1)]
    if len(c) != 4:
        raise ValueError(f"color must be (r, g, b, a) in [0, 1], got {color!r}")
    return Color(r=c[0], g=c[1], b=c[2], a=c[3])


def _vec3(values: Sequence[float], what: str) -> list[float]:
    v = [float(x) for x in np.asarray(values, dtype=float).reshape(-1)]
    if len(v) != 3:
        raise ValueError(f"{what} must have 3 components, got {values!r}")
    return v


def _entity(id: str, frame_id: str, **primitives) -> SceneEntity:
    """A SceneEntity that never expires and follows ``frame_id`` (frame_locked); timestamp 0."""
    return SceneEntity(timestamp=Timestamp(0, 0), frame_id=frame_id, id=id, frame_locked=True, **primitives)


def mesh_entity(
    id: str, frame_id: str, vertices: np.ndarray, faces: np.ndarray, color: Sequence[float]
) -> SceneEntity:
    """A SceneEntity with one TriangleListPrimitive (identity pose in ``frame_id``).

    vertices : (V, 3) float, ``frame_id`` frame, m. faces : (F, 3) int indices into vertices.
    color : (r, g, b, a) in [0, 1]. The vertices are stored once (rounded to SCENE_DECIMALS decimals, i.e.
    1 um) with an index array of 3F entries.
    """
    v = np.asarray(vertices, dtype=float)
    f = np.asarray(faces)
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"vertices must be (V, 3), got shape {v.shape}")
    if f.ndim != 2 or f.shape[1] != 3 or not np.issubdtype(f.dtype, np.integer):
        raise ValueError(f"faces must be (F, 3) integers, got shape {f.shape} dtype {f.dtype}")
    if f.size and (f.min() < 0 or f.max() >= len(v)):
        raise ValueError(f"faces index outside 0..{len(v) - 1}")
    points = [Point3(x=x, y=y, z=z) for x, y, z in np.round(v, SCENE_DECIMALS).tolist()]
    tri = TriangleListPrimitive(
        pose=Pose(position=Vector3(), orientation=Quaternion(w=1.0)),
        points=points,
        color=_rgba(color),
        indices=f.reshape(-1).astype(int).tolist(),
    )
    return _entity(id, frame_id, triangles=[tri])


def box_entity(
    id: str,
    frame_id: str,
    center: Sequence[float],
    size: Sequence[float],
    color: Sequence[float],
    quat_xyzw: Sequence[float] = (0.0, 0.0, 0.0, 1.0),
) -> SceneEntity:
    """A SceneEntity with one CubePrimitive.

    center : (3,) m and quat_xyzw : (4,) Foxglove order (x, y, z, w), both in ``frame_id``;
    size : (3,) full edge lengths, m; color : (r, g, b, a) in [0, 1].
    """
    c, s = _vec3(center, "center"), _vec3(size, "size")
    q = [float(v) for v in np.asarray(quat_xyzw, dtype=float).reshape(-1)]
    if len(q) != 4:
        raise ValueError(f"quat_xyzw must have 4 components, got {quat_xyzw!r}")
    cube = CubePrimitive(
        pose=Pose(
            position=Vector3(x=c[0], y=c[1], z=c[2]), orientation=Quaternion(x=q[0], y=q[1], z=q[2], w=q[3])
        ),
        size=Vector3(x=s[0], y=s[1], z=s[2]),
        color=_rgba(color),
    )
    return _entity(id, frame_id, cubes=[cube])


@dataclass(frozen=True)
class ObjectScene:
    """The scene entities of every trial of one object (built once by :func:`object_scene`)."""

    static: list[SceneEntity]
    """The support (world frame, id ``support``) and the object's collision hulls (``object`` frame)."""
    gripper: list[SceneEntity]
    """The palm and finger boxes (a URDF gripper: its collision meshes), each in its own link frame."""


@dataclass(frozen=True)
class RoundScene(ObjectScene):
    """The scene entities of a clutter round: the support, every object's hulls in its own frame
    (``object_<slot>``), the gripper."""

    bodies: dict[str, list[str]]
    """Body name -> the ids of its entities (deleted when the object is taken away)."""


def round_bodies(n_objects: int) -> tuple[str, ...]:
    """The /contacts body names of a round of ``n_objects``: the single-object log's, the tray, then
    ``object_0`` ... (the first, ``object``, is unused in a round)."""
    return (*BODY_NAMES, TRAY_NAME, *(clutter_body(i) for i in range(n_objects)))


def round_scene(cfg: JobConfig, hulls: list) -> RoundScene:
    """Scene entities of a round under ``cfg`` whose object ``slot`` has the collision shape ``hulls[slot]``
    (:class:`graspexp.sim.shape.CollisionShape`, object frame, m)."""
    static, bodies = [_support_entity(cfg)], {}
    for slot, parts in enumerate(hulls):
        name = clutter_body(slot)
        meshes = hull_meshes(parts)
        ids = [f"{name}_hull_{i}" for i in range(len(meshes))]
        for i, m in zip(ids, meshes, strict=True):
            static.append(mesh_entity(i, name, m.vertices, m.faces, HULL_COLOR))
        bodies[name] = ids
    return RoundScene(static=static, gripper=_gripper_entities(cfg), bodies=bodies)


def object_scene(cfg: JobConfig, hulls: list[np.ndarray]) -> ObjectScene:
    """Scene entities of one object under ``cfg`` (support size, gripper geometry); hulls : (V_i, 3) object frame, m."""
    static = [_support_entity(cfg)]
    for i, m in enumerate(hull_meshes(hulls)):
        static.append(mesh_entity(f"{OBJECT_NAME}_hull_{i}", OBJECT_NAME, m.vertices, m.faces, HULL_COLOR))
    return ObjectScene(static=static, gripper=_gripper_entities(cfg))


def _support_entity(cfg: JobConfig) -> SceneEntity:
    h = cfg.mode.support_height_m
    hx, hy = cfg.mode.support_half_size_m
    return box_entity(SUPPORT_NAME, "world", [0.0, 0.0, h / 2], [2 * hx, 2 * hy, h], SUPPORT_COLOR)


def _gripper_entities(cfg: JobConfig) -> list[SceneEntity]:
    geometry = GripperGeometry.of(cfg.gripper)
    if geometry.hand is not None:
        return hand_entities(geometry.hand)
    palm = geometry.palm()
    gripper = [box_entity(PALM_NAME, PALM_NAME, list(palm.center), list(palm.size), GRIPPER_COLOR)]
    for name, sign in zip(FINGER_NAMES, (1.0, -1.0), strict=True):
        finger = geometry.finger(sign)
        gripper.append(box_entity(name, name, list(finger.center), list(finger.size), GRIPPER_COLOR))
    return gripper


def hand_entities(hand: HandMeshes) -> list[SceneEntity]:
    """One entity per link of a URDF gripper (id and frame ``palm``, ``finger_left``, ``finger_right``): a
    TriangleListPrimitive of its collision meshes as the URDF gives them, in the link's frame."""
    out = []
    for part, name in ((PALM, PALM_NAME), (LEFT, FINGER_NAMES[0]), (RIGHT, FINGER_NAMES[1])):
        meshes = [(v, f) for p, v, f in hand.meshes if p == part]
        starts = np.cumsum([0] + [len(v) for v, _ in meshes[:-1]])
        vertices = np.concatenate([v for v, _ in meshes])
        faces = np.concatenate([f + s for (_, f), s in zip(meshes, starts, strict=True)])
        if len(faces) > LOG_MESH_MAX_FACES:
            drawn = trimesh.Trimesh(vertices, faces, process=False)
            drawn = drawn.simplify_quadric_decimation(face_count=LOG_MESH_MAX_FACES)
            vertices, faces = np.asarray(drawn.vertices), np.asarray(drawn.faces)
        out.append(mesh_entity(name, name, vertices, faces, GRIPPER_COLOR))
    return out
