"""The object's pose from the observed cloud, with Open3D: point-to-plane ICP from a prior pose (a learned
estimator's output refined, as PVN3D's pose is), or, without a prior, global registration (FPFH features
+ RANSAC, Rusu et al. 2009 as Open3D implements it) refined by the same ICP. And the pose errors every
trial records: translation (mm), rotation (deg) and ADD-S (Hinterstoisser et al. 2012's symmetric
average distance, mm).

Open3D is imported when a registration runs (the ``camera`` extra), its parallel loops limited to one
thread (``open3d.utility.set_max_threads(1)``): with two, ICP's parallel sums land in a varying order and
the registered pose changed in its last digits from run to run (measured: 3 different poses in 15
identical registrations), against the project's same-config-same-result rule.
"""

import functools
import time
from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from graspexp.config.perception import RegistrationConfig
from graspexp.perception.imports import import_optional


@dataclass(frozen=True)
class Registration:
    """An estimated pose and how it was found.

    pose : (4, 4) world from object frame, m. fitness : share of the model points ICP used that found a
    correspondence within ``max_correspondence_m`` (Open3D's fitness). rmse_m : their RMS distance, m.
    method : ``icp`` or ``global+icp``. cpu_s, wall_s : time of the registration, s (process CPU time
    over all threads, and wall time).
    """

    pose: np.ndarray
    fitness: float
    rmse_m: float
    method: str
    cpu_s: float
    wall_s: float
    n_points: int = 0
    """Observed points of the target the registration was given."""
    inliers: int = 0
    """Model points ICP's result aligned with an observed point within ``max_correspondence_m``."""
    failure: str = ""
    """Why ``pose`` is no pose of the object ("": it is): the check of :func:`failure` that failed, one line
    with the points seen and the fitness. ``pose`` is then only what the registration ended at (the prior,
    or the identity, when it did not run) and is never to be planned on."""

    @property
    def ok(self) -> bool:
        """Whether the pose passed every check (:func:`failure`)."""
        return not self.failure


@functools.cache
def open3d():
    """The ``open3d`` module, its parallel loops limited to one thread (module doc); ImportError naming what
    is wrong when it cannot be imported (:func:`graspexp.perception.imports.import_optional`)."""
    o3d = import_optional("open3d", "open3d-cpu", "pose registration")
    o3d.utility.set_max_threads(1)
    return o3d


def _cloud(points: np.ndarray, normals: np.ndarray | None = None):
    o3d = open3d()
    pc = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(np.ascontiguousarray(points, dtype=np.float64)))
    if normals is not None:
        pc.normals = o3d.utility.Vector3dVector(np.ascontiguousarray(normals, dtype=np.float64))
    return pc


