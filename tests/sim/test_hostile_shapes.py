"""Issue 39: meshes from other people's folders get a collision shape or a one-line reason, never a traceback."""

import numpy as np
import trimesh

from graspexp.config import SimConfig
from graspexp.sim.collision_shapes import FALLBACK_METHOD, shape_with_fallback


def test_a_triangle_soup_falls_back_to_a_convex_decomposition():
    sphere = trimesh.creation.icosphere(subdivisions=2, radius=0.03)
    centres = sphere.triangles.mean(axis=1, keepdims=True)
    soup = centres + 0.9 * (
        sphere.triangles - centres
    )  # 320 triangles sharing no edge, each < 1 % of the area
    mesh = trimesh.Trimesh(soup.reshape(-1, 3), np.arange(soup.size // 3).reshape(-1, 3))
    shape, note = shape_with_fallback(mesh, SimConfig(collision_method="mesh"))
    assert shape.method == FALLBACK_METHOD and shape.parts
    assert "a triangle soup?" in note and note.startswith(f"collision: {FALLBACK_METHOD} (fallback")
