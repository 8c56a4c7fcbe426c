"""One look of the camera at the scene: every view rendered (:mod:`graspexp.perception.camera`), made
noisy (:mod:`graspexp.perception.depth_noise`), back-projected and cropped to the workspace, normals
estimated (Open3D, oriented towards the view's camera): an :class:`Observation`. And the pose the
planner is told (:func:`estimate_pose`): registered from that observation."""

from collections.abc import Sequence

import numpy as np

from graspexp.config.perception import PerceptionConfig
from graspexp.perception.camera import BoxBody, MeshBody, back_project, intrinsics, render, view_poses
from graspexp.perception.depth_noise import noisy_depth
from graspexp.perception.observation import CameraView, Observation
from graspexp.perception.registration import Registration, open3d, register


def _normals(points: np.ndarray, eye: np.ndarray, cfg: PerceptionConfig) -> np.ndarray:
    """(M, 3) unit normals of one view's points (world), oriented towards the camera at ``eye``."""
    if len(points) == 0:
        return np.zeros((0, 3))
    o3d = open3d()
    pc = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))
    reg = cfg.registration
    pc.estimate_normals(
        o3d.geometry.KDTreeSearchParamHybrid(
            radius=float(reg.normal_radius_m), max_nn=int(reg.normal_neighbours)
        )
    )
    n = np.asarray(pc.normals)
    flip = np.einsum("ij,ij->i", n, eye - points) < 0
    n[flip] *= -1.0
    return n


def observe(
    cfg: PerceptionConfig,
    meshes: Sequence[MeshBody],
    boxes: Sequence[BoxBody],
    table_z: float,
    target_id: int,
    *,
    rng: np.random.Generator,
) -> Observation:
    """Render every view of ``cfg.camera`` over the support top at ``table_z`` (m) and build the
    observed cloud (module doc); the noise draws come from ``rng``."""
    cam = cfg.camera
    K = intrinsics(cam)
    views, points, normals, ids = [], [], [], []
    centre = np.array([0.0, 0.0, table_z + cam.look_at_height_m])
    for i, pose in enumerate(view_poses(cam, table_z)):
        exact = render(cam, pose, meshes, boxes)
        depth, view_ids = noisy_depth(cfg.depth_noise, exact.depth, exact.ids, exact.cos_incidence, rng=rng)
        views.append(CameraView(depth=depth, ids=view_ids, K=K, world_from_camera=pose, name=f"view{i}"))
        pts, flat = back_project(depth, cam, pose)
        inside = (
            (np.abs(pts[:, 0] - centre[0]) <= cam.workspace_half_m)
            & (np.abs(pts[:, 1] - centre[1]) <= cam.workspace_half_m)
            & (pts[:, 2] <= table_z + cam.workspace_top_m)
        )
        pts = pts[inside]
        points.append(pts)
        normals.append(_normals(pts, pose[:3, 3], cfg))
        ids.append(view_ids.ravel()[flat[inside]])
    return Observation(
        views=tuple(views),
        points=np.concatenate(points),
        normals=np.concatenate(normals),
        point_ids=np.concatenate(ids).astype(np.int32),
        target_id=int(target_id),
    )


def estimate_pose(
    cfg: PerceptionConfig,
    observation: Observation,
    model_points: np.ndarray,
    model_normals: np.ndarray,
    prior: np.ndarray | None,
    *,
    rng: np.random.Generator,
) -> Registration:
    """The target's pose registered from ``observation`` (:func:`graspexp.perception.registration.register`):
    from ``prior`` (4, 4) world, or globally when None. model_* : (N, 3) object frame."""
    pts, nrm = observation.target()
    eyes = np.array([v.world_from_camera[:3, 3] for v in observation.views])
    return register(model_points, model_normals, pts, nrm, cfg.registration, prior=prior, eyes=eyes, rng=rng)
