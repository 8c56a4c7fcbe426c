"""What an object is made of, known before its mesh is read: the files, their units and what its dataset
publishes about it. Every layout (:mod:`graspexp.datasets.catalog`) describes its objects this way."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from graspexp.datasets.regions import RegionSpec


@dataclass(frozen=True)
class MeshPart:
    """One piece of an object's geometry: a mesh file or a URDF primitive, scaled then placed."""

    file: Path | None
    """Mesh file; None for a primitive."""
    primitive: tuple[str, tuple[float, ...]] | None = None
    """URDF primitive in metres: ``("box", (x, y, z))``, ``("cylinder", (radius, length))`` or
    ``("sphere", (radius,))``; None for a file."""
    scale: float | tuple[float, float, float] = 1.0
    """File units -> metres: one factor, or one per axis (a URDF ``scale``)."""
    origin: tuple[tuple[float, ...], ...] | None = None
    """4x4 pose of the part in the object frame (a URDF collision ``<origin>``), m; None: identity."""


@dataclass(frozen=True)
class ObjectSource:
    """One object of a dataset, before loading."""

    name: str
    parts: tuple[MeshPart, ...]
    """Its geometry; empty for a procedural primitive of the ``primitives`` layout."""
    source: str = ""
    """The file a log names as the object's source (the mesh, or the URDF that places it); "" if procedural."""
    mass_kg: float | None = None
    """Published mass (YCB), a URDF ``<inertial>`` mass or a sidecar's ``mass_kg``; None: volume x density."""
    density_kg_m3: float | None = None
    """A sidecar's density; None: the dataset's ``density_kg_m3``."""
    area: RegionSpec | None = None
    """A sidecar's grasping area; None: the dataset's spec file entry, else the whole surface."""
    friction: float | None = None
    """A sidecar's Coulomb friction of the object (static and dynamic); None: ``sim.object_*_friction``."""
    published_size: tuple[float, float, float] | None = None
    """Extents the dataset publishes (BOP ``models_info.json``, YCB's google_16k models), mm; the loaded mesh
    must match."""
    published_faces: int | None = None
    """Face count the dataset publishes for this file (YCB google_16k); the file must hold exactly that many."""
    published_where: str = "models_info.json"
    """Where ``published_size`` comes from (said when the mesh disagrees with it)."""
    units_hint: str = ""
    """Where a user sets the units of this object (said when its size is implausible); "" if fixed."""
    notes: tuple[str, ...] = ()
    """What was assumed or read for this object (units, mass, area, symmetries), for the summary and log."""

    @property
    def files(self) -> tuple[Path, ...]:
        """The mesh files of its parts."""
        return tuple(p.file for p in self.parts if p.file is not None)
