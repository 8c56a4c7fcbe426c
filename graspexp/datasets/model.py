"""The object model every later stage consumes."""

import hashlib
from dataclasses import dataclass
from functools import cached_property

import numpy as np
import trimesh


@dataclass(frozen=True)
class ObjectModel:
    """One object, in its own frame, metres.

    mesh : trimesh.Trimesh, object frame, metres (vertices merged by position).
    points : (N, 3) float64, surface samples in the object frame, metres (seeded).
    normals : (N, 3) float64, outward unit normals of ``points``.
    area_mask : (N,) bool, True where the point lies in the grasping area.
    mass_kg : mass, kg.
    name : catalogue name, e.g. ``025_mug`` or ``ape``.
    dataset : the dataset's name (``dataset.name``).
    source : file the mesh came from ("" for procedural meshes).
    """

    name: str
    dataset: str
    mesh: trimesh.Trimesh
    points: np.ndarray
    normals: np.ndarray
    area_mask: np.ndarray
    mass_kg: float
    source: str = ""
    friction: float | None = None
    notes: tuple[str, ...] = ()

    @cached_property
    def mesh_sha256(self) -> str:
        """SHA-256 of the geometry every trial uses (vertices in metres as float64, faces as int64, after
        loading, scaling and merging): the same file at another scale or another file hashes differently."""
        digest = hashlib.sha256(np.ascontiguousarray(self.mesh.vertices, dtype=np.float64).tobytes())
        digest.update(np.ascontiguousarray(self.mesh.faces, dtype=np.int64).tobytes())
        return digest.hexdigest()

    @cached_property
    def area_sha256(self) -> str:
        """SHA-256 of the grasping area the planner gets (the area mask over the seeded cloud, and the
        cloud): an edited area spec hashes differently."""
        digest = hashlib.sha256(np.packbits(np.asarray(self.area_mask, dtype=bool)).tobytes())
        digest.update(np.ascontiguousarray(self.points, dtype=np.float64).tobytes())
        return digest.hexdigest()

    @cached_property
    def mesh_facts(self) -> dict[str, str]:
        """What the geometry is, readable: face count, surface area (m^2) and enclosed volume (m^3, "" if the
        mesh is not closed), as log metadata strings; a cut or rescaled file changes them."""
        closed = bool(self.mesh.is_watertight)
        return {
            "mesh_faces": str(len(self.mesh.faces)),
            "mesh_area_m2": f"{float(self.mesh.area):.6e}",
            "mesh_volume_m3": f"{float(self.mesh.volume):.6e}" if closed else "",
        }

    @property
    def area_points(self) -> np.ndarray:
        """(n_area, 3) grasping-area points, object frame, metres."""
        return self.points[self.area_mask]
