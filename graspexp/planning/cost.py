"""The grasping cost of paper Eq. (1) (collaborative mode) and Eq. (2)-(3) (bin picking), vectorised.

Units follow the paper, because its constants only make sense in them:

- ``Y_ip`` (distance from object point ``i`` to the line of path ``p``) and ``r_k`` in MILLIMETRES;
- ``alpha_p`` in DEGREES: the angle between two lines (the path and the main axis), in [0, 90]
  (``arccos |d . a|``), so ``|alpha_p - 90|`` is 0 for a path orthogonal to the main axis;
- ``beta_p`` in RADIANS: the angle between the path line and the support plane, in [0, pi/2]
  (``arcsin |d_z|``), so the bin-picking term favours near-vertical (top-down) approaches;
- ``d_k`` (height of the centre above the support plane, signed) and ``g`` (gripper stroke) in mm.

Eq. (1):  J = (w |alpha - 90| + o) / s * sum_i min(cap, num / ((Y_ip - r_k)^2 + off))
Eq. (2):  J_bin = J * T(d_k, beta_p)
Eq. (3):  T = (beta_p - pi/2)^2 / b + t0   if d_k <= g,   else t_far

with every constant taken from :class:`graspexp.config.CostConfig`.

``Y_ip`` uses ``Y^2 = |x - c|^2 - ((x - c) . d)^2`` (``d`` unit). The (paths x points) block is the
planner's hot loop: a compiled float32 kernel (:func:`graspexp.planning.kernels.distance_sums`) evaluates
it on coordinates relative to the centre (mm), where the squared-distance cancellation loses at most
~1e-3 mm^2, which changes a summand by far less than 1e-4; its sums keep a relative error near 1e-6.
:func:`distance_term` with ``dtype=np.float64`` is the exact numpy reference.
"""

import numpy as np

from graspexp.config import CostConfig
from graspexp.planning.kernels import distance_sums

M_TO_MM = 1000.0


def path_main_axis_angles_deg(directions: np.ndarray, axis: np.ndarray) -> np.ndarray:
    """alpha_p: angle between each path line and the main-axis line, degrees in [0, 90].

    directions : (..., 3) unit; axis : (3,) unit. Returns (...) float64.
    """
    c = np.clip(np.abs(directions @ axis), 0.0, 1.0)
    return np.degrees(np.arccos(c))


def path_table_angles_rad(directions: np.ndarray) -> np.ndarray:
    """beta_p: angle between each path line and the horizontal support plane, radians in [0, pi/2]."""
    return np.arcsin(np.clip(np.abs(directions[..., 2]), 0.0, 1.0))


def angle_term(alpha_deg: np.ndarray, cost: CostConfig) -> np.ndarray:
    """First factor of Eq. (1): ``(w |alpha_deg - target_deg| + offset) / divisor``."""
    return (
        cost.angle_weight * np.abs(alpha_deg - cost.angle_target_deg) + cost.angle_offset
    ) / cost.angle_divisor


def table_term(d_k_mm: float, beta_rad: np.ndarray, g_mm: float, cost: CostConfig) -> np.ndarray:
    """Eq. (3): ``(beta - target)^2 / divisor + offset`` when ``d_k_mm <= g_mm``, else ``table_far``."""
    beta = np.asarray(beta_rad, dtype=np.float64)
    if d_k_mm <= g_mm:
        return (beta - cost.table_beta_target_rad) ** 2 / cost.table_beta_divisor + cost.table_offset
    return np.full(beta.shape, float(cost.table_far))


def _kernel_distance_sums(
    points: np.ndarray,
    centers: np.ndarray,
    scale: float,
    radii_mm: np.ndarray,
    directions: np.ndarray,
    feasible: np.ndarray,
    cost: CostConfig,
) -> np.ndarray:
    """(K, M) distance sums from the compiled kernel, after the checks its fastmath needs."""
    pts = np.ascontiguousarray(points, dtype=np.float64)
    ctr = np.ascontiguousarray(centers, dtype=np.float64)
    radii = np.ascontiguousarray(radii_mm, dtype=np.float64)
    dirs = np.ascontiguousarray(directions, dtype=np.float64)
    # fastmath assumes finite numbers: a NaN or inf anywhere makes this sum non-finite.
    if not np.isfinite(
        pts.sum() + ctr.sum() + radii.sum() + dirs.sum() + cost.distance_numerator_mm2 + cost.distance_cap
    ):
        raise ValueError(
            "Eq. (1) got a non-finite point, centre, radius, direction or cost constant: check the cloud "
            "and cost.distance_numerator_mm2 / cost.distance_cap"
        )
    return distance_sums(
        pts,
        ctr,
        scale,
        radii,
        dirs,
        np.ascontiguousarray(feasible, dtype=np.bool_),
        cost.distance_numerator_mm2,
        cost.distance_offset_mm2,
        cost.distance_cap,
    )


