"""``planner=vgn``: grasps from the Volumetric Grasping Network (Breyer et al., CoRL 2020) on the camera's
depth views, with the network's own pre- and post-processing.

1. Workspace: VGN's 30 cm cube, axes along the world's, its floor ``TABLE_IN_VOLUME_M`` below the support
   plane (where VGN's table lay) and its centre above the observed target points' centroid.
2. The depth views are fused into a 40^3 TSDF (:mod:`graspexp.planning.learned.tsdf`).
3. One forward pass (:mod:`graspexp.planning.learned.vgn_network`) gives per voxel a quality, a grasp
   orientation and a width.
4. VGN's detection: the quality volume smoothed by a Gaussian, kept only near observed free space,
   widths out of range dropped, thresholded, non-maximum suppressed.
5. Each remaining voxel is a grasp in VGN's frame, converted to graspexp's (:func:`graspexp_from_vgn`);
   candidates that do not hold the target between their pads are dropped; one is chosen.

VGN's grasp frame (the authors' simulated Panda): +Z approach, +Y closing axis (the fingers at y = +-w/2),
origin between the finger roots, the fingertips ``VGN_FINGER_DEPTH_M`` ahead along +Z; a grasp in voxel
(i, j, k) lies at (i, j, k) x voxel length in the workspace frame; the quaternion is (x, y, z, w).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import torch
from scipy import ndimage
from scipy.spatial.transform import Rotation

from graspexp.config import GripperConfig
from graspexp.config.planner.vgn import VgnConfig
from graspexp.grippers import GripperGeometry
from graspexp.planning.grasp import Grasp, NoFeasibleGrasp
from graspexp.planning.learned.tsdf import DepthView, fuse
from graspexp.planning.learned.vgn_network import GRID, VgnNet, load_vgn
from graspexp.planning.request import PlanRequest, PlanResult

SIZE_M = 0.3
"""Edge of VGN's workspace cube, m (6 finger depths; the network was trained on it)."""
VOXEL_M = SIZE_M / GRID
"""Voxel length, m (7.5 mm)."""
TABLE_IN_VOLUME_M = 0.05
"""Height of the support plane above the workspace's floor, m (VGN's table lay at one finger depth)."""
VGN_FINGER_DEPTH_M = 0.05
"""Distance from VGN's grasp origin (between the finger roots) to its fingertips along +Z, m."""
DEPTH_MAX_M = 2.0
"""Depths beyond this are not fused, m (VGN's depth truncation)."""
INSIDE_MIN = 1e-3
"""Encoded TSDF values in (INSIDE_MIN, 0.5) are behind a surface (VGN's mask)."""

_NET: VgnNet | None = None


def network() -> VgnNet:
    """The loaded network, read and verified once per process."""
    global _NET
    if _NET is None:
        _NET = load_vgn()
    return _NET


@dataclass(frozen=True)
class Detections:
    """VGN's candidates in the workspace frame, before the target filter.

    poses : (n, 4, 4) grasp poses in VGN's frame convention, workspace frame, m.
    widths_m : (n,) predicted widths, m.
    quality : (n,) smoothed quality in [0, 1].
    """

    poses: np.ndarray
    widths_m: np.ndarray
    quality: np.ndarray