def model_subset(
    points: np.ndarray,
    normals: np.ndarray,
    n: int,
    *,
    rng: np.random.Generator,
    pose: np.ndarray | None = None,
    eyes: np.ndarray | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """Up to ``n`` model points (object frame) and their normals, drawn with ``rng``; with ``pose`` (4, 4)
    and camera positions ``eyes`` (V, 3) world, only points whose normal faces a camera at that pose."""
    keep = np.arange(len(points))
    if pose is not None and eyes is not None:
        wp = points @ pose[:3, :3].T + pose[:3, 3]
        wn = normals @ pose[:3, :3].T
        facing = np.zeros(len(points), dtype=bool)
        for eye in np.atleast_2d(eyes):
            facing |= np.einsum("ij,ij->i", wn, eye - wp) > 0
        if facing.sum() >= 3:
            keep = np.flatnonzero(facing)
    if len(keep) > n:
        keep = np.sort(rng.choice(keep, size=n, replace=False))
    return points[keep], normals[keep]


def icp(
    model_points: np.ndarray,
    observed: np.ndarray,
    observed_normals: np.ndarray,
    init: np.ndarray,
    cfg: RegistrationConfig,
):
    """Point-to-plane ICP of ``model_points`` (object frame) onto the observed points (world, their
    normals), starting at ``init`` (4, 4): Open3D's RegistrationResult."""
    o3d = open3d()
    reg = o3d.pipelines.registration
    return reg.registration_icp(
        _cloud(model_points),
        _cloud(observed, observed_normals),
        cfg.max_correspondence_m,
        np.asarray(init, dtype=np.float64),
        reg.TransformationEstimationPointToPlane(),
        reg.ICPConvergenceCriteria(max_iteration=int(cfg.max_iterations)),
    )


def global_pose(
    model_points: np.ndarray,
    model_normals: np.ndarray,
    observed: np.ndarray,
    observed_normals: np.ndarray,
    cfg: RegistrationConfig,
    seed: int,
) -> np.ndarray:
    """(4, 4) coarse pose from FPFH features matched by RANSAC (no prior), on clouds voxel-downsampled to
    ``global_voxel_m``; Open3D's random generator seeded with ``seed``."""
    o3d = open3d()
    reg = o3d.pipelines.registration
    o3d.utility.random.seed(int(seed) % (2**31))
    voxel = float(cfg.global_voxel_m)
    src = _cloud(model_points, model_normals).voxel_down_sample(voxel)
    dst = _cloud(observed, observed_normals).voxel_down_sample(voxel)
    param = o3d.geometry.KDTreeSearchParamHybrid(radius=5 * voxel, max_nn=100)
    fs, fd = reg.compute_fpfh_feature(src, param), reg.compute_fpfh_feature(dst, param)
    result = reg.registration_ransac_based_on_feature_matching(
        src,
        dst,
        fs,
        fd,
        True,
        1.5 * voxel,
        reg.TransformationEstimationPointToPoint(False),
        3,
        [
            reg.CorrespondenceCheckerBasedOnEdgeLength(0.9),
            reg.CorrespondenceCheckerBasedOnDistance(1.5 * voxel),
        ],
        reg.RANSACConvergenceCriteria(int(cfg.ransac_iterations), 0.999),
    )
    return np.asarray(result.transformation)


def register(
    model_points: np.ndarray,
    model_normals: np.ndarray,
    observed: np.ndarray,
    observed_normals: np.ndarray,
    cfg: RegistrationConfig,
    *,
    prior: np.ndarray | None,
    eyes: np.ndarray,
    rng: np.random.Generator,
) -> Registration:
    """The object's pose from its observed points (module doc): ICP from ``prior`` (4, 4), or global
    registration then ICP when ``prior`` is None, and the verdict of :func:`failure` on it. model_* : (N, 3)
    object frame; observed* : (M, 3) world; eyes : (V, 3) the cameras' positions, world, m. Fewer than
    ``cfg.min_target_points`` observed points: nothing runs (``pose`` the prior, or the identity; fitness 0;
    ``failure`` says so)."""
    wall0, cpu0 = time.perf_counter(), time.process_time()
    method = "icp" if prior is not None else "global+icp"
    inliers = 0
    if len(observed) < max(3, int(cfg.min_target_points)):
        pose, fitness, rmse = (
            (np.eye(4) if prior is None else np.array(prior, dtype=float)),
            0.0,
            float("nan"),
        )
    else:
        if prior is None:
            init = global_pose(
                model_points, model_normals, observed, observed_normals, cfg, int(rng.integers(2**31))
            )
        else:
            init = np.asarray(prior, dtype=float)
        src, _ = model_subset(
            model_points,
            model_normals,
            int(cfg.model_points),
            rng=rng,
            pose=init if cfg.visible_only else None,
            eyes=eyes,
        )
        result = icp(src, observed, observed_normals, init, cfg)
        pose = np.array(result.transformation)
        fitness, rmse = float(result.fitness), float(result.inlier_rmse)
        inliers = len(result.correspondence_set)
    why = failure(cfg, observed, model_points, pose, fitness, inliers)
    return Registration(
        pose=pose,
        fitness=fitness,
        rmse_m=rmse,
        method=method,
        cpu_s=time.process_time() - cpu0,
        wall_s=time.perf_counter() - wall0,
        n_points=len(observed),
        inliers=inliers,
        failure=why,
    )


def failure(
    cfg: RegistrationConfig,
    observed: np.ndarray,
    model_points: np.ndarray,
    pose: np.ndarray,
    fitness: float,
    inliers: int,
) -> str:
    """Why the registered ``pose`` (4, 4) is not the object's pose, one line naming the points the camera saw
    and the fitness; "" when it passes every check of ``cfg`` (in this order): at least
    ``min_target_points`` observed points (M, 3 world), at least ``min_inliers`` model points aligned, a
    fitness of at least ``min_fitness``, and the observed points' centroid within the registered model's
    radius plus ``centroid_margin_m`` of its centroid (``model_points`` (N, 3) object frame; see
    :class:`~graspexp.config.perception.RegistrationConfig` for why each cannot refuse a correct pose)."""
    key = "perception.registration"
    seen = f"the camera saw {len(observed)} points of the target"
    if len(observed) < cfg.min_target_points:
        return f"{seen}, fewer than {key}.min_target_points={cfg.min_target_points}"
    fit = f"{seen}; ICP aligned {inliers} model points (fitness {fitness:.3f})"
    if inliers < cfg.min_inliers:
        return f"{fit}, fewer than {key}.min_inliers={cfg.min_inliers}"
    if fitness < cfg.min_fitness:
        return f"{fit}, below {key}.min_fitness={cfg.min_fitness:g}"
    model = np.asarray(model_points, dtype=np.float64)
    centre = model.mean(axis=0)
    radius = float(np.sqrt(((model - centre) ** 2).sum(axis=1).max()))
    gap = float(np.linalg.norm(pose[:3, :3] @ centre + pose[:3, 3] - np.asarray(observed).mean(axis=0)))
    if gap > radius + cfg.centroid_margin_m:
        return (
            f"{fit}; the registered model's centroid is {1e3 * gap:.0f} mm from theirs, farther than its "
            f"radius {1e3 * radius:.0f} mm + {key}.centroid_margin_m={cfg.centroid_margin_m:g} m"
        )
    return ""


def pose_errors(estimate: np.ndarray, truth: np.ndarray, model_points: np.ndarray) -> dict[str, float]:
    """Errors of an estimated pose (4, 4) against the true one: ``trans_mm`` (distance between the object
    origins), ``rot_deg`` (angle of R_est R_true^T) and ``adds_mm`` (ADD-S: mean distance from each model
    point (object frame, (N, 3)) at the estimate to the nearest model point at the truth, mm)."""
    trans = float(np.linalg.norm(estimate[:3, 3] - truth[:3, 3])) * 1000.0
    cos = (np.trace(estimate[:3, :3] @ truth[:3, :3].T) - 1.0) / 2.0
    rot = float(np.degrees(np.arccos(np.clip(cos, -1.0, 1.0))))
    at_est = model_points @ estimate[:3, :3].T + estimate[:3, 3]
    at_true = model_points @ truth[:3, :3].T + truth[:3, 3]
    adds = float(cKDTree(at_true).query(at_est)[0].mean()) * 1000.0
    return {"trans_mm": trans, "rot_deg": rot, "adds_mm": adds}
