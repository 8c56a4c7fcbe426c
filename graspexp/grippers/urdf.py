"""A parallel gripper read from a URDF: its palm and finger collision geometry in the gripper frame.

The hand is the palm link (and the links fixed to it) with two prismatic finger joints whose child links
(and the links fixed to them) are the fingers. Each ``<collision>`` element of those links (a box, cylinder,
sphere or mesh file, at its ``<origin>``) is one convex piece: its convex hull. A non-convex finger is
described by several ``<collision>`` elements (e.g. a convex decomposition), as in any URDF for physics.

Gripper frame (as for the box models): +Z approach, +Y closing axis, origin the TCP, midway between the
pads. +Y is the first finger joint's axis (that finger opens towards +Y: the left finger), +Z the
configured approach axis of the palm link made orthogonal to +Y, +X = Y x Z. A finger's own frame is the
gripper frame moved so that its pad (the finger's innermost point along the closing axis) lies on y = 0:
with the fingers ``w`` apart the left finger's frame sits at ``+w/2`` along Y, the right one's at ``-w/2``.
The stroke is the pads' gap with both joints at zero plus twice the smaller upper joint limit.
"""

import functools
import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path

import numpy as np

PALM, LEFT, RIGHT = 0, 1, 2
"""Index of the part a piece belongs to: the palm and the left (+Y) and right (-Y) fingers."""
SLIDE = (0.0, 1.0, -1.0)
"""Per part: the sign with which half the opening moves it along +Y."""
MAX_AXIS_COS = 0.1
"""The approach axis may be at most this cosine off perpendicular to the closing axis."""


class UrdfError(ValueError):
    """A URDF that does not describe a parallel gripper (message in one line, naming the file)."""


@dataclass(frozen=True, eq=False)
class HandMeshes:
    """Collision geometry of a URDF gripper in the gripper frame (module doc), metres.

    Compared and hashed by identity: :func:`load_hand` returns one instance per file and settings.
    """

    hulls: tuple[np.ndarray, ...]
    """(V_i, 3) float64 vertices of each convex piece: the palm's in the gripper frame, a finger's in its
    own frame (the gripper frame with the fingers closed to zero opening)."""
    hull_parts: tuple[int, ...]
    """Part of each piece: :data:`PALM`, :data:`LEFT` or :data:`RIGHT`."""
    meshes: tuple[tuple[int, np.ndarray, np.ndarray], ...]
    """(part, (V, 3) float64 vertices, (F, 3) int64 faces) of each collision element as the URDF gives it
    (the real, possibly non-convex shape), in the same frames as ``hulls``: for drawing."""
    max_width_m: float
    """Largest opening between the pads the joints' limits allow, m."""
    sources: tuple[tuple[Path, int, int], ...]
    """(path, mtime ns, size) of each mesh file read: a cached hand whose files changed is read again."""

    def part_vertices(self, part: int) -> np.ndarray:
        """(V, 3) all hull vertices of one part, its own frame, m."""
        return np.concatenate([h for h, p in zip(self.hulls, self.hull_parts, strict=True) if p == part])


@dataclass(frozen=True)
class _Joint:
    name: str
    kind: str
    parent: str
    child: str
    origin: np.ndarray
    axis: np.ndarray
    upper: float


def _floats(text: str | None, n: int, default: float, where: str) -> np.ndarray:
    if text is None:
        return np.full(n, default)
    try:
        values = np.array([float(v) for v in text.split()], dtype=np.float64)
    except ValueError:
        raise UrdfError(f"{where}: expected {n} numbers, got {text!r}") from None
    if len(values) != n or not np.all(np.isfinite(values)):
        raise UrdfError(f"{where}: expected {n} finite numbers, got {text!r}")
    return values


def _origin(element: ET.Element | None, where: str) -> np.ndarray:
    """(4, 4) transform of an ``<origin xyz rpy>`` (rpy: fixed-axis roll x, pitch y, yaw z), metres."""
    out = np.eye(4)
    if element is None:
        return out
    x, y, z = _floats(element.get("xyz"), 3, 0.0, where)
    r, p, w = _floats(element.get("rpy"), 3, 0.0, where)
    cr, sr, cp, sp, cw, sw = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(w), math.sin(w)
    out[:3, :3] = [
        [cw * cp, cw * sp * sr - sw * cr, cw * sp * cr + sw * sr],
        [sw * cp, sw * sp * sr + cw * cr, sw * sp * cr - cw * sr],
        [-sp, cp * sr, cp * cr],
    ]
    out[:3, 3] = [x, y, z]
    return out


