"""An object's collision geometry: the one type the shape builders (:mod:`.collision_shapes`), their
accuracy check (:mod:`.collision_accuracy`) and the scene (:mod:`.scene`) share."""

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh


@dataclass(frozen=True)
class CollisionShape:
    """An object's collision geometry in the object frame, metres."""

    method: str
    """The ``sim.collision_method`` it was made for (one of :data:`graspexp.sim.collision_shapes.METHODS`)."""
    parts: tuple[tuple[np.ndarray, np.ndarray], ...]
    """(vertices (V, 3) float32, faces (F, 3) int64) per part: convex hulls, or one closed mesh."""
    convex: bool
    """True: every part is a convex hull (PhysX convex shapes). False: one closed triangle mesh."""
    mesh_file: Path | None = None
    """The OBJ file of the closed mesh that SAPIEN cooks once per process; None for hulls."""
    key: str = ""
    """The cache key it was built under (mesh content, method parameters, library versions); "" if uncached."""
    sha256: str = ""
    """SHA-256 of the shape itself (its parts' float32 vertices and int64 faces): what every trial that used
    it collided with, recorded in each log ("" if not computed)."""
    file_scale: float = 1.0
    """Uniform factor PhysX applies to ``mesh_file`` (a round's scaled object, ``mode.object_scale``: its
    ``parts`` are scaled already, the cooked file and its SDF are shared and scaled by PhysX); 1: as the file is."""

    def meshes(self) -> list[trimesh.Trimesh]:
        """The parts as triangle meshes (object frame, metres)."""
        return [trimesh.Trimesh(v, f, process=False) for v, f in self.parts]
