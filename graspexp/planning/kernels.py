"""Compiled (numba) loops of the planner: Eq. (1)'s distance sums, K-means, grasp frames, the section between
the pads.

Each kernel is a plain serial loop (no threads: on a shared 2-core machine ``prange`` was 20x slower) that
numba compiles on first use and caches on disk, so a process pays the compilation once per machine and
afterwards only numba's import and the cache load (docs/guide/development.md). The cache lives in
``$NUMBA_CACHE_DIR`` when set, else in a per-user folder (:func:`numba_cache_dir`, mode 0700), never in the
shared ``$GRASPEXP_CACHE`` nor beside the installed package; either must be private (owned by this user,
writable by no one else: numba's index files are pickles). When no private writable folder is found the
kernels still work, compiled afresh in every process.

The public wrappers live with their meaning: :func:`graspexp.planning.cost.all_path_costs` and
:func:`~graspexp.planning.cost.distance_term`, :func:`graspexp.planning.clusters.segment` and
:func:`~graspexp.planning.clusters.max_radii_m`, :func:`graspexp.planning.pose.grasp_rotations` and
:func:`~graspexp.planning.pose.slab_spans_m`, :func:`graspexp.planning.collision.cloud_hits` and
:func:`~graspexp.planning.collision.lowest_z`, :func:`graspexp.planning.stability.pad_contacts` and
:func:`~graspexp.planning.stability.pad_edge_excess_m`.

The kernels over a batch of grasp frames (the section, the swept boxes, the pads' contacts) see the
frames ``optimal_plus`` tries for one path and roll as a run of consecutive frames with one rotation,
moved along their Y and Z axes only: per run one pass over the cloud keeps the points near the frames'
YZ plane (:func:`_run_cull`), and every frame of the run scans those. The cull only leaves out points the
exact test would reject, and the exact tests and sums are the same expressions in the same point order,
so the results are bit for bit those of a scan over every point.
"""

import os
import stat
import tempfile
import warnings
from pathlib import Path

import numba
import numpy as np


def numba_cache_dir() -> Path:
    """The per-user folder of numba's compiled kernels: ``$XDG_CACHE_HOME/graspexp/numba``, else
    ``~/.cache/graspexp/numba``; never ``$GRASPEXP_CACHE``, which may be shared by a cluster's users
    (numba's cache index files are pickles: whoever can write them runs code in the next process)."""
    base = os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache"
    return Path(base) / "graspexp" / "numba"


def _private(folder: Path, what: str) -> bool:
    """True when ``folder`` exists (created ``0700`` here if needed), is owned by this user and writable by
    no one else, and a file can be written in it; ``what`` names where the folder came from."""
    try:
        folder.mkdir(mode=0o700, parents=True, exist_ok=True)
        st = folder.stat()
        if st.st_uid != os.getuid() or st.st_mode & (stat.S_IWGRP | stat.S_IWOTH):
            warnings.warn(
                f"numba cache {folder} ({what}) is not private to this user (another owner, or group/other "
                "write access: its pickles would run anyone's code); compiling the planner's kernels in this "
                "process instead: point it at a folder of your own, mode 700",
                RuntimeWarning,
                stacklevel=2,
            )
            return False
        tempfile.TemporaryFile(dir=folder).close()
    except OSError:
        return False
    return True


def _enable_disk_cache() -> bool:
    """Point numba's cache at the per-user folder (module doc); False when it is not usable. A
    ``$NUMBA_CACHE_DIR`` set by the user wins if it is private too (else the kernels are not cached)."""
    if numba.config.CACHE_DIR:
        return _private(Path(numba.config.CACHE_DIR), "NUMBA_CACHE_DIR")
    numba.config.CACHE_DIR = str(numba_cache_dir())
    return _private(Path(numba.config.CACHE_DIR), "the per-user default")


_CACHE = _enable_disk_cache()
jit_kernel = numba.njit(cache=_CACHE, nogil=True, error_model="numpy", boundscheck=False)
_jit_fast = numba.njit(cache=_CACHE, nogil=True, error_model="numpy", boundscheck=False, fastmath=True)


