"""Main axis (PCA), the choice of K, and K-means segmentation of the grasping area (paper III-B, III-D).

Main axis
    The first principal component of the grasping-area points (eigenvector of the largest eigenvalue of
    their 3x3 covariance), unit length. Its sign is fixed so that its largest-magnitude component is
    positive (ties: the first such component), which makes it a deterministic function of the cloud.

K (``planner.k: auto``)
    ``K = clamp(ceil(L / (c * g)), 1, k_max)``, where ``L`` is the extent of the area along its main axis
    (max - min of the projections, m), ``g = gripper.max_width_m`` and ``c =
    planner.auto_k_stroke_fraction`` (its docstring gives the reading); a bigger gripper gives fewer
    clusters, as the paper asks (III-B, IV-D). K never exceeds the number of area points.

Pose axis (``planner.pose_axis``)
    ``object`` / ``area``: the main axis of that cloud; ``area_if_elongated``: the area's main axis when
    the area's :func:`elongation` is at least ``planner.pose_axis_min_elongation``, else the object's.

Radius ``r_k`` (``planner.cluster_radius``)
    ``rms``: the root-mean-square distance of the cluster's points from its centre ``c_k`` (the centre
    is the cluster mean, so ``r_k^2`` is the cluster's total variance); ``max``: the largest distance
    (:func:`max_radii_m`). Metres.
"""

import math
from dataclasses import dataclass

import numpy as np

from graspexp.planning.kernels import cluster_max_distances, kmeans

KMEANS_MAX_ITER = 100
"""Lloyd iterations cap."""

KMEANS_TOL = 1e-3
"""Relative tolerance (scikit-learn's definition): stop once the centres move less than about sqrt(1e-3) (~3 %) of the
area's RMS spread per iteration (about 1 mm on these objects); scikit-learn's 1e-4 costs 3-4x the iterations."""


def main_axis(points_m: np.ndarray) -> np.ndarray:
    """First principal component of (n, 3) points, unit (3,) float64, sign fixed as in the module doc.

    A single point (or a degenerate cloud) still yields a unit vector (eigh's output for a zero matrix).
    """
    pts = np.asarray(points_m, dtype=np.float64)
    n = max(len(pts), 1)
    mean = np.ones(len(pts)) @ pts / n
    # E[x x^T] - mean mean^T: BLAS products instead of centring, as numpy is slow on (n, 3) broadcasts;
    # for clouds within a metre of the origin the cancellation costs < 1e-12 relative.
    cov = pts.T @ pts / n - np.outer(mean, mean)
    _, vecs = np.linalg.eigh(cov)
    axis = vecs[:, -1]
    axis = axis / np.linalg.norm(axis)
    if axis[int(np.argmax(np.abs(axis)))] < 0:
        axis = -axis
    return axis


def elongation(points_m: np.ndarray) -> float:
    """Ratio of the first to the second principal standard deviation of (n, 3) points, sqrt(l1 / l2)
    (dimensionless, >= 1): how clearly the cloud has a main axis. 1 for a ring or a disc, where the first
    principal component is any direction in its plane; inf when l2 = 0 (collinear points)."""
    pts = np.asarray(points_m, dtype=np.float64)
    if len(pts) < 2:
        return 1.0
    centred = pts - pts.mean(axis=0)
    vals = np.linalg.eigvalsh(centred.T @ centred / len(pts))  # ascending
    return math.inf if vals[1] <= 0 else float(math.sqrt(max(vals[2], 0.0) / vals[1]))


def extent_along(points_m: np.ndarray, axis: np.ndarray) -> float:
    """Extent (max - min) of the points' projections on a unit axis, m."""
    proj = np.asarray(points_m, dtype=np.float64) @ axis
    return float(proj.max() - proj.min()) if len(proj) else 0.0


def choose_k(
    k: object,
    k_max: int,
    area_points_m: np.ndarray,
    axis: np.ndarray,
    gripper_max_width_m: float,
    stroke_fraction: float,
) -> int:
    """Number of clusters: ``k`` if an int, else the ``auto`` rule of the module doc; at most n_area."""
    n_area = len(area_points_m)
    if k == "auto":
        length_m = extent_along(area_points_m, axis)
        chosen = math.ceil(length_m / (stroke_fraction * gripper_max_width_m))
        chosen = min(max(chosen, 1), int(k_max))
    else:
        chosen = int(k)
        if chosen < 1:
            raise ValueError(f"planner.k={k!r} is invalid: expected 'auto' or a positive integer")
    return max(1, min(chosen, n_area))


@dataclass(frozen=True)
class Clusters:
    """K-means result on the grasping area.

    centers_m : (K, 3) float64 centroids, world, metres.
    radii_m : (K,) float64 RMS distance of each cluster's points from its centre, metres (the planner
        may replace it by :func:`max_radii_m`, ``planner.cluster_radius``).
    labels : (n_area,) int cluster index of each area point.
    """

    centers_m: np.ndarray
    radii_m: np.ndarray
    labels: np.ndarray


def segment(area_points_m: np.ndarray, k: int, *, random_state: int) -> Clusters:
    """Seeded K-means of (n, 3) area points into at most ``k`` clusters, compiled
    (:func:`graspexp.planning.kernels.kmeans`; scikit-learn's own call costs about 0.8 ms of input
    validation, a sixth of the planner's latency budget).

    Greedy k-means++ seeding (Arthur & Vassilvitskii 2007, the variant scikit-learn uses): the first
    centre uniformly, then each next one the best, by resulting potential, of ``2 + floor(ln k)`` points
    drawn with probability proportional to their squared distance to the nearest chosen centre; then
    Lloyd iterations until the centres move less than ``KMEANS_TOL`` x the mean per-axis variance
    (scikit-learn's rule). The labels are the final centres' and the centres those labels' means. An
    empty cluster keeps its centre during the iterations; clusters still empty at the end (only possible
    with fewer distinct points than ``k``) are dropped and the rest renumbered.
    """
    pts = np.ascontiguousarray(area_points_m, dtype=np.float64)
    if k == 1:  # the mean, whatever the seed: skip the generator (a tenth of this call)
        first, draws = 0, np.empty((0, 2))
    else:
        rng = np.random.default_rng(random_state)
        first = int(rng.integers(len(pts)))
        draws = rng.random((k - 1, 2 + int(np.log(k))))  # k-means++ candidates of centres 1 .. k-1
    labels, sums = kmeans(pts, k, first, draws, KMEANS_TOL, KMEANS_MAX_ITER)
    if sums[:, 3].min() == 0:
        used, labels = np.unique(labels, return_inverse=True)
        sums = sums[used]
    centers = sums[:, :3] / sums[:, 3:4]
    # RMS distance from the centre: E|p|^2 - |c|^2 (float64; for clouds within a metre of the origin the
    # cancellation costs < 1e-12 relative).
    mean_sq = sums[:, 4] / sums[:, 3] - (centers * centers).sum(axis=1)
    return Clusters(centers_m=centers, radii_m=np.sqrt(np.maximum(mean_sq, 0.0)), labels=labels)


def max_radii_m(area_points_m: np.ndarray, clusters: Clusters) -> np.ndarray:
    """(K,) largest distance of each cluster's (n, 3) area points from its centre, metres."""
    return cluster_max_distances(
        np.ascontiguousarray(area_points_m, dtype=np.float64),
        np.ascontiguousarray(clusters.centers_m, dtype=np.float64),
        np.ascontiguousarray(clusters.labels, dtype=np.int64),
    )