def infer(net: VgnNet, grid: np.ndarray, threads: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One forward pass on a (40, 40, 40) float32 TSDF: quality (40, 40, 40), quaternions (4, 40, 40, 40)
    (x, y, z, w), widths (40, 40, 40) in voxels, float32."""
    before = torch.get_num_threads()
    torch.set_num_threads(threads)
    try:
        with torch.inference_mode():
            q, r, w = net(torch.from_numpy(np.ascontiguousarray(grid, np.float32))[None, None])
    finally:
        torch.set_num_threads(before)
    return q[0, 0].numpy(), r[0].numpy(), w[0, 0].numpy()


def detect(
    grid: np.ndarray, quality: np.ndarray, rot: np.ndarray, width_vox: np.ndarray, cfg: VgnConfig
) -> Detections:
    """VGN's post-processing of one forward pass (voxel units inside, metres out)."""
    q = quality.astype(np.float64)
    if cfg.quality_sigma_voxels > 0:
        q = ndimage.gaussian_filter(q, sigma=cfg.quality_sigma_voxels, mode="nearest")
    free = grid > 0.5
    behind = (grid > INSIDE_MIN) & (grid < 0.5)
    if cfg.surface_band_voxels > 0:
        near = ndimage.binary_dilation(free, iterations=cfg.surface_band_voxels, mask=~behind)
    else:
        near = free
    width_m = width_vox.astype(np.float64) * VOXEL_M
    keep = near & (width_m >= cfg.min_width_m) & (width_m <= cfg.max_width_m) & (q >= cfg.quality_threshold)
    q = np.where(keep, q, 0.0)
    peak = ndimage.maximum_filter(q, size=cfg.nms_size_voxels)
    idx = np.argwhere(keep & (q == peak))  # C order: deterministic
    poses = np.tile(np.eye(4), (len(idx), 1, 1))
    if len(idx):
        quats = rot[:, idx[:, 0], idx[:, 1], idx[:, 2]].T.astype(np.float64)
        poses[:, :3, :3] = Rotation.from_quat(quats).as_matrix()  # scipy: (x, y, z, w), as VGN
        poses[:, :3, 3] = idx * VOXEL_M
    at = tuple(idx.T)
    return Detections(poses, width_m[at], q[at])


def graspexp_from_vgn(gripper: GripperConfig) -> np.ndarray:
    """(4, 4) pose of graspexp's grasp frame in VGN's: same axes (+Z approach, +Y closing); the origin
    moved along +Z so that both frames put the fingertips at the same place (graspexp's TCP lies
    ``gripper.tcp_from_tip_m`` behind the tips, VGN's origin ``VGN_FINGER_DEPTH_M`` behind them)."""
    T = np.eye(4)
    T[2, 3] = VGN_FINGER_DEPTH_M - GripperGeometry.of(gripper).tip_z_m
    return T


def target_points_between_pads(
    pose: np.ndarray, opening_m: float, gripper: GripperConfig, points: np.ndarray
) -> int:
    """How many of ``points`` (n, 3) world lie between the pads of a graspexp grasp ``pose`` (4, 4) world
    opened to ``opening_m``: |x| within half the finger width, |y| within half the opening, z between
    the finger roots and the tips (grasp frame)."""
    geo = GripperGeometry.of(gripper)
    local = (points - pose[:3, 3]) @ pose[:3, :3]
    inside = (
        (np.abs(local[:, 0]) <= geo.finger_width_m / 2)
        & (np.abs(local[:, 1]) <= opening_m / 2)
        & (local[:, 2] >= geo.root_z_m)
        & (local[:, 2] <= geo.tip_z_m)
    )
    return int(inside.sum())


def world_from_volume(target_points: np.ndarray, table_z: float) -> np.ndarray:
    """(4, 4) pose of the workspace corner: axes along the world's, centred in x and y on the target
    points' centroid, floor ``TABLE_IN_VOLUME_M`` below the support plane."""
    T = np.eye(4)
    centre = target_points[:, :2].mean(axis=0)
    T[:3, 3] = [centre[0] - SIZE_M / 2, centre[1] - SIZE_M / 2, table_z - TABLE_IN_VOLUME_M]
    return T


def _opening(cfg: VgnConfig, gripper: GripperConfig, predicted_m: float) -> float:
    if cfg.opening == "max":
        return float(gripper.max_width_m)
    return float(np.clip(predicted_m + 2 * cfg.width_clearance_m, gripper.min_width_m, gripper.max_width_m))


def plan_vgn(req: PlanRequest) -> PlanResult:
    """The grasp VGN detects on the target in the request's camera observation; NoFeasibleGrasp (one line)
    when the request has no observation, the camera saw no target point, or no candidate holds it."""
    cfg: VgnConfig = req.planner
    obs = getattr(req, "observation", None)
    if obs is None:
        raise NoFeasibleGrasp("vgn plans from the camera's depth views; the request carries no observation")
    target = np.asarray(obs.points)[np.asarray(obs.point_ids) == obs.target_id]
    if len(target) == 0:
        raise NoFeasibleGrasp(f"vgn: the camera saw no point of the target (id {obs.target_id})")
    wall0, cpu0 = time.perf_counter(), time.process_time()
    volume = world_from_volume(target, req.table_z)
    views = [DepthView(v.depth, v.K, v.world_from_camera) for v in obs.views]
    grid = fuse(views, volume, SIZE_M, GRID, DEPTH_MAX_M)
    wall1, cpu1 = time.perf_counter(), time.process_time()
    quality, rot, width = infer(network(), grid, cfg.threads)
    wall2, cpu2 = time.perf_counter(), time.process_time()
    found = detect(grid, quality, rot, width, cfg)
    to_gx = graspexp_from_vgn(req.gripper)
    poses = volume @ found.poses @ to_gx
    openings = [_opening(cfg, req.gripper, w) for w in found.widths_m]
    holds = [
        target_points_between_pads(p, o, req.gripper, target) >= cfg.min_target_points
        for p, o in zip(poses, openings, strict=True)
    ]
    chosen = np.flatnonzero(holds)
    timing = {
        "fuse_wall_s": wall1 - wall0,
        "fuse_cpu_s": cpu1 - cpu0,
        "infer_wall_s": wall2 - wall1,
        "infer_cpu_s": cpu2 - cpu1,
        "n_detected": len(found.quality),
    }
    if len(chosen) == 0:
        raise NoFeasibleGrasp(
            f"vgn: {len(found.quality)} detections above quality {cfg.quality_threshold}, none holds "
            f"{cfg.min_target_points} target points between its pads"
        )
    if cfg.selection == "best":
        pick = int(chosen[np.argmax(found.quality[chosen])])
    else:
        pick = int(np.random.default_rng(req.seed).choice(chosen))
    extras = {
        **timing,
        "quality": float(found.quality[pick]),
        "predicted_width_m": float(found.widths_m[pick]),
        "trained_for": "panda",
    }
    grasp = Grasp(
        pose=poses[pick],
        width_m=openings[pick],
        cost=1.0 - float(found.quality[pick]),
        n_feasible=len(chosen),
        extras=extras,
    )
    return PlanResult(grasp, {"tsdf": grid, "quality": quality, "world_from_volume": volume})
