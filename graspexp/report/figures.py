"""Figures of the planner's stages, in the manner of the paper's Figs. 3-9, 12 and 14, drawn from a plan's
:class:`graspexp.planning.details.PaperDetails` (``python -m graspexp figures``).

Per object: ``fig03_cloud.png`` (the complete point cloud), ``fig04_area.png`` (grasping area red, the rest
blue), ``fig05_clusters.png`` (the K clusters in colours, centres as black-ringed dots), ``fig06_paths.png``
(grasping paths of every cluster, one in ``PATH_STRIDE`` of the M drawn), ``fig07_main_axis.png`` (the
area's PCA main axis), ``fig08_removed_paths.png`` (the support plane, kept paths green, removed grey) and
``fig09_grasp_pose.png`` (the chosen pose, X red, Y green, Z blue, its path and the finger opening); an
overview grid of the areas (Figs. 12, 14).
"""

import math
from collections.abc import Sequence
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from graspexp.config.gripper import GripperConfig  # noqa: E402
from graspexp.grippers import GripperGeometry  # noqa: E402
from graspexp.planning.request import PlanResult  # noqa: E402

PATH_STRIDE = 8
"""Draw one path in this many (256 paths per cluster would hide the object)."""
AREA_COLOUR, REST_COLOUR = "tab:red", "tab:blue"
POINT_SIZE = 2.0
FIG_SIZE_IN = (5.5, 5.5)
DPI = 130


def _axes(fig, spec=(1, 1, 1), title=""):
    ax = fig.add_subplot(*spec, projection="3d")
    ax.set_title(title, fontsize=9)
    ax.set_xlabel("x (m)", fontsize=7)
    ax.set_ylabel("y (m)", fontsize=7)
    ax.set_zlabel("z (m)", fontsize=7)
    ax.tick_params(labelsize=6)
    return ax


def _equal_aspect(ax, pts: np.ndarray) -> None:
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    mid, half = (lo + hi) / 2, max(float((hi - lo).max()) / 2, 1e-3)
    for setter, m in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), mid, strict=True):
        setter(m - half, m + half)
    ax.set_box_aspect((1, 1, 1))


def _scatter(ax, pts, colour, size=POINT_SIZE, alpha=0.8, **kw):
    ax.scatter(
        pts[:, 0], pts[:, 1], pts[:, 2], s=size, c=colour, alpha=alpha, depthshade=False, linewidths=0, **kw
    )


def _split_cloud(ax, det, rest_alpha=0.25):
    cloud, mask = det.cloud, det.area_mask
    _scatter(ax, cloud[~mask], REST_COLOUR, alpha=rest_alpha)
    _scatter(ax, cloud[mask], AREA_COLOUR)


def _table(ax, det, extent_pts):
    lo, hi = extent_pts[:, :2].min(axis=0), extent_pts[:, :2].max(axis=0)
    xx, yy = np.meshgrid([lo[0], hi[0]], [lo[1], hi[1]])
    ax.plot_surface(xx, yy, np.full_like(xx, float(det.table_z)), color="tab:blue", alpha=0.18, linewidth=0)


def _cluster_colours(k: int):
    cmap = plt.get_cmap("tab10")
    return [cmap(j % 10) for j in range(k)]


def _path_lines(ax, det, which, colour, **kw):
    """Draw the (k, p) pairs of ``which`` (a (K, M) bool mask, subsampled) as sphere-point -> centre lines."""
    r = float(det.sphere_radius)
    centers, dirs = det.centers, det.directions
    stride = np.zeros(dirs.shape[1], dtype=bool)
    stride[::PATH_STRIDE] = True
    for k, p in zip(*np.nonzero(which & stride), strict=True):
        a = centers[k] - r * dirs[k, p]
        ax.plot(*np.stack([a, centers[k]]).T, color=colour(k) if callable(colour) else colour, lw=0.6, **kw)


def _sphere_extent(det) -> np.ndarray:
    r = float(det.sphere_radius)
    return np.vstack([det.cloud, det.centers + r, det.centers - r])


def _save(fig, path: Path) -> Path:
    fig.tight_layout()
    fig.savefig(path, dpi=DPI)
    plt.close(fig)
    return path


