"""``planner=vgn``: grasps from the Volumetric Grasping Network (Breyer et al., CoRL 2020) on the camera's
depth views, with the network's own pre- and post-processing.

1. Workspace: VGN's 30 cm cube, axes along the world's, its floor ``TABLE_IN_VOLUME_M`` below the support
   plane (where VGN's table lay); one object: its centre above the observed target points' centroid; a
   clutter scene: VGN's one fixed volume centred on the mode's workspace, fused and inferred once per
   scene (VGN's clutter removal, ethz-asl/vgn ``experiments/clutter_removal.py``).
2. The depth views are fused into a 40^3 TSDF (:mod:`graspexp.perception.tsdf`).
3. One forward pass (:mod:`graspexp.planning.learned.vgn_network`) gives per voxel a quality, a grasp
   orientation and a width.
4. VGN's detection: the quality volume smoothed by a Gaussian, kept only near observed free space,
   widths out of range dropped, thresholded, non-maximum suppressed.
5. Each remaining voxel is a grasp in VGN's frame, converted to graspexp's (:func:`graspexp_from_vgn`),
   and assigned to the object whose observed points it holds between its pads (the most of them); the
   target's candidates are those assigned to it; one is chosen. A clutter scene is planned through
   :func:`plan_vgn_scene` (the plugin's ``plan_scene``): one volume, one forward pass, every target.

Another network on the same TSDF with the same detection (GIGA, :mod:`graspexp.planning.learned.giga`) plans
through :func:`plan_in_volume` and :func:`plan_scene_in_volume` with its own forward pass (:data:`Outputs`).

VGN's grasp frame (the authors' simulated Panda): +Z approach, +Y closing axis (the fingers at y = +-w/2),
origin between the finger roots, the fingertips ``VGN_FINGER_DEPTH_M`` ahead along +Z; a grasp in voxel
(i, j, k) lies at (i, j, k) x voxel length in the workspace frame; the quaternion is (x, y, z, w).
"""

from __future__ import annotations

import contextlib
import functools
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass

import numpy as np
import torch
from scipy import ndimage
from scipy.spatial.transform import Rotation

from graspexp.config import GripperConfig
from graspexp.config.planner.vgn import VGN_CHECKPOINTS, VgnConfig
from graspexp.grippers import GripperGeometry
from graspexp.perception.tsdf import fuse
from graspexp.planning.grasp import Grasp, NoFeasibleGrasp
from graspexp.planning.learned.vgn_network import GRID, VgnNet, load_vgn
from graspexp.planning.request import PlanRequest, PlanResult
from graspexp.planning.scene import SceneRequest, SceneResult, per_object

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


@functools.cache
def network(checkpoint: str = "vgn_conv") -> VgnNet:
    """The network with the weights ``checkpoint`` names (``planner.checkpoint``, :data:`VGN_CHECKPOINTS`),
    read and verified once per process."""
    return load_vgn(VGN_CHECKPOINTS[checkpoint])


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


@contextlib.contextmanager
def torch_threads(threads: int) -> Iterator[None]:
    """torch on ``threads`` threads in inference mode inside the block; the thread count restored after."""
    before = torch.get_num_threads()
    torch.set_num_threads(threads)
    try:
        with torch.inference_mode():
            yield
    finally:
        torch.set_num_threads(before)