@_jit_fast
def distance_sums(
    points: np.ndarray,
    centers: np.ndarray,
    scale: float,
    radii_mm: np.ndarray,
    directions: np.ndarray,
    feasible: np.ndarray,
    numerator_mm2: float,
    offset_mm2: float,
    cap: float,
) -> np.ndarray:
    """``sum_i min(cap, num / ((Y_ip - r_k)^2 + off))`` for every feasible path of every cluster, float32
    arithmetic (see :mod:`.cost`).

    points : (N, 3) float64 and centers : (K, 3) float64 in one unit, ``scale`` x which gives mm;
    radii_mm : (K,) r_k, mm; directions : (K, M, 3) float64 unit; feasible : (K, M) bool.
    Returns (K, M) float64, 0 where not feasible. Requires finite inputs and ``offset_mm2 > 0``
    (fastmath assumes no inf/NaN). Per cluster the points are copied once, relative to its centre, into
    float32 structure-of-arrays form (x, y, z, |x|^2) so that the inner loop over points vectorises.
    """
    n = points.shape[0]
    n_clusters, n_paths = feasible.shape
    xs = np.empty(n, np.float32)
    ys = np.empty(n, np.float32)
    zs = np.empty(n, np.float32)
    sq = np.empty(n, np.float32)
    num = np.float32(numerator_mm2)
    off = np.float32(offset_mm2)
    top = np.float32(cap)
    out = np.zeros((n_clusters, n_paths))
    for k in range(n_clusters):
        for i in range(n):
            a = np.float32((points[i, 0] - centers[k, 0]) * scale)
            b = np.float32((points[i, 1] - centers[k, 1]) * scale)
            c = np.float32((points[i, 2] - centers[k, 2]) * scale)
            xs[i] = a
            ys[i] = b
            zs[i] = c
            sq[i] = a * a + b * b + c * c
        r = np.float32(radii_mm[k])
        for p in range(n_paths):
            if not feasible[k, p]:
                continue
            dx = np.float32(directions[k, p, 0])
            dy = np.float32(directions[k, p, 1])
            dz = np.float32(directions[k, p, 2])
            total = np.float32(0.0)
            for i in range(n):
                t = xs[i] * dx + ys[i] * dy + zs[i] * dz
                u = np.sqrt(np.abs(sq[i] - t * t)) - r  # Y_ip - r_k; abs() absorbs rounding below 0
                total += min(top, num / (u * u + off))
            out[k, p] = total
    return out


@jit_kernel
def grasp_frames(approaches: np.ndarray, axis: np.ndarray, parallel_tol: float) -> np.ndarray:
    """(B, 3, 3) grasp rotations, columns X, Y, Z (:func:`graspexp.planning.pose.grasp_rotations`).

    approaches : (B, 3) float64, any length; axis : (3,) float64 unit main axis.
    """
    out = np.empty((approaches.shape[0], 3, 3))
    for b in range(approaches.shape[0]):
        z = approaches[b] / np.sqrt(approaches[b, 0] ** 2 + approaches[b, 1] ** 2 + approaches[b, 2] ** 2)
        x = axis - (z[0] * axis[0] + z[1] * axis[1] + z[2] * axis[2]) * z
        norm = np.sqrt(x[0] ** 2 + x[1] ** 2 + x[2] ** 2)
        if norm < parallel_tol:  # seed with the world axis least aligned with Z (lowest index on ties)
            seed = np.zeros(3)
            seed[np.argmin(np.abs(z))] = 1.0
            x = seed - (seed[0] * z[0] + seed[1] * z[1] + seed[2] * z[2]) * z
            norm = np.sqrt(x[0] ** 2 + x[1] ** 2 + x[2] ** 2)
        x = x / norm
        y = np.array([z[1] * x[2] - z[2] * x[1], z[2] * x[0] - z[0] * x[2], z[0] * x[1] - z[1] * x[0]])
        y = y / np.sqrt(y[0] ** 2 + y[1] ** 2 + y[2] ** 2)
        out[b, :, 0] = x
        out[b, :, 1] = y
        out[b, :, 2] = z
    return out


@_jit_fast
def kmeans(
    points: np.ndarray, k: int, first: int, draws: np.ndarray, tol: float, max_iter: int
) -> tuple[np.ndarray, np.ndarray]:
    """Greedy k-means++ seeding, then Lloyd iterations (:func:`graspexp.planning.clusters.segment`).

    points : (n, 3) float64; first : index of the first centre; draws : (k - 1, n_trials) uniform [0, 1)
    numbers, row j - 1 picking the candidates of centre j; tol : relative tolerance (x the mean per-axis
    variance) on the summed squared centre moves of one iteration.

    Returns the (n,) int64 labels of the final centres (nearest, lowest index on ties) and the (k, 5)
    per-cluster sums of ``[x, y, z, 1, |p|^2]`` over those labels (column 3 counts the points).
    Requires finite points (fastmath).
    """
    n = points.shape[0]
    xs = np.ascontiguousarray(points[:, 0])
    ys = np.ascontiguousarray(points[:, 1])
    zs = np.ascontiguousarray(points[:, 2])
    centers = np.empty((k, 3))
    centers[0] = points[first]
    closest = _sq_dists(xs, ys, zs, points[first, 0], points[first, 1], points[first, 2])
    cum = np.empty(n)
    for j in range(1, k):
        total = 0.0
        for i in range(n):  # sequential on purpose: the cumulative sums the draws are searched in
            total += closest[i]
            cum[i] = total
        best_potential = np.inf
        best = closest
        best_index = 0
        for t in range(draws.shape[1]):
            cand = min(np.searchsorted(cum, draws[j - 1, t] * total), n - 1)
            trial = np.minimum(_sq_dists(xs, ys, zs, xs[cand], ys[cand], zs[cand]), closest)
            potential = trial.sum()
            if potential < best_potential:
                best_potential, best_index, best = potential, cand, trial
        closest = best
        centers[j] = points[best_index]

    spread = 0.0  # n x the summed per-axis variances
    for values in (xs, ys, zs):
        spread += ((values - values.mean()) ** 2).sum()
    tol_abs = tol * spread / (3 * n)
    labels = np.empty(n, np.int64)
    sums = np.empty((k, 5))
    for _ in range(max_iter):
        _assign(xs, ys, zs, centers, labels, sums)
        step = 0.0
        for j in range(k):
            if sums[j, 3] > 0:  # an empty cluster keeps its centre
                for a in range(3):
                    new = sums[j, a] / sums[j, 3]
                    step += (new - centers[j, a]) ** 2
                    centers[j, a] = new
        if step <= tol_abs:
            break
    _assign(xs, ys, zs, centers, labels, sums)
    return labels, sums


