"""An object's grasping area shown: a four-view figure (the mesh shaded grey, faces whose nearest surface
sample is in the area red; axes in mm, object frame), its facts one a line, and a commented folder-dataset
sidecar template filled in with the object's values (``python -m graspexp area``)."""

from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import trimesh  # noqa: E402
from matplotlib.collections import PolyCollection  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402
from omegaconf import DictConfig  # noqa: E402
from scipy.spatial import cKDTree  # noqa: E402

from graspexp.datasets import ObjectModel  # noqa: E402
from graspexp.datasets.catalog import object_source  # noqa: E402
from graspexp.datasets.folder import UNITS  # noqa: E402

MM = 1000.0
"""Metres to millimetres."""
VIEWS: dict[str, tuple[tuple[float, float, float], tuple[float, float, float]]] = {
    "front (from -y)": ((0.0, -1.0, 0.0), (0.0, 0.0, 1.0)),
    "side (from +x)": ((1.0, 0.0, 0.0), (0.0, 0.0, 1.0)),
    "top (from +z)": ((0.0, 0.0, 1.0), (0.0, 1.0, 0.0)),
    "iso (from +x -y +z)": ((1.0, -1.0, 1.0), (0.0, 0.0, 1.0)),
}
"""View name -> (direction from the object to the camera, world direction that points up on screen)."""
AXIS_NAMES = ("x", "y", "z")
REST_RGB, AREA_RGB = np.array([0.80, 0.80, 0.80]), np.array([0.86, 0.16, 0.14])
NEIGHBOURS = 8
"""Surface samples considered per face when colouring the area."""
MAX_FACES = 30_000
"""A finer mesh is decimated to this many faces before it is drawn."""
EDGE_PER_SPACING = 1.5
"""Faces are split until no edge is longer than this many mean sample spacings (coarse meshes)..."""
RESOLVED_SAMPLES = 2048
"""...counting at most this many samples: a denser cloud does not refine the faces (drawing time)."""
FIG_SIZE_IN, DPI = (10.0, 10.0), 100


def render_mesh(model: ObjectModel) -> tuple[trimesh.Trimesh, np.ndarray]:
    """The mesh to draw (object frame, metres) and its (F,) bool faces in the area.

    A mesh of more than ``MAX_FACES`` faces is decimated; faces with an edge longer than
    ``EDGE_PER_SPACING`` mean sample spacings (sqrt(surface area / N)) are split, so that a coarse
    primitive's long faces follow the area. A face is in the area when its surface sample is: among the
    ``NEIGHBOURS`` samples nearest to its centre, the nearest whose normal faces the same side (so the
    inside of a thin wall keeps its own colour), else the nearest.
    """
    mesh = model.mesh
    if len(mesh.faces) > MAX_FACES:
        mesh = mesh.simplify_quadric_decimation(face_count=MAX_FACES)
    max_edge_m = EDGE_PER_SPACING * np.sqrt(mesh.area / min(len(model.points), RESOLVED_SAMPLES))
    fine = trimesh.Trimesh(*_split_long_edges(mesh.vertices, mesh.faces, max_edge_m), process=False)
    _, near = cKDTree(model.points).query(fine.triangles_center, k=min(NEIGHBOURS, len(model.points)))
    near = near.reshape(len(fine.faces), -1)
    same_side = np.einsum("fkj,fj->fk", model.normals[near], fine.face_normals) > 0
    nearest = near[np.arange(len(near)), np.argmax(same_side, axis=1)]
    return fine, model.area_mask[nearest]


def _split_long_edges(
    vertices: np.ndarray, faces: np.ndarray, max_edge_m: float
) -> tuple[np.ndarray, np.ndarray]:
    """Bisect every face's longest edge until no edge exceeds ``max_edge_m`` (winding kept; the new
    vertices are not shared, which a drawing does not mind)."""
    vertices, faces = np.asarray(vertices, dtype=float), np.asarray(faces)
    while True:
        corners = vertices[faces]
        lengths = np.linalg.norm(np.roll(corners, -1, axis=1) - corners, axis=2)  # edge i: corner i -> i+1
        longest = lengths.argmax(axis=1)
        split = lengths[np.arange(len(faces)), longest] > max_edge_m
        if not split.any():
            return vertices, faces
        a, b, c = np.take_along_axis(faces[split], (longest[split, None] + np.arange(3)) % 3, axis=1).T
        mid = len(vertices) + np.arange(len(a))
        vertices = np.vstack([vertices, (vertices[a] + vertices[b]) / 2])
        faces = np.vstack([faces[~split], np.stack([a, mid, c], axis=1), np.stack([mid, b, c], axis=1)])