def draw_object(name: str, result: PlanResult, gripper: GripperConfig, out: Path) -> list[Path]:
    """Write the seven per-object figures of object ``name``'s plan ``result`` (by the paper's planners:
    its details are a :class:`PaperDetails`) with ``gripper`` into ``out``; returns their paths."""
    out.mkdir(parents=True, exist_ok=True)
    det = result.details
    cloud, mask = det.cloud, det.area_mask
    k = len(det.centers)
    colours = _cluster_colours(k)
    written = []

    fig = plt.figure(figsize=FIG_SIZE_IN)
    ax = _axes(fig, title=f"{name}: complete point cloud (N = {len(cloud)})")
    _scatter(ax, cloud, "tab:gray")
    _equal_aspect(ax, cloud)
    written.append(_save(fig, out / "fig03_cloud.png"))

    fig = plt.figure(figsize=FIG_SIZE_IN)
    ax = _axes(fig, title=f"{name}: grasping area (red, {int(mask.sum())} points) and the rest (blue)")
    _split_cloud(ax, det, rest_alpha=0.5)
    _equal_aspect(ax, cloud)
    written.append(_save(fig, out / "fig04_area.png"))

    fig = plt.figure(figsize=FIG_SIZE_IN)
    ax = _axes(fig, title=f"{name}: K = {k} clusters and their centres")
    _scatter(ax, cloud[~mask], "lightgray", alpha=0.3)
    area, labels = cloud[mask], det.labels
    for j in range(k):
        _scatter(ax, area[labels == j], [colours[j]], size=3.0)
    ax.scatter(*det.centers.T, s=60, c=colours, edgecolors="black", linewidths=1.2, depthshade=False)
    _equal_aspect(ax, cloud)
    written.append(_save(fig, out / "fig05_clusters.png"))

    m = det.directions.shape[1]
    fig = plt.figure(figsize=FIG_SIZE_IN)
    ax = _axes(fig, title=f"{name}: M = {m} paths per cluster (1 in {PATH_STRIDE} drawn)")
    _split_cloud(ax, det)
    _path_lines(ax, det, np.ones_like(det.feasible), lambda j: colours[j])
    _equal_aspect(ax, _sphere_extent(det))
    written.append(_save(fig, out / "fig06_paths.png"))

    fig = plt.figure(figsize=FIG_SIZE_IN)
    ax = _axes(fig, title=f"{name}: main axis of the grasping area (PCA)")
    _split_cloud(ax, det)
    a, centroid = det.main_axis, area.mean(axis=0)
    proj = (area - centroid) @ a
    ends = centroid + np.outer([proj.min() - 0.02, proj.max() + 0.02], a)
    ax.plot(*ends.T, color="red", lw=3)
    _equal_aspect(ax, cloud)
    written.append(_save(fig, out / "fig07_main_axis.png"))

    feasible = det.feasible
    fig = plt.figure(figsize=FIG_SIZE_IN)
    n_removed = int((~feasible).sum())
    ax = _axes(
        fig, title=f"{name}: {n_removed} of {feasible.size} paths removed (grey), support plane (blue)"
    )
    _split_cloud(ax, det)
    _path_lines(ax, det, feasible, "tab:green")
    _path_lines(ax, det, ~feasible, "gray", ls="--", alpha=0.6)
    _table(ax, det, _sphere_extent(det))
    _equal_aspect(ax, _sphere_extent(det))
    written.append(_save(fig, out / "fig08_removed_paths.png"))

    written.append(_draw_pose(name, result, gripper, out / "fig09_grasp_pose.png"))
    return written


def _draw_pose(name: str, result: PlanResult, gr: GripperConfig, path: Path) -> Path:
    det, g = result.details, result.grasp
    fig = plt.figure(figsize=FIG_SIZE_IN)
    ax = _axes(fig, title=f"{name}: grasp k={g.cluster} p={g.path}, width {g.width_m * 1000:.0f} mm")
    _split_cloud(ax, det, rest_alpha=0.15)
    o, R = g.pose[:3, 3], g.pose[:3, :3]
    length = 0.6 * float(det.sphere_radius)
    for col, colour in enumerate(("red", "green", "blue")):
        ax.plot(*np.stack([o, o + length * R[:, col]]).T, color=colour, lw=2.5)
    start = o - float(det.sphere_radius) * R[:, 2]
    ax.plot(*np.stack([start, o]).T, color="black", lw=1, ls=":")
    geometry = GripperGeometry.of(gr)
    half_w, root, tip = g.width_m / 2, geometry.root_z_m, geometry.tip_z_m
    y, z = R[:, 1], R[:, 2]
    for side in (-1.0, 1.0):  # fingers: pads +-width/2 along the closing axis, palm face to fingertips
        finger = np.stack([o + side * half_w * y + root * z, o + side * half_w * y + tip * z])
        ax.plot(*finger.T, color="black", lw=3)
    palm = np.stack([o - half_w * y + root * z, o + half_w * y + root * z])
    ax.plot(*palm.T, color="black", lw=3)
    _equal_aspect(ax, np.vstack([det.cloud, start]))
    return _save(fig, path)


def draw_overview(plans: Sequence[tuple[str, PlanResult]], path: Path, title: str) -> Path:
    """Grid of grasping areas (red) over the clouds (blue), one panel per (object name, plan) (Figs. 12,
    14)."""
    cols = min(3, len(plans))
    rows = math.ceil(len(plans) / cols)
    fig = plt.figure(figsize=(3.4 * cols, 3.4 * rows))
    for i, (name, result) in enumerate(plans):
        ax = _axes(fig, (rows, cols, i + 1), title=name)
        _split_cloud(ax, result.details, rest_alpha=0.4)
        _equal_aspect(ax, result.details.cloud)
    fig.suptitle(title, fontsize=11)
    return _save(fig, path)