@jit_kernel
def cluster_max_distances(points: np.ndarray, centers: np.ndarray, labels: np.ndarray) -> np.ndarray:
    """(K,) largest distance of the (n, 3) points from their cluster's centre (``labels`` (n,) int64 index
    the (K, 3) centres); 0 for a cluster without points."""
    out = np.zeros(centers.shape[0])
    for i in range(points.shape[0]):
        j = labels[i]
        d2 = (points[i, 0] - centers[j, 0]) ** 2 + (points[i, 1] - centers[j, 1]) ** 2
        d2 += (points[i, 2] - centers[j, 2]) ** 2
        if d2 > out[j]:
            out[j] = d2
    return np.sqrt(out)


@_jit_fast
def _sq_dists(xs: np.ndarray, ys: np.ndarray, zs: np.ndarray, cx: float, cy: float, cz: float) -> np.ndarray:
    """(n,) squared distances of the points (coordinate arrays) from the point (cx, cy, cz)."""
    return (xs - cx) ** 2 + (ys - cy) ** 2 + (zs - cz) ** 2


@_jit_fast
def _assign(
    xs: np.ndarray, ys: np.ndarray, zs: np.ndarray, centers: np.ndarray, labels: np.ndarray, sums: np.ndarray
) -> None:
    """Label every point with its nearest centre (lowest index on ties) and fill the (k, 5) per-cluster
    sums of ``[x, y, z, 1, |p|^2]``: one branch-free pass over the points per cluster to label, one to sum."""
    k = centers.shape[0]
    nearest = _sq_dists(xs, ys, zs, centers[0, 0], centers[0, 1], centers[0, 2])
    labels[:] = 0
    for j in range(1, k):  # branch-free and vectorised over the points: labels are spatially mixed
        cx, cy, cz = centers[j, 0], centers[j, 1], centers[j, 2]
        for i in range(xs.shape[0]):
            d = (xs[i] - cx) ** 2 + (ys[i] - cy) ** 2 + (zs[i] - cz) ** 2
            closer = d < nearest[i]
            nearest[i] = d if closer else nearest[i]
            labels[i] = j if closer else labels[i]
    for j in range(k):
        sx = sy = sz = count = sq = 0.0
        for i in range(xs.shape[0]):
            w = 1.0 if labels[i] == j else 0.0
            x, y, z = xs[i], ys[i], zs[i]
            sx += w * x
            sy += w * y
            sz += w * z
            count += w
            sq += w * (x * x + y * y + z * z)
        sums[j, 0], sums[j, 1], sums[j, 2], sums[j, 3], sums[j, 4] = sx, sy, sz, count, sq


@_jit_fast
def slab_spans(
    points: np.ndarray,
    centers: np.ndarray,
    rotations: np.ndarray,
    half_width: float,
    z_lo: float,
    z_hi: float,
) -> np.ndarray:
    """Span [y_lo, y_hi] of the points with ``|x| <= half_width`` and ``z_lo <= z <= z_hi`` in each frame.

    points : (N, 3) float64 world; centers : (B, 3) frame origins; rotations : (B, 3, 3) frame axes as
    columns. Returns (B, 2) float64 relative to each origin, [0, 0] where no point qualifies
    (:func:`graspexp.planning.pose.slab_spans_m`). Requires finite inputs (fastmath). Consecutive frames
    with one rotation share one cull of the points (:func:`_run_cull`); a lone frame scans them all.
    """
    xs, ys, zs = _soa(points)  # structure of arrays: the first pass vectorises
    pts32 = _soa32(points)
    n = xs.shape[0]
    out = np.zeros((rotations.shape[0], 2))
    y_lo = np.empty(n)  # y where inside, else +big
    y_hi = np.empty(n)  # y where inside, else -big
    keep, cull, idx = np.empty(n, dtype=np.bool_), np.empty((3, n)), np.empty(n, dtype=np.int64)
    box = np.array([[half_width, z_lo, z_hi]])
    b = 0
    while b < rotations.shape[0]:
        if b + 1 == rotations.shape[0] or np.any(rotations[b + 1] != rotations[b]):  # a lone frame
            _slab_span(xs, ys, zs, n, rotations[b], centers[b], half_width, z_lo, z_hi, y_lo, y_hi, out[b])
            b += 1
            continue
        end, k = _run_cull(pts32, xs, ys, zs, rotations, centers, b, box, keep, cull, idx)
        for g in range(b, end):
            _slab_span(
                cull[0],
                cull[1],
                cull[2],
                k,
                rotations[g],
                centers[g],
                half_width,
                z_lo,
                z_hi,
                y_lo,
                y_hi,
                out[g],
            )
        b = end
    return out


