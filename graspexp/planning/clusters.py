"""Main axis (PCA), the choice of K, and K-means segmentation of the grasping area (paper III-B, III-D).

Main axis
    The first principal component of the grasping-area points (eigenvector of the largest eigenvalue of
    their 3x3 covariance), unit length. Its sign is fixed so that its largest-magnitude component is
    positive (ties: the first such component), which makes it a deterministic function of the cloud.

K (``planner.k: auto``)
    ``K = clamp(ceil(L / (AUTO_K_STROKE_FRACTION * g)), 1, k_max)``, where ``L`` is the extent of the
    area along its main axis (max - min of the projections, m) and ``g = gripper.max_width_m``. With the
    fraction 0.5 each cluster spans at most half the stroke along the main axis, so its along-axis
    spread never alone pushes the opening ``2 r_k (1 + margin)`` past the stroke; a bigger gripper gives
    fewer clusters, as the paper asks (III-B, IV-D). K never exceeds the number of area points.

Radius ``r_k``
    The root-mean-square distance of the cluster's points from its centre ``c_k`` (m). The centre is
    the cluster mean (the K-means centroid), so ``r_k^2`` is the cluster's total variance. RMS rather
    than max keeps a few outlying surface points from inflating the opening.
"""

import math
from dataclasses import dataclass

import numpy as np
from sklearn import config_context
from sklearn.cluster import kmeans_plusplus

AUTO_K_STROKE_FRACTION = 0.5
"""Default ``c`` in the ``k: auto`` rule (``planner.auto_k_stroke_fraction``): one cluster per
``c * gripper.max_width_m`` of area length."""

KMEANS_MAX_ITER = 100
"""Lloyd iterations cap."""

KMEANS_TOL = 1e-3
"""Relative tolerance (sklearn's definition): stop once the centres move less than about sqrt(1e-3) (~3 %) of the
area's RMS spread per iteration (about 1 mm on these objects); sklearn's 1e-4 costs 3-4x the iterations."""


def main_axis(points_m: np.ndarray) -> np.ndarray:
    """First principal component of (n, 3) points, unit (3,) float64, sign fixed as in the module doc.

    A single point (or a degenerate cloud) still yields a unit vector (eigh's output for a zero matrix).
    """
    pts = np.asarray(points_m, dtype=np.float64)
    centred = pts - pts.mean(axis=0)
    cov = centred.T @ centred / max(len(pts), 1)
    _, vecs = np.linalg.eigh(cov)
    axis = vecs[:, -1]
    axis = axis / np.linalg.norm(axis)
    if axis[int(np.argmax(np.abs(axis)))] < 0:
        axis = -axis
    return axis


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
    stroke_fraction: float = AUTO_K_STROKE_FRACTION,
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
    radii_m : (K,) float64 RMS distance of each cluster's points from its centre, metres.
    labels : (n_area,) int cluster index of each area point.
    """

    centers_m: np.ndarray
    radii_m: np.ndarray
    labels: np.ndarray


def _means(pts: np.ndarray, labels: np.ndarray, k: int, fallback: np.ndarray | None = None) -> np.ndarray:
    """(k, 3) mean of each label's points; an empty label keeps its ``fallback`` row."""
    onehot = (labels[:, None] == np.arange(k)).astype(np.float64)  # (n, k)
    counts = onehot.sum(axis=0)
    out = (onehot.T @ pts) / np.maximum(counts, 1.0)[:, None]
    if fallback is not None:
        out[counts == 0] = fallback[counts == 0]
    return out


def _lloyd(pts: np.ndarray, k: int, random_state: int) -> tuple[np.ndarray, np.ndarray]:
    """K-means: scikit-learn's seeded greedy k-means++ initialisation, then Lloyd iterations in numpy
    (scikit-learn's ``KMeans`` object costs 1.5-3 ms of fixed overhead on these ~1000-point clouds).
    Stops when the centres move less than ``KMEANS_TOL`` x the mean per-axis variance (sklearn's rule)."""
    with config_context(assume_finite=True, skip_parameter_validation=True):
        centers, _ = kmeans_plusplus(pts, k, random_state=random_state)
    tol = KMEANS_TOL * float(np.var(pts, axis=0).mean())
    for _ in range(KMEANS_MAX_ITER):
        # argmin_j |x - c_j|^2 = argmin_j (|c_j|^2 - 2 x . c_j): |x|^2 is the same for every j
        labels = (np.sum(centers * centers, axis=1) - 2.0 * pts @ centers.T).argmin(axis=1)
        new = _means(pts, labels, k, fallback=centers)
        shift = float(np.sum((new - centers) ** 2))
        centers = new
        if shift <= tol:
            break
    labels = (np.sum(centers * centers, axis=1) - 2.0 * pts @ centers.T).argmin(axis=1)
    return labels.astype(np.int64), centers


def segment(area_points_m: np.ndarray, k: int, *, random_state: int) -> Clusters:
    """Seeded K-means (k-means++ init, Lloyd) of (n, 3) area points into at most ``k`` clusters.

    Fewer than ``k`` come back only when the area has fewer distinct points than ``k``.
    """
    pts = np.asarray(area_points_m, dtype=np.float64)
    if k == 1:
        labels = np.zeros(len(pts), dtype=np.int64)
        centers = pts.mean(axis=0, keepdims=True)
    else:
        labels, centers = _lloyd(pts, k, random_state)
        # Drop clusters left empty (only possible with fewer distinct points than k) and renumber.
        used, labels = np.unique(labels, return_inverse=True)
        k = len(used)
        centers = _means(pts, labels, k)
    sq = np.sum((pts - centers[labels]) ** 2, axis=1)
    counts = np.bincount(labels, minlength=k)
    radii = np.sqrt(np.bincount(labels, weights=sq, minlength=k) / np.maximum(counts, 1))
    return Clusters(centers_m=centers, radii_m=radii, labels=labels)
