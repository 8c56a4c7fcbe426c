"""A folder of your own objects (``dataset=folder dataset.root=DIR``).

Every mesh file in ``DIR`` (:data:`MESH_SUFFIXES`: whatever trimesh reads as a surface) is an object named
by its file stem, and so is every single-link URDF ``DIR/NAME.urdf`` (its collision geometry: meshes with
their ``scale`` and ``<origin>``, boxes, cylinders, spheres; its ``<inertial>`` mass); a mesh file a URDF
uses is then not a second object. An optional sidecar ``DIR/NAME.yaml`` says what the file cannot::

    units: mm              # m, cm, mm, or a number: the factor from file units to metres
    mass_kg: 0.12          # or density_kg_m3: 950 (not both)
    friction: 0.8          # Coulomb friction of the object's surface (static and dynamic)
    area:                  # the grasping area: a region spec (graspexp/datasets/regions.py)
      relative: true
      ops:
        - keep_box: {min: [0, 0, 0.2], max: [1, 1, 0.8]}
    # or   area: {meshlab_ply: lemon_area.ply}   (the paper's MeshLab route; path relative to DIR)

Without a sidecar: ``dataset.units`` (metres by default), ``dataset.density_kg_m3`` and the whole surface
as the area; each assumption is stated in the run's summary and recorded in every trial's log.
``python -m graspexp.area dataset=folder dataset.root=DIR --object NAME --write-sidecar DIR/NAME.yaml``
renders an object's area and writes a sidecar to start from.
"""

from __future__ import annotations

import functools
import logging
import math
import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from scipy.spatial.transform import Rotation

from graspexp.config import dataset
from graspexp.config.constraints import Interval
from graspexp.core.userinput import UserInputError, inside_folder, object_name_problem, read_user_yaml, shown
from graspexp.datasets.errors import DatasetError, ObjectError
from graspexp.datasets.regions import parse_entry
from graspexp.datasets.source import MeshPart, ObjectSource

log = logging.getLogger(__name__)
MESH_SUFFIXES = (".obj", ".ply", ".stl", ".glb", ".gltf", ".off")
"""Mesh files of a folder dataset (case-insensitive)."""
UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001}
"""Unit names -> metres per file unit."""
MASS_KG = Interval(0, 100, "right", "kg")
"""An object's mass (a sidecar's ``mass_kg``, a URDF's ``<inertial>`` mass), kg: a graspable object."""
SIDECAR_KEYS = ("units", "mass_kg", "density_kg_m3", "friction", "area", "note")
SIDECAR_NUMBERS = {
    "mass_kg": MASS_KG,
    "density_kg_m3": dataset.CONSTRAINTS["density_kg_m3"][0],  # the bounds of dataset.density_kg_m3
    "friction": Interval(0, 5, "right"),
}
"""The numeric sidecar keys and their allowed values."""


@dataclass(frozen=True)
class FolderEntry:
    """One object found in the folder: its mesh file or its URDF."""

    name: str
    file: Path
    urdf: bool


def scan(folder: Path) -> dict[str, FolderEntry]:
    """name -> entry for every mesh file and URDF in ``folder`` (not recursive), sorted by name.

    Raises :class:`DatasetError` for a missing folder, an empty one, or two files with one name.
    """
    if not folder.is_dir():
        raise DatasetError(
            f"folder dataset {folder.resolve()} does not exist (dataset.root); put your mesh files there"
        )
    return _scan_cached(folder.resolve(), folder.stat().st_mtime_ns)


@functools.lru_cache(maxsize=8)
def _scan_cached(folder: Path, _mtime_ns: int) -> dict[str, FolderEntry]:
    files = sorted(p for p in folder.iterdir() if p.is_file() or p.is_symlink())  # a dangling link too
    urdfs = [p for p in files if p.suffix.lower() == ".urdf"]
    used = {f.resolve() for u in urdfs for f in _urdf_mesh_files(u)}
    found: dict[str, FolderEntry] = {}
    invalid = []
    for path in files:
        is_urdf = path.suffix.lower() == ".urdf"
        if not is_urdf and (path.suffix.lower() not in MESH_SUFFIXES or path.resolve() in used):
            continue
        if object_name_problem(path.stem):
            invalid.append(f"{path.name!r} ({object_name_problem(path.stem)})")
            continue
        if path.stem in found:
            raise DatasetError(
                f"two files in {folder} give object {path.stem!r}: {found[path.stem].file.name} and "
                f"{path.name}; rename or move one of them"
            )
        found[path.stem] = FolderEntry(path.stem, path, is_urdf)
    if invalid:  # its name would become a folder of the run: never written under
        log.warning("folder %s: not an object, rename to use: %s", folder, "; ".join(invalid))
    if not found:
        raise DatasetError(
            f"folder dataset {folder} holds no mesh file ({', '.join(MESH_SUFFIXES)}) and no URDF; "
            "put your meshes there or point dataset.root at the folder that holds them"
        )
    return dict(sorted(found.items()))