def _check_offset(cost: CostConfig) -> None:
    if not cost.distance_offset_mm2 > 0:  # also rejects NaN
        raise ValueError(
            f"cost.distance_offset_mm2={cost.distance_offset_mm2!r} is invalid: expected a positive number "
            "(it keeps Eq. (1)'s denominator away from 0)"
        )


def _check_dtype(dtype: type) -> None:
    if dtype is not np.float32 and dtype is not np.float64:
        raise ValueError(
            f"dtype={dtype!r} is invalid: expected np.float32 (compiled) or np.float64 (reference)"
        )


def distance_term(
    rel_points_mm: np.ndarray,
    directions: np.ndarray,
    r_k_mm: float,
    cost: CostConfig,
    *,
    dtype: type = np.float32,
) -> np.ndarray:
    """Second factor of Eq. (1) for every path of one cluster.

    rel_points_mm : (N, 3) object points minus the cluster centre, millimetres.
    directions : (M, 3) unit path directions (either sign: only the line matters).
    r_k_mm : the cluster radius, millimetres.
    dtype : ``np.float32``: the compiled float32 kernel (the planner's path); ``np.float64``: the numpy
        float64 reference (tests).

    Returns
    -------
    (M,) float64: ``sum_i min(cap, num / ((Y_ip - r_k)^2 + off))``.
    """
    _check_offset(cost)
    _check_dtype(dtype)
    d = np.asarray(directions, dtype=np.float64)
    if dtype is np.float32:
        one = np.ones((1, len(d)), dtype=bool)
        return _kernel_distance_sums(
            rel_points_mm, np.zeros((1, 3)), 1.0, np.array([r_k_mm]), d[None], one, cost
        )[0]
    x = np.asarray(rel_points_mm, dtype=np.float64)
    y2 = np.einsum("ij,ij->i", x, x) - (d @ x.T) ** 2  # (M, N) Y^2
    y = np.sqrt(np.abs(y2))  # only rounding can make Y^2 negative
    terms = cost.distance_numerator_mm2 / ((y - r_k_mm) ** 2 + cost.distance_offset_mm2)
    return np.minimum(terms, cost.distance_cap).sum(axis=1)


def all_path_costs(
    points_m: np.ndarray,
    centers_m: np.ndarray,
    radii_m: np.ndarray,
    directions: np.ndarray,
    feasible: np.ndarray,
    axis: np.ndarray,
    mode: str,
    table_z_m: float,
    gripper_max_width_m: float,
    cost: CostConfig,
    *,
    dtype: type = np.float32,
) -> np.ndarray:
    """Eq. (1) (``mode == "collab"``) or Eq. (2) (``mode == "bin"``) for every feasible path of every cluster.

    points_m : (N, 3) whole object cloud, world, metres; centers_m : (K, 3) c_k; radii_m : (K,) r_k,
    metres; directions : (K, M, 3) unit approach directions; feasible : (K, M) bool; axis : (3,) unit
    main axis. dtype : as in :func:`distance_term` (one compiled call for all clusters, or the reference).

    Returns
    -------
    (K, M) float64 costs, ``inf`` where not feasible.
    """
    if mode not in ("collab", "bin"):
        raise ValueError(f"mode={mode!r} is invalid: expected one of collab, bin")
    _check_offset(cost)
    _check_dtype(dtype)
    points = np.asarray(points_m, dtype=np.float64)
    centers = np.asarray(centers_m, dtype=np.float64).reshape(-1, 3)
    radii_mm = np.asarray(radii_m, dtype=np.float64).reshape(-1) * M_TO_MM
    directions = np.asarray(directions, dtype=np.float64)
    feasible = np.asarray(feasible, dtype=bool)
    if dtype is np.float32:
        dist = _kernel_distance_sums(points, centers, M_TO_MM, radii_mm, directions, feasible, cost)
    else:
        dist = np.zeros(feasible.shape)
        for k, ok in enumerate(feasible):
            rel_mm = (points - centers[k]) * M_TO_MM
            dist[k, ok] = distance_term(rel_mm, directions[k, ok], radii_mm[k], cost, dtype=np.float64)
    j = angle_term(path_main_axis_angles_deg(directions, axis), cost) * dist
    if mode == "bin":
        beta = path_table_angles_rad(directions)
        for k, center in enumerate(centers):
            d_k_mm = (float(center[2]) - table_z_m) * M_TO_MM
            j[k] *= table_term(d_k_mm, beta[k], gripper_max_width_m * M_TO_MM, cost)
    j[~feasible] = np.inf
    return j
