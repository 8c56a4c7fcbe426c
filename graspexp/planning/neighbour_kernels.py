"""Compiled test of a clutter round's neighbours against the swept gripper (:func:`graspexp.planning.
collision.neighbour_hits`); its own module, so that the numba cache of :mod:`graspexp.planning.kernels`
stays valid."""

import numpy as np

from graspexp.planning.kernels import jit_kernel


@jit_kernel
def _box_gap_sq(x: float, y: float, z: float, hx: float, hy: float, z0: float, z1: float) -> float:
    """Squared distance from the point (x, y, z) (frame axes, m) to the box ``|x| <= hx, |y| <= hy,
    z0 <= z <= z1``, m^2 (0 inside)."""
    dx = max(abs(x) - hx, 0.0)
    dy = max(abs(y) - hy, 0.0)
    dz = max(z0 - z, 0.0, z - z1)
    return dx * dx + dy * dy + dz * dz


@jit_kernel
def cells_swept_hits(
    points: np.ndarray,
    starts: np.ndarray,
    centres: np.ndarray,
    radii: np.ndarray,
    poses: np.ndarray,
    half_widths: np.ndarray,
    finger: np.ndarray,
    palm: np.ndarray,
    pads: np.ndarray,
    boxes: bool,
    between: bool,
) -> np.ndarray:
    """(B,) bool: whether a point of the cubed cloud (:class:`graspexp.planning.cells.CellCloud`: points,
    starts, centres, radii) lies, in the frame of a grasp (poses (B, 4, 4) world, half openings
    half_widths (B,) m), with ``between``, between the pads: ``|x| <= pads[0]``, ``|y| < half_widths[g]``,
    ``pads[1] <= z <= pads[2]``, or, with ``boxes``, in the swept finger and palm boxes of
    :func:`graspexp.planning.kernels.swept_box_hits` (finger [half x, thickness, z lo, z hi, margin], palm
    [half x, half y, z lo, z hi]). A cube whose bounding sphere misses the union of those boxes is skipped;
    the others' points get the exact tests, the same expressions as a scan of every point, so the result
    is that scan's. A grasp's scan ends at its first such point."""
    out = np.zeros(poses.shape[0], dtype=np.bool_)
    fx, ft, fz0, fz1, m = finger[0], finger[1], finger[2], finger[3], finger[4]
    px, py, pz0, pz1 = palm[0], palm[1], palm[2], palm[3]
    hx, zlo, zhi = pads[0], pads[1], pads[2]
    for g in range(poses.shape[0]):
        r = poses[g]
        tx, ty, tz, h = r[0, 3], r[1, 3], r[2, 3], half_widths[g]
        y0, y1 = h - m, h + ft + m
        # bounds of the fingers with the gap between them (box A) and of the palm (box B), frame axes
        ax, ay, az0, az1 = (hx, h, zlo, zhi) if between else (fx, y1, fz0, fz1)
        if boxes:
            ax, ay, az0, az1 = max(ax, fx), max(ay, y1), min(az0, fz0), max(az1, fz1)
        for c in range(centres.shape[0]):
            qx, qy, qz = centres[c, 0] - tx, centres[c, 1] - ty, centres[c, 2] - tz
            x = r[0, 0] * qx + r[1, 0] * qy + r[2, 0] * qz
            y = r[0, 1] * qx + r[1, 1] * qy + r[2, 1] * qz
            z = r[0, 2] * qx + r[1, 2] * qy + r[2, 2] * qz
            reach = radii[c] * radii[c]
            gap = _box_gap_sq(x, y, z, ax, ay, az0, az1)
            if boxes:
                gap = min(gap, _box_gap_sq(x, y, z, px, py, pz0, pz1))
            if gap > reach:
                continue
            for i in range(starts[c], starts[c + 1]):
                dx, dy, dz = points[i, 0] - tx, points[i, 1] - ty, points[i, 2] - tz
                z = r[0, 2] * dx + r[1, 2] * dy + r[2, 2] * dz
                x = abs(r[0, 0] * dx + r[1, 0] * dy + r[2, 0] * dz)
                y = abs(r[0, 1] * dx + r[1, 1] * dy + r[2, 1] * dz)
                hit = between and (x <= hx) & (y < h) & (zlo <= z) & (z <= zhi)
                if boxes:
                    hit |= (x <= fx) & (fz0 <= z) & (z <= fz1) & (y0 <= y) & (y <= y1)
                    hit |= (x <= px) & (y <= py) & (pz0 <= z) & (z <= pz1)
                if hit:
                    out[g] = True
                    break
            if out[g]:
                break
    return out