def object_source(folder: Path, entry: FolderEntry, default_units: str) -> ObjectSource:
    """The :class:`ObjectSource` of one folder object, its sidecar applied."""
    sidecar_path = folder / f"{entry.name}.yaml"
    side = read_sidecar(sidecar_path) if sidecar_path.is_file() else {}
    if entry.file.is_symlink() and not entry.file.exists():
        raise ObjectError(
            f"mesh file {entry.file} is a symbolic link to {os.readlink(entry.file)}, which does not exist"
        )
    notes: list[str] = []
    if entry.urdf:
        parts, urdf_mass = read_urdf(entry.file)
        if "units" in side:
            raise ObjectError(
                f"{sidecar_path}: 'units' does not apply to a URDF object; set <mesh scale> there"
            )
        notes.append(f"geometry: {len(parts)} collision part(s) of {entry.file.name}")
    else:
        units = side.get("units", default_units)
        scale = units_factor(units, f"{sidecar_path}: units" if "units" in side else "dataset.units")
        parts, urdf_mass = (MeshPart(entry.file, scale=scale),), None
        notes.append(f"units: {units} ({sidecar_path.name if 'units' in side else 'dataset.units'})")
    mass = side.get("mass_kg", urdf_mass)
    if "mass_kg" in side:
        notes.append(f"mass: {mass:g} kg ({sidecar_path.name})")
    elif urdf_mass is not None:
        notes.append(f"mass: {mass:g} kg (URDF <inertial>)")
    elif "density_kg_m3" in side:
        notes.append(f"mass: volume x {side['density_kg_m3']:g} kg/m^3 ({sidecar_path.name})")
    else:
        notes.append("mass: volume x dataset.density_kg_m3")
    try:
        area = parse_entry(entry.name, side["area"], sidecar_path) if "area" in side else None
    except DatasetError as err:
        raise ObjectError(str(err)) from None
    if "friction" in side:
        notes.append(f"friction: {side['friction']:g} ({sidecar_path.name})")
    return ObjectSource(
        name=entry.name,
        parts=parts,
        source=str(entry.file.resolve()),
        mass_kg=mass,
        density_kg_m3=side.get("density_kg_m3"),
        area=area,
        friction=side.get("friction"),
        units_hint=(
            f"the <mesh scale> in {entry.file}"
            if entry.urdf
            else f"'units:' in {sidecar_path} (m, cm, mm or a factor), or dataset.units for the whole folder"
        ),
        notes=tuple(notes),
    )


def units_factor(units: Any, what: str) -> float:
    """Metres per file unit for ``units`` (``m``, ``cm``, ``mm`` or a positive number)."""
    if isinstance(units, str) and units in UNITS:
        return UNITS[units]
    try:
        factor = float(units) if not isinstance(units, bool) else math.nan
    except (TypeError, ValueError):
        factor = math.nan
    if not (math.isfinite(factor) and factor > 0):
        raise ObjectError(
            f"{what}={shown(units)} is invalid: expected m, cm, mm or a positive number (metres per file unit)"
        )
    return factor


def read_sidecar(path: Path) -> dict[str, Any]:
    """A sidecar's keys, checked strictly (types, ranges, no unknown or conflicting keys); raises
    :class:`ObjectError` naming the file and the key."""
    try:
        data = read_user_yaml(path, f"sidecar {path}")
    except UserInputError as err:
        raise ObjectError(str(err)) from None
    data = {} if data is None else data
    if not isinstance(data, dict):
        raise ObjectError(f"sidecar {path} must be a mapping of {', '.join(SIDECAR_KEYS)}")
    unknown = sorted(shown(k) for k in data if k not in SIDECAR_KEYS)
    if unknown:
        raise ObjectError(
            f"sidecar {path}: unknown key(s) [{', '.join(unknown)}]; valid keys: {', '.join(SIDECAR_KEYS)}"
        )
    if "mass_kg" in data and "density_kg_m3" in data:
        raise ObjectError(f"sidecar {path}: give mass_kg or density_kg_m3, not both")
    for key, allowed in SIDECAR_NUMBERS.items():
        if key in data and not allowed.accepts(data[key]):
            raise ObjectError(f"sidecar {path}: {key}={shown(data[key])} is invalid: expected {allowed}")
    if "units" in data:
        units_factor(data["units"], f"sidecar {path}: units")
    if "note" in data and not isinstance(data["note"], str):
        raise ObjectError(f"sidecar {path}: note must be text")
    return data