def _mesh_path(filename: str, urdf: Path) -> Path:
    """The file a ``<mesh filename>`` names: relative to the URDF's folder; ``package://pkg/rest`` is looked
    up as ``rest`` or ``pkg/rest`` in the URDF's folder and its parents."""
    if filename.startswith("file://"):
        filename = filename[len("file://") :]
    if not filename.startswith("package://"):
        return urdf.parent / filename
    pkg, _, rest = filename[len("package://") :].partition("/")
    for folder in (urdf.parent, *urdf.parent.parents):
        for candidate in (folder / rest, folder / pkg / rest):
            if candidate.is_file():
                return candidate
    return urdf.parent / rest


def _geometry(element: ET.Element, urdf: Path, where: str, sources: list[Path]):
    """The trimesh.Trimesh of a ``<geometry>`` element, its own frame, metres; a mesh file read is appended
    to ``sources``."""
    import trimesh  # here, not at the top: only a URDF gripper needs it, and the box models load fast

    shape = next(iter(element), None)
    if shape is None:
        raise UrdfError(f"{where}: empty <geometry>")
    if shape.tag == "box":
        return trimesh.creation.box(extents=_floats(shape.get("size"), 3, math.nan, where + " box size"))
    if shape.tag == "cylinder":
        radius = float(_floats(shape.get("radius"), 1, math.nan, where + " radius")[0])
        length = float(_floats(shape.get("length"), 1, math.nan, where + " length")[0])
        return trimesh.creation.cylinder(radius=radius, height=length, sections=32)
    if shape.tag == "sphere":
        radius = float(_floats(shape.get("radius"), 1, math.nan, where + " radius")[0])
        return trimesh.creation.icosphere(subdivisions=2, radius=radius)
    if shape.tag == "mesh":
        path = _mesh_path(shape.get("filename", ""), urdf).resolve()
        sources.append(path)
        if not path.is_file():
            raise UrdfError(f"{where}: mesh file {path} not found")
        try:
            mesh = trimesh.load(path, force="mesh", skip_materials=True)
        except Exception as exc:  # trimesh raises many types for unreadable files
            raise UrdfError(f"{where}: cannot read mesh {path}: {exc}") from None
        if len(mesh.vertices) < 4:
            raise UrdfError(f"{where}: mesh {path} has fewer than 4 vertices")
        mesh.apply_scale(_floats(shape.get("scale"), 3, 1.0, where + " mesh scale"))
        return mesh
    raise UrdfError(f"{where}: unsupported geometry <{shape.tag}>")


def _parse(urdf: Path) -> tuple[dict[str, ET.Element], dict[str, _Joint]]:
    try:
        root = ET.parse(urdf).getroot()
    except (OSError, ET.ParseError) as exc:
        raise UrdfError(f"cannot read {urdf}: {exc}") from None
    if root.tag != "robot":
        raise UrdfError(f"{urdf} is not a URDF (its root element is <{root.tag}>, not <robot>)")
    links = {link.get("name", ""): link for link in root.findall("link")}
    joints = {}
    for j in root.findall("joint"):
        name = j.get("name", "")
        where = f"{urdf} joint {name!r}"
        parent, child, limit = j.find("parent"), j.find("child"), j.find("limit")
        if parent is None or child is None:
            raise UrdfError(f"{where} lacks <parent> or <child>")
        axis = _floats(j.find("axis").get("xyz") if j.find("axis") is not None else None, 3, 0.0, where)
        axis = axis if np.any(axis) else np.array([1.0, 0.0, 0.0])
        upper = math.nan if limit is None else float(_floats(limit.get("upper"), 1, math.nan, where)[0])
        joints[name] = _Joint(
            name,
            j.get("type", ""),
            parent.get("link", ""),
            child.get("link", ""),
            _origin(j.find("origin"), where),
            axis / np.linalg.norm(axis),
            upper,
        )
    return links, joints


def _rigid_group(link: str, joints: dict[str, _Joint]) -> dict[str, np.ndarray]:
    """``link`` and every link fixed to it below it: name -> (4, 4) pose in ``link``'s frame."""
    out = {link: np.eye(4)}
    todo = [link]
    while todo:
        parent = todo.pop()
        for j in joints.values():
            if j.parent == parent and j.kind == "fixed" and j.child not in out:
                out[j.child] = out[parent] @ j.origin
                todo.append(j.child)
    return out