@jit_kernel
def cube_sort(points: np.ndarray, side: float, slack: float):
    """The (N, 3) cloud ``points`` (m) sorted into cubes of side ``side`` (m) from its lowest corner, by a
    counting sort: (sorted points (N, 3), starts (C + 1,) int64, centres (C, 3), radii (C,)) of the C
    occupied cubes: a cube's points ``sorted[starts[c]:starts[c + 1]]``, the middle of their box and the
    farthest of them from it plus ``slack``, m (:class:`graspexp.planning.cells.CellCloud`). A point's cube
    is its offset from the corner times ``1 / side``, truncated: one at a cube's face may fall in either
    cube, and either is right (a cube's sphere bounds the points it holds, whichever they are). Bounds
    are kept in scalars (registers), and a cube's radius is the root of its largest squared distance
    (the root is monotonic: the largest root, bit for bit)."""
    n = points.shape[0]
    x0, y0, z0 = points[0, 0], points[0, 1], points[0, 2]
    x1, y1, z1 = x0, y0, z0
    for i in range(n):
        x, y, z = points[i, 0], points[i, 1], points[i, 2]
        x0, x1 = min(x0, x), max(x1, x)
        y0, y1 = min(y0, y), max(y1, y)
        z0, z1 = min(z0, z), max(z1, z)
    inv = 1.0 / side
    nx, ny, nz = int((x1 - x0) * inv) + 1, int((y1 - y0) * inv) + 1, int((z1 - z0) * inv) + 1
    cube = np.empty(n, dtype=np.int64)
    counts = np.zeros(nx * ny * nz + 1, dtype=np.int64)
    for i in range(n):
        ix = min(int((points[i, 0] - x0) * inv), nx - 1)
        iy = min(int((points[i, 1] - y0) * inv), ny - 1)
        iz = min(int((points[i, 2] - z0) * inv), nz - 1)
        c = (ix * ny + iy) * nz + iz
        cube[i] = c
        counts[c + 1] += 1
    occupied = 0
    for b in range(1, counts.shape[0]):
        occupied += counts[b] > 0
        counts[b] += counts[b - 1]
    fill = counts[:-1].copy()
    out = np.empty((n, 3))
    for i in range(n):
        j = fill[cube[i]]
        out[j, 0], out[j, 1], out[j, 2] = points[i, 0], points[i, 1], points[i, 2]
        fill[cube[i]] += 1
    starts = np.empty(occupied + 1, dtype=np.int64)
    centres = np.empty((occupied, 3))
    radii = np.empty(occupied)
    c = 0
    for b in range(counts.shape[0] - 1):
        s, e = counts[b], counts[b + 1]
        if e == s:
            continue
        starts[c] = s
        bx0, by0, bz0 = out[s, 0], out[s, 1], out[s, 2]
        bx1, by1, bz1 = bx0, by0, bz0
        for i in range(s + 1, e):
            bx0, bx1 = min(bx0, out[i, 0]), max(bx1, out[i, 0])
            by0, by1 = min(by0, out[i, 1]), max(by1, out[i, 1])
            bz0, bz1 = min(bz0, out[i, 2]), max(bz1, out[i, 2])
        cx, cy, cz = (bx0 + bx1) / 2, (by0 + by1) / 2, (bz0 + bz1) / 2
        far = 0.0
        for i in range(s, e):
            d0, d1, d2 = out[i, 0] - cx, out[i, 1] - cy, out[i, 2] - cz
            far = max(far, d0 * d0 + d1 * d1 + d2 * d2)
        centres[c, 0], centres[c, 1], centres[c, 2] = cx, cy, cz
        radii[c] = np.sqrt(far) + slack
        c += 1
    starts[occupied] = n
    return out, starts, centres, radii


@jit_kernel
def occupancy_grid(points: np.ndarray, side: float, max_cells: int):
    """Which cubes of side ``side`` (m; cube ``floor(p / side)`` per axis, as :func:`graspexp.planning.
    cells.cube_keys`) hold a point of ``points`` (N, 3): a (X, Y, Z) uint8 grid over the occupied cubes' box
    and the index of its first cube (3,) int64; an empty (0, 0, 0) grid when the box exceeds ``max_cells``."""
    n = points.shape[0]
    first = np.empty(3, dtype=np.int64)
    dims = np.empty(3, dtype=np.int64)
    for a in range(3):
        lo, hi = np.inf, -np.inf
        for i in range(n):
            lo, hi = min(lo, points[i, a]), max(hi, points[i, a])
        first[a] = int(np.floor(lo / side))
        dims[a] = int(np.floor(hi / side)) - first[a] + 1
    if dims[0] * dims[1] * dims[2] > max_cells:
        return np.zeros((0, 0, 0), dtype=np.uint8), first
    grid = np.zeros((dims[0], dims[1], dims[2]), dtype=np.uint8)
    for i in range(n):
        grid[
            int(np.floor(points[i, 0] / side)) - first[0],
            int(np.floor(points[i, 1] / side)) - first[1],
            int(np.floor(points[i, 2] / side)) - first[2],
        ] = 1
    return grid, first


@jit_kernel
def paths_clear(
    centers: np.ndarray,
    steps: np.ndarray,
    directions: np.ndarray,
    grid: np.ndarray,
    first: np.ndarray,
    side: float,
) -> np.ndarray:
    """(K, M) bool: whether no sample ``centers[k] - steps[k, s] * directions[k, p]`` (m) of path (k, p)
    lies in an occupied cube of ``grid`` (:func:`occupancy_grid`, cubes of side ``side``, m). The samples
    are the same expressions as numpy's broadcast, so the cubes are those of a vectorised sampling."""
    k_n, m_n, s_n = directions.shape[0], directions.shape[1], steps.shape[1]
    nx, ny, nz = grid.shape
    out = np.ones((k_n, m_n), dtype=np.bool_)
    for k in range(k_n):
        for p in range(m_n):
            for s in range(s_n):
                st = steps[k, s]
                ix = int(np.floor((centers[k, 0] - st * directions[k, p, 0]) / side)) - first[0]
                iy = int(np.floor((centers[k, 1] - st * directions[k, p, 1]) / side)) - first[1]
                iz = int(np.floor((centers[k, 2] - st * directions[k, p, 2]) / side)) - first[2]
                if 0 <= ix < nx and 0 <= iy < ny and 0 <= iz < nz and grid[ix, iy, iz]:
                    out[k, p] = False
                    break
    return out