def _projection(view: str) -> tuple[np.ndarray, np.ndarray]:
    """(2, 3) rows: screen right and up directions; (3,) direction towards the camera (unit)."""
    towards, up = (np.asarray(v, dtype=float) for v in VIEWS[view])
    towards /= np.linalg.norm(towards)
    right = np.cross(up, towards)
    right /= np.linalg.norm(right)
    return np.stack([right, np.cross(towards, right)]), towards


def _draw_view(ax, mesh: trimesh.Trimesh, in_area: np.ndarray, view: str) -> None:
    """Orthographic view, painter's order (far faces first), back faces culled, Lambert shading."""
    screen, towards = _projection(view)
    normals = mesh.face_normals
    front = np.flatnonzero(normals @ towards > 0)
    front = front[np.argsort(mesh.triangles_center[front] @ towards)]
    light = towards + 0.4 * screen[0] + 0.6 * screen[1]
    shade = 0.45 + 0.55 * np.clip(normals[front] @ (light / np.linalg.norm(light)), 0.0, 1.0)
    colours = np.where(in_area[front, None], AREA_RGB, REST_RGB) * shade[:, None]
    polygons = mesh.triangles[front] @ screen.T * MM
    ax.add_collection(PolyCollection(polygons, facecolors=colours, edgecolors=colours, linewidths=0.3))
    corners = np.asarray(list(np.ndindex(2, 2, 2)))
    extent = mesh.bounds[corners, [0, 1, 2]] @ screen.T * MM
    pad = 0.05 * float(np.ptp(extent, axis=0).max())
    ax.set_xlim(extent[:, 0].min() - pad, extent[:, 0].max() + pad)
    ax.set_ylim(extent[:, 1].min() - pad, extent[:, 1].max() + pad)
    ax.set_aspect("equal")
    ax.set_title(view, fontsize=10)
    labels = [AXIS_NAMES[int(np.argmax(np.abs(d)))] for d in screen]
    if all(np.isclose(np.abs(d).max(), 1.0) for d in screen):
        ax.set_xlabel(f"{labels[0]} (mm)")
        ax.set_ylabel(f"{labels[1]} (mm)")
    else:
        ax.set_xlabel("mm, in the view plane")
        _draw_triad(ax, screen, extent, pad)


def _draw_triad(ax, screen: np.ndarray, extent: np.ndarray, pad: float) -> None:
    """The object frame's axes (x red, y green, z blue) in the lower left corner of a view."""
    origin = extent.min(axis=0) + pad
    for axis, colour in zip(np.eye(3), ("red", "green", "blue"), strict=True):
        tip = origin + 2 * pad * (screen @ axis)
        ax.annotate("", tip, origin, arrowprops={"arrowstyle": "->", "color": colour, "lw": 1.5})
        ax.text(*tip, AXIS_NAMES[int(np.argmax(axis))], color=colour, fontsize=9)


def draw_area(model: ObjectModel, mesh: trimesh.Trimesh, in_area: np.ndarray, path: Path) -> Path:
    """Write the four-view PNG of the grasping area to ``path``; returns it."""
    fig, axes = plt.subplots(2, 2, figsize=FIG_SIZE_IN)
    for ax, view in zip(axes.flat, VIEWS, strict=True):
        _draw_view(ax, mesh, in_area, view)
    fig.suptitle(
        f"{model.name} ({model.dataset}): grasping area in red, {model.area_mask.mean():.1%} of "
        f"{len(model.points)} surface samples"
    )
    fig.legend(
        handles=[Patch(color=AREA_RGB, label="grasping area"), Patch(color=REST_RGB, label="rest")],
        loc="lower center",
        ncol=2,
    )
    fig.tight_layout(rect=(0, 0.03, 1, 0.97))
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return path


def _extents_mm(bounds_m: np.ndarray) -> str:
    size = (bounds_m[1] - bounds_m[0]) * MM
    ranges = ", ".join(
        f"{a} {lo:.1f}..{hi:.1f}" for a, lo, hi in zip(AXIS_NAMES, *(bounds_m * MM), strict=True)
    )
    return f"{size[0]:.1f} x {size[1]:.1f} x {size[2]:.1f} mm ({ranges})"