def _finger_joints(
    names: tuple[str, ...] | None, joints: dict[str, _Joint], links, urdf: Path
) -> list[_Joint]:
    """The two finger joints: those named, else the prismatic joints whose child carries collision geometry."""
    if names is not None:
        if len(names) != 2:
            raise UrdfError(f"gripper.urdf_finger_joints must name 2 joints of {urdf}, got {list(names)}")
        missing = [n for n in names if n not in joints]
        if missing:
            raise UrdfError(f"{urdf} has no joint {missing[0]!r}; its joints: {', '.join(joints)}")
        chosen = [joints[n] for n in names]
    else:
        prismatic = [j for j in joints.values() if j.kind == "prismatic"]
        chosen = [j for j in prismatic if any(True for _ in _collisions_of(j.child, joints, links))]
        if len(chosen) != 2:
            raise UrdfError(
                f"{urdf}: expected 2 prismatic finger joints (with collision geometry below them), found "
                f"{len(chosen)} ({', '.join(j.name for j in prismatic) or 'no prismatic joint'}); "
                "name them with gripper.urdf_finger_joints=[left,right]"
            )
    for j in chosen:
        if j.kind != "prismatic":
            raise UrdfError(f"{urdf} joint {j.name!r} is {j.kind!r}; finger joints must be prismatic")
        if not math.isfinite(j.upper):
            raise UrdfError(f"{urdf} joint {j.name!r} has no <limit upper=...>")
    return chosen


def _collisions_of(link: str, joints: dict[str, _Joint], links: dict[str, ET.Element]):
    """(element, (4, 4) pose in ``link``'s frame) of every <collision> of ``link``'s rigid group."""
    for name, pose in _rigid_group(link, joints).items():
        element = links.get(name)
        for c in element.findall("collision") if element is not None else ():
            yield c, pose @ _origin(c.find("origin"), f"link {name!r} collision")


def _part_meshes(link: str, pose: np.ndarray, links, joints, urdf: Path, sources: list[Path]) -> list:
    """trimesh.Trimesh of each collision element of ``link``'s rigid group, in the frame where the link sits
    at ``pose`` (4, 4)."""
    if link not in links:
        raise UrdfError(f"{urdf} has no link {link!r}; its links: {', '.join(links)}")
    out = []
    for c, local in _collisions_of(link, joints, links):
        element = c.find("geometry")
        if element is None:
            raise UrdfError(f"{urdf} link {link!r}: <collision> without <geometry>")
        mesh = _geometry(element, urdf, f"{urdf} link {link!r}", sources)
        out.append(mesh.apply_transform(pose @ local))
    return out


def load_hand(
    urdf: str,
    palm_link: str | None,
    finger_joints: tuple[str, ...] | None,
    approach_axis: tuple[float, float, float],
    tcp_m: tuple[float, float, float] | None,
    tcp_from_tip_m: float,
) -> HandMeshes:
    """The gripper of file ``urdf`` (module doc); :class:`UrdfError` for a file that is not one.

    palm_link : the palm link (None: the finger joints' parent); finger_joints : (left, right) joint names
    (None: found); approach_axis : (3,) +Z in the palm link's frame; tcp_m : (3,) TCP in the palm link's
    frame, m (its closing-axis component is replaced by the pads' middle; None: centred on the fingers'
    width, ``tcp_from_tip_m`` behind the fingertips). Cached per file state and settings.
    """
    path = Path(urdf).expanduser().resolve()
    hand = _cached_hand(path, palm_link, finger_joints, approach_axis, tcp_m, tcp_from_tip_m)
    if hand.sources != _file_states(hand.sources):  # a mesh file changed since: read everything again
        _load_hand.cache_clear()
        hand = _cached_hand(path, palm_link, finger_joints, approach_axis, tcp_m, tcp_from_tip_m)
    return hand


def _file_states(files) -> tuple:
    """((path, mtime_ns, size) of each file of ``files`` ((path, ...) tuples); -1s for a missing one."""
    out = []
    for path, *_ in files:
        try:
            st = path.stat()
            out.append((path, st.st_mtime_ns, st.st_size))
        except OSError:
            out.append((path, -1, -1))
    return tuple(out)