def infer(net: VgnNet, grid: np.ndarray, threads: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """One forward pass on a (40, 40, 40) float32 TSDF: quality (40, 40, 40), quaternions (4, 40, 40, 40)
    (x, y, z, w), widths (40, 40, 40) in voxels, float32."""
    with torch_threads(threads):
        q, r, w = net(torch.from_numpy(np.ascontiguousarray(grid, np.float32))[None, None])
    return q[0, 0].numpy(), r[0].numpy(), w[0, 0].numpy()


Outputs = Callable[[np.ndarray, VgnConfig], tuple[np.ndarray, np.ndarray, np.ndarray]]
"""A network's forward pass on a (40, 40, 40) float32 TSDF with the planner's config: quality (40, 40, 40),
quaternions (4, 40, 40, 40) (x, y, z, w), widths (40, 40, 40) in voxels (:func:`vgn_outputs`)."""


def vgn_outputs(grid: np.ndarray, cfg: VgnConfig) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """VGN's forward pass with the weights of ``cfg.checkpoint`` on ``cfg.threads`` threads (:func:`infer`)."""
    return infer(network(cfg.checkpoint), grid, cfg.threads)


def detect(
    grid: np.ndarray, quality: np.ndarray, rot: np.ndarray, width_vox: np.ndarray, cfg: VgnConfig
) -> Detections:
    """VGN's post-processing of one forward pass (voxel units inside, metres out), with GIGA's two additions
    when set: the wall margin (``cfg.wall_margin_m``) and the forced best candidate (``cfg.force_threshold``)."""
    q = quality.astype(np.float64)
    if cfg.quality_sigma_voxels > 0:
        q = ndimage.gaussian_filter(q, sigma=cfg.quality_sigma_voxels, mode="nearest")
    free = grid > 0.5
    behind = (grid > INSIDE_MIN) & (grid < 0.5)
    if cfg.surface_band_voxels > 0:
        near = ndimage.binary_dilation(free, iterations=cfg.surface_band_voxels, mask=~behind)
    else:
        near = free
    margin = int(cfg.wall_margin_m / VOXEL_M + 1e-9)  # GIGA's int(limit / voxel_size)
    if margin > 0:
        near[:margin], near[-margin:], near[:, :margin], near[:, -margin:] = False, False, False, False
    width_m = width_vox.astype(np.float64) * VOXEL_M
    valid = near & (width_m >= cfg.min_width_m) & (width_m <= cfg.max_width_m)
    keep = valid & (q >= cfg.quality_threshold)
    forced = cfg.force_threshold is not None and not keep.any()
    if forced:
        keep = valid & (q >= cfg.force_threshold)
    q = np.where(keep, q, 0.0)
    peak = ndimage.maximum_filter(q, size=cfg.nms_size_voxels)
    idx = np.argwhere(keep & (q == peak))  # C order: deterministic
    if forced and len(idx):  # GIGA keeps the best of the suppressed candidates only
        idx = idx[[int(np.argmax(q[tuple(idx.T)]))]]
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
    """(4, 4) pose of the workspace corner of a one-object trial: axes along the world's, centred in x and y
    on the target points' centroid, floor ``TABLE_IN_VOLUME_M`` below the support plane."""
    return _volume_at(target_points[:, :2].mean(axis=0), table_z)


def world_from_scene_volume(workspace_xy: np.ndarray, table_z: float) -> np.ndarray:
    """(4, 4) pose of the workspace corner of a clutter scene: VGN's one fixed volume (its clutter removal
    fuses and infers on the tray's workspace, never per object), centred in x and y on the mode's
    workspace ``workspace_xy`` ((2, 2) [[x_min, y_min], [x_max, y_max]] world m), floor
    ``TABLE_IN_VOLUME_M`` below the support plane."""
    return _volume_at(np.asarray(workspace_xy, dtype=np.float64).mean(axis=0), table_z)


def _volume_at(centre_xy: np.ndarray, table_z: float) -> np.ndarray:
    T = np.eye(4)
    T[:3, 3] = [centre_xy[0] - SIZE_M / 2, centre_xy[1] - SIZE_M / 2, table_z - TABLE_IN_VOLUME_M]
    return T


@dataclass(frozen=True)
class SceneGrasps:
    """VGN's candidates of one volume, in graspexp's grasp frame, each assigned to the object it holds.

    volume : (4, 4) world pose of the volume's corner. grid : (40, 40, 40) the fused TSDF (network input).
    quality_volume : (40, 40, 40) the network's raw quality. poses : (n, 4, 4) world grasp poses (graspexp's
    frame). openings : (n,) planned openings, m. found : the detections (VGN's frame, volume frame).
    owner : (n,) int object id whose observed points the candidate holds between its pads (the most of
    them, at least ``min_target_points``), 0: none. timing : fusion and inference wall and CPU seconds,
    detection count.
    """

    volume: np.ndarray
    grid: np.ndarray
    quality_volume: np.ndarray
    poses: np.ndarray
    openings: np.ndarray
    found: Detections
    owner: np.ndarray
    timing: dict[str, float]


def scene_grasps(req: PlanRequest, volume: np.ndarray, outputs: Outputs | None = None) -> SceneGrasps:
    """Fuse the request's depth views into the volume whose corner is ``volume`` (4, 4), run the network
    once (``outputs``, default VGN's: :func:`vgn_outputs`), detect (:func:`detect`) and assign every candidate
    to the object it holds (every object id > 0 of the observed cloud)."""
    cfg: VgnConfig = req.planner
    obs = req.observation
    wall0, cpu0 = time.perf_counter(), time.process_time()
    grid = fuse(obs.views, volume, SIZE_M, GRID, DEPTH_MAX_M)
    wall1, cpu1 = time.perf_counter(), time.process_time()
    quality, rot, width = (outputs or vgn_outputs)(grid, cfg)
    wall2, cpu2 = time.perf_counter(), time.process_time()
    found = detect(grid, quality, rot, width, cfg)
    poses = volume @ found.poses @ graspexp_from_vgn(req.gripper)
    openings = np.array([_opening(cfg, req.gripper, w) for w in found.widths_m], dtype=np.float64)
    points, ids = np.asarray(obs.points), np.asarray(obs.point_ids)
    objects = [int(i) for i in np.unique(ids) if i > 0]
    counts = np.zeros((len(poses), len(objects)), dtype=np.int64)
    for j, oid in enumerate(objects):
        mine = points[ids == oid]
        for i, (p, o) in enumerate(zip(poses, openings, strict=True)):
            counts[i, j] = target_points_between_pads(p, o, req.gripper, mine)
    owner = np.zeros(len(poses), dtype=np.int64)
    if objects and len(poses):
        most = np.argmax(counts, axis=1)  # ties: the smaller id
        held = counts[np.arange(len(poses)), most] >= cfg.min_target_points
        owner[held] = np.asarray(objects)[most[held]]
    timing = {
        "fuse_wall_s": wall1 - wall0,
        "fuse_cpu_s": cpu1 - cpu0,
        "infer_wall_s": wall2 - wall1,
        "infer_cpu_s": cpu2 - cpu1,
        "n_detected": len(found.quality),
    }
    return SceneGrasps(volume, grid, quality, poses, openings, found, owner, timing)


def _opening(cfg: VgnConfig, gripper: GripperConfig, predicted_m: float) -> float:
    if cfg.opening == "max":
        return float(gripper.max_width_m)
    return float(np.clip(predicted_m + 2 * cfg.width_clearance_m, gripper.min_width_m, gripper.max_width_m))


def plan_vgn(req: PlanRequest) -> PlanResult:
    """The grasp VGN detects on the target in the request's camera observation, in a volume centred on the
    target's observed points; NoFeasibleGrasp (one line) when the request has no observation, the camera saw
    no target point, or no candidate holds it."""
    return plan_in_volume(req, vgn_outputs)


def plan_vgn_scene(req: SceneRequest) -> SceneResult:
    """VGN's clutter removal: one fixed volume on the mode's workspace, fused and inferred once for the
    scene (at the first target the camera saw), each candidate assigned to the object it holds; a target's
    candidates are those assigned to it. Targets in the request's order (``first_found``: up to the first
    grasp found); the fusion's and inference's times are in the extras of the target that paid them."""
    return plan_scene_in_volume(req, vgn_outputs)


def plan_in_volume(req: PlanRequest, outputs: Outputs) -> PlanResult:
    """:func:`plan_vgn` with the forward pass ``outputs`` (a network of VGN's input and outputs)."""
    target = _target_points(req)
    return _choose(req, scene_grasps(req, world_from_volume(target, req.table_z), outputs), paid=True)


def plan_scene_in_volume(req: SceneRequest, outputs: Outputs) -> SceneResult:
    """:func:`plan_vgn_scene` with the forward pass ``outputs`` (a network of VGN's input and outputs)."""
    scene: SceneGrasps | None = None

    def plan_target(target: PlanRequest) -> PlanResult:
        nonlocal scene
        _target_points(target)
        paid = scene is None
        if scene is None:
            volume = world_from_scene_volume(target.workspace_xy, target.table_z)
            scene = scene_grasps(target, volume, outputs)
        return _choose(target, scene, paid)

    return per_object(plan_target)(req)


def _target_points(req: PlanRequest) -> np.ndarray:
    """(n, 3) the observed points of the request's target, world m; NoFeasibleGrasp without an observation
    or when the camera saw none."""
    obs, name = req.observation, req.planner.name
    if obs is None:
        raise NoFeasibleGrasp(
            f"{name} plans from the camera's depth views; the request carries no observation"
        )
    target = np.asarray(obs.points)[np.asarray(obs.point_ids) == obs.target_id]
    if len(target) == 0:
        raise NoFeasibleGrasp(f"{name}: the camera saw no point of the target (id {obs.target_id})")
    return target


def _choose(req: PlanRequest, scene: SceneGrasps, paid: bool) -> PlanResult:
    """The grasp of ``scene``'s candidates held by the request's target (``planner.selection``); ``paid``:
    this plan computed ``scene`` (its fusion and inference times go into the extras, else zeros)."""
    cfg: VgnConfig = req.planner
    obs = req.observation
    found = scene.found
    chosen = np.flatnonzero(scene.owner == obs.target_id)
    if len(chosen) == 0:
        raise NoFeasibleGrasp(
            f"{cfg.name}: {len(found.quality)} detections above quality {cfg.quality_threshold}, none holds "
            f"{cfg.min_target_points} target points between its pads"
        )
    if cfg.selection == "best":
        pick = int(chosen[np.argmax(found.quality[chosen])])
    else:
        pick = int(np.random.default_rng(req.seed).choice(chosen))
    timing = dict(scene.timing)
    if not paid:
        timing.update(dict.fromkeys(("fuse_wall_s", "fuse_cpu_s", "infer_wall_s", "infer_cpu_s"), 0.0))
    extras = {
        **timing,
        "quality": float(found.quality[pick]),
        "predicted_width_m": float(found.widths_m[pick]),
        "trained_for": "panda",
    }
    grasp = Grasp(
        pose=scene.poses[pick],
        width_m=float(scene.openings[pick]),
        cost=1.0 - float(found.quality[pick]),
        n_feasible=len(chosen),
        extras=extras,
    )
    return PlanResult(
        grasp, {"tsdf": scene.grid, "quality": scene.quality_volume, "world_from_volume": scene.volume}
    )
