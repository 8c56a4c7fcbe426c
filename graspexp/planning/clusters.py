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

AUTO_K_STROKE_FRACTION = 0.5
"""Default ``c`` in the ``k: auto`` rule (``planner.auto_k_stroke_fraction``): one cluster per
``c * gripper.max_width_m`` of area length."""

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


def _means(pts_1: np.ndarray, labels: np.ndarray, k: int, fallback: np.ndarray | None = None) -> np.ndarray:
    """(k, 3) mean of each label's points; an empty label keeps its ``fallback`` row.

    pts_1 : (n, 4) points with a column of ones, so one product gives the sums and the counts.
    """
    sums = (labels == np.arange(k)[:, None]).astype(np.float64) @ pts_1  # (k, 4)
    counts = sums[:, 3]
    out = sums[:, :3] / np.maximum(counts, 1.0)[:, None]
    if fallback is not None and counts.min() == 0:
        out[counts == 0] = fallback[counts == 0]
    return out


def _nearest(pts_1t: np.ndarray, centers: np.ndarray) -> np.ndarray:
    """(n,) index of the centre nearest each point, lowest index on ties: argmin_j (|c_j|^2 - 2 c_j . x),
    one product with the (4, n) points-and-ones ``pts_1t``. A loop over the few centres beats
    ``argmin(axis=0)``."""
    coef = np.empty((len(centers), 4))
    coef[:, :3] = centers * -2.0
    coef[:, 3] = np.einsum("ij,ij->i", centers, centers)
    dist = coef @ pts_1t  # (k, n)
    best = dist[0]
    labels = np.zeros(dist.shape[1], dtype=np.int64)
    for j in range(1, len(dist)):
        closer = dist[j] < best
        labels[closer] = j
        np.minimum(best, dist[j], out=best)
    return labels


def _kmeans_plusplus(pts_t: np.ndarray, k: int, rng: np.random.Generator) -> np.ndarray:
    """Greedy k-means++ seeding (Arthur & Vassilvitskii 2007, the variant scikit-learn uses): the first
    centre uniformly, then each next one the best, by resulting potential, of ``2 + floor(ln k)`` points
    drawn with probability proportional to their squared distance to the nearest chosen centre.

    scikit-learn's ``kmeans_plusplus`` runs the same algorithm behind about 0.8 ms of input validation
    per call, a sixth of this planner's whole budget (``python -m graspexp.bench.plan_latency``).
    pts_t : (3, n) points. Returns (k, 3) centres, points of the set.
    """
    n_trials = 2 + int(np.log(k))
    n = pts_t.shape[1]
    sq_norms = np.einsum("ij,ij->j", pts_t, pts_t)

    def sq_distances(idx: np.ndarray) -> np.ndarray:  # (len(idx), n) squared distances, clipped at 0
        c = pts_t[:, idx]
        dist = (c.T * -2.0) @ pts_t + sq_norms + sq_norms[idx][:, None]
        return np.maximum(dist, 0.0, out=dist)

    chosen = [int(rng.integers(n))]
    closest = sq_distances(np.array(chosen))[0]  # to the nearest chosen centre
    for _ in range(1, k):
        draws = rng.random(n_trials) * closest.sum()
        cand = np.minimum(np.searchsorted(np.cumsum(closest), draws), n - 1)
        dist = np.minimum(sq_distances(cand), closest)  # (n_trials, n)
        best = int(np.argmin(dist.sum(axis=1)))
        closest = dist[best]
        chosen.append(int(cand[best]))
    return pts_t[:, chosen].T.copy()


def _lloyd(pts: np.ndarray, k: int, random_state: int) -> tuple[np.ndarray, np.ndarray]:
    """K-means: seeded greedy k-means++ (:func:`_kmeans_plusplus`), then Lloyd iterations. Stops when
    the centres move less than ``KMEANS_TOL`` x the mean per-axis variance (scikit-learn's rule)."""
    pts_1 = np.hstack([pts, np.ones((len(pts), 1))])  # (n, 4)
    pts_1t = np.ascontiguousarray(pts_1.T)
    centers = _kmeans_plusplus(pts_1t[:3], k, np.random.default_rng(random_state))
    tol = KMEANS_TOL * float(np.var(pts_1t[:3], axis=1).mean())
    for _ in range(KMEANS_MAX_ITER):
        new = _means(pts_1, _nearest(pts_1t, centers), k, fallback=centers)
        step = (new - centers).ravel()
        centers = new
        if step @ step <= tol:
            break
    return _nearest(pts_1t, centers), centers


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
        if np.bincount(labels, minlength=k).min() == 0:
            # Drop clusters left empty (only possible with fewer distinct points than k) and renumber.
            used, labels = np.unique(labels, return_inverse=True)
            k = len(used)
        centers = _means(np.hstack([pts, np.ones((len(pts), 1))]), labels, k)
    sq = np.sum((pts - centers[labels]) ** 2, axis=1)
    counts = np.bincount(labels, minlength=k)
    radii = np.sqrt(np.bincount(labels, weights=sq, minlength=k) / np.maximum(counts, 1))
    return Clusters(centers_m=centers, radii_m=radii, labels=labels)