@_jit_fast
def _slab_span(
    xs: np.ndarray,
    ys: np.ndarray,
    zs: np.ndarray,
    k: int,
    r: np.ndarray,
    c: np.ndarray,
    half_width: float,
    z_lo: float,
    z_hi: float,
    y_lo: np.ndarray,
    y_hi: np.ndarray,
    out: np.ndarray,
) -> None:
    """:func:`slab_spans` of the first ``k`` points (coordinate arrays, world) in the frame of rotation
    ``r`` (3, 3) at origin ``c`` (3,), written into ``out`` (2,) where some point is inside; ``y_lo``,
    ``y_hi`` (N,) are scratch."""
    big = 1e30  # a finite sentinel: fastmath assumes no inf
    cx, cy, cz = c[0], c[1], c[2]
    for i in range(k):
        px, py, pz = xs[i] - cx, ys[i] - cy, zs[i] - cz
        x = r[0, 0] * px + r[1, 0] * py + r[2, 0] * pz
        y = r[0, 1] * px + r[1, 1] * py + r[2, 1] * pz
        z = r[0, 2] * px + r[1, 2] * py + r[2, 2] * pz
        inside = (abs(x) <= half_width) & (z >= z_lo) & (z <= z_hi)  # no short circuit: selects
        y_lo[i] = y if inside else big
        y_hi[i] = y if inside else -big
    # A second, scalar pass: LLVM does not vectorise float min/max reductions without function-wide
    # no-NaN attributes, which numba does not set; fused into the first pass they halve its speed.
    lo, hi = _extremes(y_lo, y_hi, k, big)
    if lo <= hi:  # some point was inside
        out[0] = lo
        out[1] = hi


SLACK_M = 1e-9
"""Added to a cull's bound, m: far above the rounding of coordinates below a kilometre, so a point culled
by :func:`_run_cull` fails the exact test too."""