def summary(model: ObjectModel, mesh: trimesh.Trimesh, in_area: np.ndarray) -> list[str]:
    """The printed facts, one a line; extents are axis-aligned, object frame, mm."""
    area = model.area_points
    share = float(model.area_mask.mean())
    face_share = float(mesh.area_faces[in_area].sum() / mesh.area)
    return [
        f"object: {model.name} (dataset {model.dataset}){f', {model.source}' if model.source else ''}",
        f"points: {len(model.points)} surface samples, {len(area)} in the area",
        f"area share of the samples: {share:.2%} (area_mask.mean() = {share:.4f})",
        f"area share of the surface area: {face_share:.2%} (mesh faces whose nearest sample is in the area)",
        f"object extents (mesh bounds, x y z): {_extents_mm(model.mesh.bounds)}",
        f"area extents (its samples, x y z): {_extents_mm(np.stack([area.min(axis=0), area.max(axis=0)]))}",
        f"mass: {model.mass_kg:.4g} kg",
    ]


def _vector(values: np.ndarray, digits: int = 4) -> str:
    return "[" + ", ".join(f"{v:.{digits}f}" for v in values) + "]"


def _units_line(cfg: DictConfig, model: ObjectModel) -> str:
    """The sidecar's ``units:`` line: how the object's mesh file was read (a URDF sets its own scale)."""
    if model.source.lower().endswith(".urdf"):
        return "# units: none for a URDF object; its <mesh scale> sets them."
    parts = object_source(cfg.dataset, model.name).parts
    scale = parts[0].scale if parts else 1.0
    return f"units: {next((name for name, f in UNITS.items() if f == scale), f'{scale:g}')}"


def sidecar_template(model: ObjectModel, cfg: DictConfig) -> str:
    """A commented folder-dataset sidecar (``NAME.yaml``) with the object's values, to edit: its units
    as its file was read, its mass, its friction if it has one, and a relative area to start from."""
    lo, hi = model.mesh.bounds
    area = model.area_points
    volume_kind = "enclosed" if model.mesh.is_watertight else "convex hull's"
    volume_m3 = model.mesh.volume if model.mesh.is_watertight else model.mesh.convex_hull.volume
    density = model.mass_kg / volume_m3
    friction = (
        f"# friction: {cfg.sim.object_static_friction}"
        if model.friction is None
        else f"friction: {model.friction:g}"
    )
    origin = f"{model.dataset}/{model.name}" + (f":\n#   {model.source}" if model.source else "")
    rel = (np.stack([area.min(axis=0), area.max(axis=0)]) - lo) / np.where(hi > lo, hi - lo, 1.0)
    return f"""\
# Sidecar of {model.name} for a folder dataset: save it as DIR/{model.name}.yaml beside the mesh file.
# Started by `python -m graspexp area` from {origin}

# Units of the mesh file: m, cm, mm, or a number (file units -> metres); as it was read here.
{_units_line(cfg, model)}

# Mass of the object in kg (as loaded: {model.mass_kg:.4g} kg); or density_kg_m3 instead, not both
# (the same mass: {density:.0f} kg/m^3 over the {volume_kind} volume, {volume_m3 * 1e6:.0f} cm^3).
mass_kg: {model.mass_kg:.4g}
# density_kg_m3: {density:.0f}

# Coulomb friction of the object, static and dynamic; omit it to keep the job's sim.object_*_friction
# (static {cfg.sim.object_static_friction}, dynamic {cfg.sim.object_dynamic_friction}).
{friction}

# Grasping area, in the format of graspexp/datasets/regions.py: ops applied in order (keep_box,
# exclude_box, keep_halfspace, keep_sphere, keep_cylinder, keep_all, ...), or meshlab_ply: FILE.
# relative: true gives coordinates as fractions 0..1 of the mesh bounds (object frame, m):
#   min {_vector(lo)}, max {_vector(hi)}, extents {_vector(hi - lo)}
# The current area ({model.area_mask.mean():.1%} of the samples) spans, relative:
#   min {_vector(rel[0], 3)}, max {_vector(rel[1], 3)}
area:
  note: middle band of the height (25 % to 75 %), all sides; edit
  relative: true
  ops:
    - keep_box: {{min: [0, 0, 0.25], max: [1, 1, 0.75]}}
"""
