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

Radius ``r_k`` (``planner.cluster_radius``)
    ``rms``: the root-mean-square distance of the cluster's points from its centre ``c_k`` (the centre
    is the cluster mean, so ``r_k^2`` is the cluster's total variance); ``max``: the largest distance
    (:func:`max_radii_m`). Metres.
"""

import math
from dataclasses import dataclass

import numpy as np

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


def _kmeans_plusplus(pts_t: np.ndarray, sq_norms: np.ndarray, k: int, rng: np.random.Generator) -> np.ndarray:
    """Greedy k-means++ seeding (Arthur & Vassilvitskii 2007, the variant scikit-learn uses): the first
    centre uniformly, then each next one the best, by resulting potential, of ``2 + floor(ln k)`` points
    drawn with probability proportional to their squared distance to the nearest chosen centre.

    scikit-learn's ``kmeans_plusplus`` runs the same algorithm behind about 0.8 ms of input validation
    per call, a sixth of this planner's whole budget (``python -m graspexp.bench.plan_latency``).
    pts_t : (3, n) points; sq_norms : (n,) their squared norms. Returns (k, 3) centres, points of the set.
    """
    n_trials = 2 + int(np.log(k))
    n = pts_t.shape[1]

    def sq_distances(idx: np.ndarray) -> np.ndarray:  # (len(idx), n) squared distances, clipped at 0
        dist = (pts_t[:, idx].T * -2.0) @ pts_t + sq_norms + sq_norms[idx][:, None]
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


def _cluster_sums(aug: np.ndarray, aug_t: np.ndarray, centers: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Assign every point to its nearest centre (lowest index on ties) and sum per cluster.

    aug : (n, 5) rows ``[x, y, z, 1, |p|^2]``; aug_t : (4, n) its first four columns, transposed;
    centers : (k, 3). Returns the (n,) labels and the (k, 5) per-cluster sums of ``aug`` (so column 3
    counts the points). Nearest = argmin_j (|c_j|^2 - 2 c_j . p): one (k, 4) x (4, n) product.
    """
    coef = np.empty((len(centers), 4))
    coef[:, :3] = centers * -2.0
    coef[:, 3] = (centers * centers).sum(axis=1)
    labels = (coef @ aug_t).argmin(axis=0)
    return labels, (labels == np.arange(len(centers))[:, None]).astype(np.float64) @ aug


def segment(area_points_m: np.ndarray, k: int, *, random_state: int) -> Clusters:
    """Seeded K-means of (n, 3) area points into at most ``k`` clusters: greedy k-means++
    (:func:`_kmeans_plusplus`), then Lloyd iterations until the centres move less than ``KMEANS_TOL`` x
    the mean per-axis variance (scikit-learn's rule); the labels are the final centres' and the centres
    those labels' means. An empty cluster keeps its centre during the iterations; clusters still empty at
    the end (only possible with fewer distinct points than ``k``) are dropped and the rest renumbered.
    """
    pts = np.asarray(area_points_m, dtype=np.float64)
    aug = np.empty((len(pts), 5))
    aug[:, :3] = pts
    aug[:, 3] = 1.0
    aug[:, 4] = (pts * pts).sum(axis=1)
    aug_t = aug[:, :4].T.copy()
    if k == 1:
        labels, sums = np.zeros(len(pts), dtype=np.int64), aug.sum(axis=0, keepdims=True)
    else:
        centers = _kmeans_plusplus(aug_t[:3], aug[:, 4], k, np.random.default_rng(random_state))
        tol = KMEANS_TOL * float(np.var(aug_t[:3], axis=1).mean())
        for _ in range(KMEANS_MAX_ITER):
            _, sums = _cluster_sums(aug, aug_t, centers)
            new = sums[:, :3] / np.maximum(sums[:, 3:4], 1.0)
            if sums[:, 3].min() == 0:
                new[sums[:, 3] == 0] = centers[sums[:, 3] == 0]
            step = (new - centers).ravel()
            centers = new
            if step @ step <= tol:
                break
        labels, sums = _cluster_sums(aug, aug_t, centers)
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
    pts = np.asarray(area_points_m, dtype=np.float64)
    d2 = ((pts - clusters.centers_m[clusters.labels]) ** 2).sum(axis=1)
    out = np.zeros(len(clusters.centers_m))
    np.maximum.at(out, clusters.labels, d2)
    return np.sqrt(out)