def read_urdf(path: Path) -> tuple[tuple[MeshPart, ...], float | None]:
    """(collision parts, ``<inertial>`` mass or None) of a single-link URDF object. Mesh paths are relative
    to the URDF's folder (``package://NAME/`` and ``file://`` prefixes are stripped)."""
    link = _single_link(path)
    parts = []
    for i, collision in enumerate(link.findall("collision")):
        geometry = collision.find("geometry")
        shape = geometry[0] if geometry is not None and len(geometry) else None
        origin = _origin(collision.find("origin"), path, f"collision {i}")
        if shape is None:
            raise ObjectError(f"URDF {path}: collision {i} has no <geometry>")
        if shape.tag == "mesh":
            parts.append(
                MeshPart(
                    _mesh_file(path, shape), scale=_floats(shape, "scale", 3, path, (1, 1, 1)), origin=origin
                )
            )
        elif shape.tag == "box":
            parts.append(MeshPart(None, ("box", _floats(shape, "size", 3, path)), origin=origin))
        elif shape.tag == "cylinder":
            dims = (_floats(shape, "radius", 1, path)[0], _floats(shape, "length", 1, path)[0])
            parts.append(MeshPart(None, ("cylinder", dims), origin=origin))
        elif shape.tag == "sphere":
            parts.append(MeshPart(None, ("sphere", _floats(shape, "radius", 1, path)), origin=origin))
        else:
            raise ObjectError(f"URDF {path}: collision {i} has unknown geometry <{shape.tag}>")
    if not parts:
        raise ObjectError(f"URDF {path}: link {link.get('name')!r} has no <collision> geometry")
    mass_el = link.find("inertial/mass")
    mass = None if mass_el is None else _floats(mass_el, "value", 1, path)[0]
    if mass is not None and not MASS_KG.accepts(mass):
        raise ObjectError(f"URDF {path}: <inertial><mass value={mass:g}> is invalid: expected {MASS_KG}")
    return tuple(parts), mass


def _urdf_mesh_files(path: Path) -> list[Path]:
    """The mesh files a URDF's collision and visual elements name (for the scan; never raises)."""
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError):
        return []
    return [_resolve(path, m.get("filename", "")) for m in root.iter("mesh") if m.get("filename")]


def _single_link(path: Path) -> ET.Element:
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError) as err:
        raise ObjectError(f"URDF {path} cannot be read: {err}") from None
    links = [link for link in root.findall("link") if link.find("collision") is not None]
    if root.tag != "robot" or len(links) != 1 or root.findall("joint"):
        raise ObjectError(
            f"URDF {path}: an object is a <robot> with one link that has <collision> geometry and no joints; "
            f"found {len(links)} such link(s) and {len(root.findall('joint'))} joint(s)"
        )
    return links[0]


def _resolve(urdf: Path, filename: str) -> Path:
    for prefix in ("file://", "package://"):
        if filename.startswith(prefix):
            filename = filename[len(prefix) :]
            if prefix == "package://":
                filename = filename.split("/", 1)[
                    -1
                ]  # package://<pkg>/<path>: the path, from the URDF folder
    given = Path(filename)
    return given if given.is_absolute() else urdf.parent / given


def _mesh_file(urdf: Path, mesh: ET.Element) -> Path:
    file = _resolve(urdf, mesh.get("filename", ""))
    if not inside_folder(file, urdf.parent):
        raise ObjectError(
            f"URDF {urdf}: mesh filename={shown(mesh.get('filename'))} leaves the URDF's folder; an object's "
            "files are given relative to its folder, inside it"
        )
    if not file.is_file():
        raise ObjectError(f"URDF {urdf}: mesh file {file} (filename={mesh.get('filename')!r}) not found")
    return file


def _floats(el: ET.Element, attr: str, n: int, path: Path, default: tuple | None = None) -> tuple[float, ...]:
    text = el.get(attr)
    if text is None and default is not None:
        return tuple(float(v) for v in default)
    try:
        values = tuple(float(v) for v in (text or "").split())
    except ValueError:
        values = ()
    if len(values) != n or not all(math.isfinite(v) and v > 0 for v in values):
        raise ObjectError(
            f"URDF {path}: <{el.tag} {attr}={shown(text)}> must be {n} finite positive number(s)"
        )
    return values


def _origin(el: ET.Element | None, path: Path, what: str) -> tuple[tuple[float, ...], ...] | None:
    if el is None:
        return None
    try:
        xyz = [float(v) for v in el.get("xyz", "0 0 0").split()]
        rpy = [float(v) for v in el.get("rpy", "0 0 0").split()]
    except ValueError:
        xyz = rpy = []
    if len(xyz) != 3 or len(rpy) != 3 or not all(math.isfinite(v) for v in xyz + rpy):
        raise ObjectError(
            f"URDF {path}: {what} <origin xyz={el.get('xyz')!r} rpy={el.get('rpy')!r}> is invalid"
        )
    pose = np.eye(4)
    pose[:3, :3] = Rotation.from_euler("xyz", rpy).as_matrix()  # URDF rpy: fixed-axis roll, pitch, yaw
    pose[:3, 3] = xyz
    return tuple(tuple(float(v) for v in row) for row in pose)