@jit_kernel
def _soa(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The (N, 3) points as three contiguous (N,) coordinate arrays (structure of arrays: loops vectorise)."""
    return (
        np.ascontiguousarray(points[:, 0]),
        np.ascontiguousarray(points[:, 1]),
        np.ascontiguousarray(points[:, 2]),
    )


@jit_kernel
def _rotation_run(rotations: np.ndarray, origins: np.ndarray, b: int) -> tuple[int, float, float, float]:
    """End (exclusive) of the run of frames from ``b`` whose (3, 3) rotation is bitwise ``rotations[b]``,
    and how far their origins (B, 3) lie from ``origins[b]`` along that rotation's axes, m: the largest
    distance along X and the smallest and largest offset along Z (the frames of one path and roll move
    along their Y and Z axes only)."""
    r, o = rotations[b], origins[b]
    end, dx, dz_lo, dz_hi = b + 1, 0.0, 0.0, 0.0
    while end < rotations.shape[0]:
        q = rotations[end]
        same = True
        for i in range(3):
            for j in range(3):
                same = same and q[i, j] == r[i, j]
        if not same:
            break
        d0, d1, d2 = origins[end, 0] - o[0], origins[end, 1] - o[1], origins[end, 2] - o[2]
        dx = max(dx, abs(r[0, 0] * d0 + r[1, 0] * d1 + r[2, 0] * d2))
        dz = r[0, 2] * d0 + r[1, 2] * d1 + r[2, 2] * d2
        dz_lo, dz_hi = min(dz_lo, dz), max(dz_hi, dz)
        end += 1
    return end, dx, dz_lo, dz_hi


@jit_kernel
def _soa32(points: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, float]:
    """The (N, 3) points as three float32 coordinate arrays (the cull's pass moves half the bytes and
    runs twice as wide) and the slack, m, that covers the float32 rounding of a frame coordinate computed
    from them (:func:`_run_cull`): ``SLACK_M`` plus 1e-6 x the largest coordinate magnitude, generous
    for float32's 6e-8 relative step."""
    x32, y32, z32 = (
        points[:, 0].astype(np.float32),
        points[:, 1].astype(np.float32),
        points[:, 2].astype(np.float32),
    )
    return x32, y32, z32, SLACK_M + 1e-6 * (np.abs(points).max() if points.shape[0] else 0.0)


@jit_kernel
def _run_cull(
    pts32: tuple[np.ndarray, np.ndarray, np.ndarray, float],
    xs: np.ndarray,
    ys: np.ndarray,
    zs: np.ndarray,
    rotations: np.ndarray,
    origins: np.ndarray,
    b: int,
    boxes: np.ndarray,
    keep: np.ndarray,
    cull: np.ndarray,
    idx: np.ndarray,
) -> tuple[int, int]:
    """The end of the run of frames from ``b`` (:func:`_rotation_run`) and the count ``k`` of the points
    (coordinate arrays, world) that may lie, in some frame of the run, in one of the slabs ``boxes``
    (S, 3), S = 1 or 2, rows [half x, z lo, z hi] (``|x| <= half x``, ``z lo <= z <= z hi``, any y, frame axes, m);
    their coordinates are copied into the first ``k`` columns of ``cull`` (3, N) and their indices,
    ascending, into ``idx``. ``keep`` (N,) bool is scratch. The test runs in float32 on ``pts32``
    (:func:`_soa32`), its bounds those of frame ``b`` grown by the run's offsets, the float32 slack (the
    origin's magnitude included) and :data:`SLACK_M`: every point left out fails the exact test in every
    frame."""
    x32, y32, z32, slack = pts32
    end, dx, dz_lo, dz_hi = _rotation_run(rotations, origins, b)
    r, o = rotations[b], origins[b]
    slack += 1e-6 * max(abs(o[0]), abs(o[1]), abs(o[2]))
    ax, ay, az = np.float32(r[0, 0]), np.float32(r[1, 0]), np.float32(r[2, 0])
    cx, cy, cz = np.float32(r[0, 2]), np.float32(r[1, 2]), np.float32(r[2, 2])
    off_x = np.float32(r[0, 0] * o[0] + r[1, 0] * o[1] + r[2, 0] * o[2])
    off_z = np.float32(r[0, 2] * o[0] + r[1, 2] * o[1] + r[2, 2] * o[2])
    last = boxes.shape[0] - 1  # one slab or two: a single slab is tested twice
    x0, x1 = np.float32(boxes[0, 0] + dx + slack), np.float32(boxes[last, 0] + dx + slack)
    z0_lo, z1_lo = np.float32(boxes[0, 1] + dz_lo - slack), np.float32(boxes[last, 1] + dz_lo - slack)
    z0_hi, z1_hi = np.float32(boxes[0, 2] + dz_hi + slack), np.float32(boxes[last, 2] + dz_hi + slack)
    for i in range(xs.shape[0]):  # vectorised; both slabs from one pair of frame coordinates
        x = abs(ax * x32[i] + ay * y32[i] + az * z32[i] - off_x)
        z = cx * x32[i] + cy * y32[i] + cz * z32[i] - off_z
        keep[i] = ((x <= x0) & (z >= z0_lo) & (z <= z0_hi)) | ((x <= x1) & (z >= z1_lo) & (z <= z1_hi))
    k = 0
    for i in range(xs.shape[0]):  # branch-free: the kept points are spatially mixed
        idx[k] = i
        k += keep[i]
    for j in range(k):
        i = idx[j]
        cull[0, j], cull[1, j], cull[2, j] = xs[i], ys[i], zs[i]
    return end, k


@jit_kernel
def _pad_reach(
    r: np.ndarray,
    cull: np.ndarray,
    k: int,
    half_width: float,
    z_lo: float,
    z_hi: float,
    xs: np.ndarray,
    ys: np.ndarray,
    zs: np.ndarray,
    y_lo: np.ndarray,
    y_hi: np.ndarray,
) -> tuple[float, float]:
    """The first ``k`` world points of ``cull`` (3, N) in the frame of the (4, 4) world pose ``r``, written
    into ``xs`` (|x|), ``ys`` and ``zs``, and into ``y_lo`` / ``y_hi`` y where the point is in the pads'
    reach (``|x| <= half_width``, ``z_lo <= z <= z_hi``), else +inf / -inf; returns the reach's extreme
    (lo, hi) along y, (inf, -inf) where no point is in it."""
    for i in range(k):  # vectorised
        px, py, pz = cull[0, i] - r[0, 3], cull[1, i] - r[1, 3], cull[2, i] - r[2, 3]
        x = abs(r[0, 0] * px + r[1, 0] * py + r[2, 0] * pz)
        y = r[0, 1] * px + r[1, 1] * py + r[2, 1] * pz
        z = r[0, 2] * px + r[1, 2] * py + r[2, 2] * pz
        inside = (x <= half_width) & (z >= z_lo) & (z <= z_hi)
        xs[i], ys[i], zs[i] = x, y, z
        y_lo[i] = y if inside else np.inf
        y_hi[i] = y if inside else -np.inf
    lo, hi = _extremes(y_lo, y_hi, k, np.inf)
    return lo, hi


@jit_kernel
def _extremes(y_lo: np.ndarray, y_hi: np.ndarray, k: int, big: float) -> tuple[float, float]:
    """The smallest of ``y_lo[:k]`` and ``big`` and the largest of ``y_hi[:k]`` and ``-big`` (no NaN), in
    four independent chains of selects each (one chain waits on every compare: four run at once). The
    extremes' values are those of one chain; only a zero's sign may differ (+0 and -0 compare equal, and
    one chain keeps the first in order), so a zero is redone in one chain."""
    l0, l1, l2, l3 = big, big, big, big
    h0, h1, h2, h3 = -big, -big, -big, -big
    k4 = k - k % 4
    for i in range(0, k4, 4):
        l0 = y_lo[i] if y_lo[i] < l0 else l0
        l1 = y_lo[i + 1] if y_lo[i + 1] < l1 else l1
        l2 = y_lo[i + 2] if y_lo[i + 2] < l2 else l2
        l3 = y_lo[i + 3] if y_lo[i + 3] < l3 else l3
        h0 = y_hi[i] if y_hi[i] > h0 else h0
        h1 = y_hi[i + 1] if y_hi[i + 1] > h1 else h1
        h2 = y_hi[i + 2] if y_hi[i + 2] > h2 else h2
        h3 = y_hi[i + 3] if y_hi[i + 3] > h3 else h3
    for i in range(k4, k):
        l0 = y_lo[i] if y_lo[i] < l0 else l0
        h0 = y_hi[i] if y_hi[i] > h0 else h0
    l0, l2 = (l1 if l1 < l0 else l0), (l3 if l3 < l2 else l2)
    h0, h2 = (h1 if h1 > h0 else h0), (h3 if h3 > h2 else h2)
    lo, hi = (l2 if l2 < l0 else l0), (h2 if h2 > h0 else h0)
    if lo == 0.0 or hi == 0.0:  # which of +0 and -0: the first in point order, as one chain keeps it
        lo, hi = big, -big
        for i in range(k):  # selects, no branches
            lo = y_lo[i] if y_lo[i] < lo else lo
            hi = y_hi[i] if y_hi[i] > hi else hi
    return lo, hi


@jit_kernel
def pad_contact_stats(
    points: np.ndarray,
    normals: np.ndarray,
    area: np.ndarray,
    poses: np.ndarray,
    half_width: float,
    z_lo: float,
    z_hi: float,
    band: float,
) -> np.ndarray:
    """Per grasp frame: [depth of the shallower pad's contact from ``z_hi``, larger contact-normal angle to
    the closing axis (rad), smaller share of contact points in ``area``] (:func:`graspexp.planning.
    stability.pad_contacts`). points, normals : (N, 3) world; area : (N,) bool; poses : (B, 4, 4).
    Returns (B, 3) float64; a side without contact points gives -inf, pi and 0. Consecutive poses with
    one rotation share one cull of the points (:func:`_run_cull`); the sums run in point order."""
    n = points.shape[0]
    out = np.empty((poses.shape[0], 3))
    px, py, pz = _soa(points)
    pts32 = _soa32(points)
    keep, cull, idx = np.empty(n, dtype=np.bool_), np.empty((3, n)), np.empty(n, dtype=np.int64)
    xs, ys, zs, y_lo, y_hi = np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    contact, hits = np.empty(n, dtype=np.uint8), np.empty(n, dtype=np.int64)  # a frame's contact points
    box = np.array([[half_width, z_lo, z_hi]])
    b = 0
    while b < poses.shape[0]:
        end, k = _run_cull(pts32, px, py, pz, poses[:, :3, :3], poses[:, :3, 3], b, box, keep, cull, idx)
        for g in range(b, end):
            r = poses[g]
            lo, hi = _pad_reach(r, cull, k, half_width, z_lo, z_hi, xs, ys, zs, y_lo, y_hi)
            if lo > hi:
                out[g, 0], out[g, 1], out[g, 2] = -np.inf, np.pi, 0.0
                continue
            left_from, right_to = hi - band, lo + band
            for j in range(k):  # vectorised
                contact[j] = (y_hi[j] >= left_from) | (y_lo[j] <= right_to)
            m = 0
            for j in range(k):  # branch-free: a branch per point mispredicts at every contact
                hits[m] = j
                m += contact[j]
            sums = np.zeros((2, 6))  # per pad (left: +Y, right: -Y): count, in area, z, normal x, y, z
            for t in range(m):  # both pads in one pass, each summed in point order
                j = hits[t]
                left, right = y_hi[j] >= left_from, y_lo[j] <= right_to
                i = idx[j]
                # the normal in the grasp frame: R^T n
                nx = r[0, 0] * normals[i, 0] + r[1, 0] * normals[i, 1] + r[2, 0] * normals[i, 2]
                ny = r[0, 1] * normals[i, 0] + r[1, 1] * normals[i, 1] + r[2, 1] * normals[i, 2]
                nz = r[0, 2] * normals[i, 0] + r[1, 2] * normals[i, 1] + r[2, 2] * normals[i, 2]
                for side, hit in ((0, left), (1, right)):
                    if hit:
                        sums[side, 0] += 1
                        sums[side, 1] += area[i]
                        sums[side, 2] += zs[j]
                        sums[side, 3] += nx
                        sums[side, 4] += ny
                        sums[side, 5] += nz
            depth, angle, share = np.inf, 0.0, 1.0
            for side, sign in ((0, 1.0), (1, -1.0)):
                count, in_area, sum_z, nx_, ny, nz_ = sums[side]
                if count == 0:
                    depth, angle, share = -np.inf, np.pi, 0.0
                    continue
                depth = min(depth, z_hi - sum_z / count)
                length = np.sqrt(nx_ * nx_ + ny * ny + nz_ * nz_)
                a = np.pi if length == 0 else np.arccos(min(max(sign * ny / length, -1.0), 1.0))
                angle = max(angle, a)
                share = min(share, in_area / count)
            out[g, 0], out[g, 1], out[g, 2] = depth, angle, share
        b = end
    return out


@jit_kernel
def pad_edge_excess(
    points: np.ndarray,
    poses: np.ndarray,
    half_width: float,
    z_lo: float,
    z_hi: float,
    thickness: float,
    clearance: float,
) -> np.ndarray:
    """Per grasp frame: how far the object reaches past a pad's contact plane within ``clearance`` of that
    finger's side or tip faces, the larger of the two fingers', m (:func:`graspexp.planning.stability.
    pad_edge_excess_m`). points : (N, 3) world; poses : (B, 4, 4). Returns (B,) float64, -inf where no
    point lies there or no point is in the pads' reach."""
    n = points.shape[0]
    out = np.full(poses.shape[0], -np.inf)
    cull = np.ascontiguousarray(points.T)
    xs, ys, zs, y_lo, y_hi = np.empty(n), np.empty(n), np.empty(n), np.empty(n), np.empty(n)
    for b in range(poses.shape[0]):
        lo, hi = _pad_reach(poses[b], cull, n, half_width, z_lo, z_hi, xs, ys, zs, y_lo, y_hi)
        if lo > hi:
            continue
        worst = -np.inf
        for i in range(n):
            x, z = xs[i], zs[i]
            beside = x > half_width and x <= half_width + clearance and z >= z_lo and z <= z_hi + clearance
            beyond = x <= half_width + clearance and z > z_hi and z <= z_hi + clearance
            if not (beside or beyond):
                continue
            for past in (ys[i] - hi, lo - ys[i]):  # left finger beyond y = hi, right beyond y = lo
                if past <= thickness + clearance:
                    worst = max(worst, past)
        out[b] = worst
    return out


COUNT_ALL = np.iinfo(np.int64).max
"""``stop_at`` of the swept-volume kernels that counts every point (no early stop)."""


BOX_BLOCK = 128
"""Points counted per vectorised block of :func:`_box_hits` before the ``stop_at`` test."""


@jit_kernel
def _box_hits(
    cull: np.ndarray, k: int, r: np.ndarray, h: float, finger: np.ndarray, palm: np.ndarray, stop_at: int
) -> int:
    """Points among the first ``k`` of ``cull`` (3, N) world inside the swept boxes of the (4, 4) pose
    ``r`` with half opening ``h`` (:func:`swept_box_hits`), counted up to ``stop_at``: branch-free blocks
    of :data:`BOX_BLOCK` points (vectorised), the test after each block."""
    fx, ft, fz0, fz1, m = finger[0], finger[1], finger[2], finger[3], finger[4]
    px, py, pz0, pz1 = palm[0], palm[1], palm[2], palm[3]
    y0, y1 = h - m, h + ft + m
    count = 0
    for s in range(0, k, BOX_BLOCK):
        for i in range(s, min(s + BOX_BLOCK, k)):
            qx, qy, qz = cull[0, i] - r[0, 3], cull[1, i] - r[1, 3], cull[2, i] - r[2, 3]
            z = r[0, 2] * qx + r[1, 2] * qy + r[2, 2] * qz
            x = abs(r[0, 0] * qx + r[1, 0] * qy + r[2, 0] * qz)
            y = abs(r[0, 1] * qx + r[1, 1] * qy + r[2, 1] * qz)
            in_finger = (x <= fx) & (fz0 <= z) & (z <= fz1) & (y0 <= y) & (y <= y1)
            in_palm = (x <= px) & (y <= py) & (pz0 <= z) & (z <= pz1)
            count += in_finger | in_palm
        if count >= stop_at:
            return stop_at
    return count


@jit_kernel
def swept_box_hits(
    points: np.ndarray,
    poses: np.ndarray,
    half_widths: np.ndarray,
    finger: np.ndarray,
    palm: np.ndarray,
    stop_at: int,
) -> np.ndarray:
    """Points inside the swept finger and palm boxes of each grasp (:func:`graspexp.planning.collision.
    cloud_hits`). points : (N, 3) world; poses : (B, 4, 4); half_widths : (B,) half openings, m;
    finger : [half x, thickness, z lo, z hi, margin]; palm : [half x, half y, z lo, z hi], margin included
    except in ``finger``'s y bounds; a grasp's count stops at ``stop_at`` (1: is it free?). Consecutive
    poses with one rotation share one cull of the points (:func:`_run_cull`, by the finger and palm slabs).
    Returns (B,) int64."""
    n = points.shape[0]
    out = np.zeros(poses.shape[0], dtype=np.int64)
    xs, ys, zs = _soa(points)
    pts32 = _soa32(points)
    keep, cull, idx = np.empty(n, dtype=np.bool_), np.empty((3, n)), np.empty(n, dtype=np.int64)
    boxes = np.array([[finger[0], finger[2], finger[3]], [palm[0], palm[2], palm[3]]])
    b = 0
    while b < poses.shape[0]:
        end, k = _run_cull(pts32, xs, ys, zs, poses[:, :3, :3], poses[:, :3, 3], b, boxes, keep, cull, idx)
        for g in range(b, end):
            out[g] = _box_hits(cull, k, poses[g], half_widths[g], finger, palm, stop_at)
        b = end
    return out


@jit_kernel
def box_lowest_z(
    poses: np.ndarray, half_widths: np.ndarray, finger: np.ndarray, palm: np.ndarray
) -> np.ndarray:
    """Lowest world z of the swept finger and palm boxes of each grasp (:func:`graspexp.planning.collision.
    lowest_z`): per box ``t_z + sum_a min(R[2, a] lo_a, R[2, a] hi_a)`` summed over a = x, y, z in order,
    the smallest of the three boxes. poses : (B, 4, 4); half_widths : (B,) half openings, m;
    finger : [width, thickness, z lo, z hi]; palm : [x, y, z lo, z hi] (sizes, not halves), z lo swept.
    Returns (B,) float64, m."""
    out = np.empty(poses.shape[0])
    fx, ft = finger[0] / 2, finger[1]
    px, py = palm[0] / 2, palm[1] / 2
    for b in range(poses.shape[0]):
        r0, r1, r2 = poses[b, 2, 0], poses[b, 2, 1], poses[b, 2, 2]
        h = half_widths[b]
        sx = min(r0 * -fx, r0 * fx)
        sz = min(r2 * finger[2], r2 * finger[3])
        left = sx + min(r1 * h, r1 * (h + ft)) + sz
        right = sx + min(r1 * (-h - ft), r1 * -h) + sz
        base = min(r0 * -px, r0 * px) + min(r1 * -py, r1 * py) + min(r2 * palm[2], r2 * palm[3])
        out[b] = poses[b, 2, 3] + min(min(left, right), base)
    return out


@jit_kernel
def swept_hull_hits(
    points: np.ndarray,
    poses: np.ndarray,
    half_widths: np.ndarray,
    normals: np.ndarray,
    offsets: np.ndarray,
    slides: np.ndarray,
    lo: np.ndarray,
    hi: np.ndarray,
    stop_at: int,
) -> np.ndarray:
    """Points inside any swept convex piece of each grasp (:func:`graspexp.planning.hull_sweep.
    hull_cloud_hits`). points : (N, 3) world; poses : (B, 4, 4); half_widths : (B,) half openings, m;
    normals : (P, F, 3) and offsets : (P, F) the pieces' half-spaces ``n . p <= offset`` at zero opening,
    margin included (padding rows: zero normal, offset 1); slides : (P,) +1, -1 or 0, how half the opening
    moves a piece along +Y; lo, hi : (P, 3) the pieces' bounding boxes at zero opening, margin included; a
    grasp's count stops at ``stop_at`` (1: is it free?). Returns (B,) int64."""
    out = np.zeros(poses.shape[0], dtype=np.int64)
    for b in range(poses.shape[0]):
        r = poses[b]
        h = half_widths[b]
        count = 0
        for i in range(points.shape[0]):
            qx, qy, qz = points[i, 0] - r[0, 3], points[i, 1] - r[1, 3], points[i, 2] - r[2, 3]
            x = r[0, 0] * qx + r[1, 0] * qy + r[2, 0] * qz
            y = r[0, 1] * qx + r[1, 1] * qy + r[2, 1] * qz
            z = r[0, 2] * qx + r[1, 2] * qy + r[2, 2] * qz
            for p in range(normals.shape[0]):
                yp = y - slides[p] * h
                if (
                    x < lo[p, 0]
                    or x > hi[p, 0]
                    or yp < lo[p, 1]
                    or yp > hi[p, 1]
                    or z < lo[p, 2]
                    or z > hi[p, 2]
                ):
                    continue
                inside = True
                for f in range(normals.shape[1]):
                    if normals[p, f, 0] * x + normals[p, f, 1] * yp + normals[p, f, 2] * z > offsets[p, f]:
                        inside = False
                        break
                if inside:
                    count += 1
                    break
            if count >= stop_at:
                break
        out[b] = count
    return out