def _cached_hand(path: Path, *settings) -> HandMeshes:
    try:
        stat = path.stat()
    except OSError:
        raise UrdfError(f"{path} not found") from None
    return _load_hand(path, stat.st_mtime_ns, stat.st_size, *settings)


@functools.lru_cache(maxsize=8)
def _load_hand(
    path, _mtime_ns, _size, palm_link, finger_joints, approach_axis, tcp_m, tcp_from_tip_m
) -> HandMeshes:
    links, joints = _parse(path)
    left, right = _finger_joints(finger_joints, joints, links, path)
    palm = palm_link or left.parent
    palm_group = _rigid_group(palm, joints)
    for j in (left, right):
        if j.parent not in palm_group:
            raise UrdfError(
                f"{path} joint {j.name!r} moves from link {j.parent!r}, not from the palm {palm!r}"
            )
    poses = {j.name: palm_group[j.parent] @ j.origin for j in (left, right)}
    y = poses[left.name][:3, :3] @ left.axis
    if float(poses[right.name][:3, :3] @ right.axis @ y) > -0.99:
        raise UrdfError(f"{path} joints {left.name!r} and {right.name!r} do not open in opposite directions")
    z = np.asarray(approach_axis, dtype=np.float64)
    if not np.linalg.norm(z) > 0 or abs(z @ y) > MAX_AXIS_COS * np.linalg.norm(z):
        raise UrdfError(
            f"gripper.urdf_approach_axis={list(approach_axis)} is not perpendicular to the closing axis "
            f"{np.round(y, 3).tolist()} of {path} (palm link frame)"
        )
    z = z - (z @ y) * y
    z /= np.linalg.norm(z)
    rot = np.stack([np.cross(y, z), y, z], axis=1)  # columns X, Y, Z of the gripper frame, palm frame
    sources: list[Path] = []
    parts = {
        PALM: _part_meshes(palm, np.eye(4), links, joints, path, sources),
        LEFT: _part_meshes(left.child, poses[left.name], links, joints, path, sources),
        RIGHT: _part_meshes(right.child, poses[right.name], links, joints, path, sources),
    }
    for part, name in ((PALM, palm), (LEFT, left.child), (RIGHT, right.child)):
        if not parts[part]:
            raise UrdfError(f"{path} link {name!r} has no collision geometry")
    in_grip = {p: [m.vertices @ rot for m in ms] for p, ms in parts.items()}  # rotated, palm origin
    fingers = np.concatenate(in_grip[LEFT] + in_grip[RIGHT])
    inner_left = min(v[:, 1].min() for v in in_grip[LEFT])
    inner_right = max(v[:, 1].max() for v in in_grip[RIGHT])
    gap = inner_left - inner_right
    if tcp_m is None:
        tcp = np.array(
            [(fingers[:, 0].min() + fingers[:, 0].max()) / 2, 0.0, fingers[:, 2].max() - tcp_from_tip_m]
        )
    else:
        tcp = np.asarray(tcp_m, dtype=np.float64) @ rot
    tcp[1] = (inner_left + inner_right) / 2
    shift = {PALM: tcp, LEFT: tcp + [0.0, gap / 2, 0.0], RIGHT: tcp - [0.0, gap / 2, 0.0]}
    hulls, hull_parts, meshes = [], [], []
    link_names = {PALM: palm, LEFT: left.child, RIGHT: right.child}
    for part, ms in parts.items():
        for m, v in zip(ms, in_grip[part], strict=True):
            local = v - shift[part]
            try:
                hull = m.convex_hull
            except Exception as exc:  # qhull on a flat or degenerate piece
                raise UrdfError(
                    f"{path} link {link_names[part]!r}: a collision piece has no 3-D hull: {exc}"
                ) from None
            hulls.append(np.asarray(hull.vertices, dtype=np.float64) @ rot - shift[part])
            hull_parts.append(part)
            meshes.append((part, local, np.asarray(m.faces, dtype=np.int64)))
    max_width = gap + 2.0 * min(left.upper, right.upper)
    if not max_width > 0:
        raise UrdfError(f"{path}: the finger joints' upper limits give no opening (stroke {max_width:.4g} m)")
    states = _file_states(tuple((p,) for p in dict.fromkeys(sources)))
    return HandMeshes(tuple(hulls), tuple(hull_parts), tuple(meshes), float(max_width), states)
