"""Issue 39: a URDF gripper with a huge scanned finger mesh is drawn into each log decimated, not whole."""

import numpy as np
import trimesh

from graspexp.grippers import LEFT, PALM, RIGHT, HandMeshes
from graspexp.record import scene


def test_a_huge_gripper_link_is_drawn_decimated_into_the_log(monkeypatch):
    monkeypatch.setattr(scene, "LOG_MESH_MAX_FACES", 200)  # the cap, scaled down with the mesh
    finger = trimesh.creation.icosphere(subdivisions=3, radius=0.01)  # 1280 faces
    box = trimesh.creation.box(extents=(0.02, 0.02, 0.02))  # 12 faces: drawn as given
    parts = ((PALM, box), (LEFT, finger), (RIGHT, box))
    meshes = tuple((p, np.asarray(m.vertices, float), np.asarray(m.faces, np.int64)) for p, m in parts)
    hand = HandMeshes((), (), meshes, 0.1, ())
    monkeypatch.setattr(scene, "mesh_entity", lambda id, frame, v, f, color: (id, len(f)))  # faces drawn
    (_, palm), (_, left), (_, right) = scene.hand_entities(hand)
    assert (palm, right) == (12, 12) and 0 < left <= 200
