"""Compiled test of a clutter round's neighbours between the pads (:func:`graspexp.planning.collision.
neighbour_hits`); its own module, so that the numba cache of :mod:`graspexp.planning.kernels` stays valid."""

import numpy as np

from graspexp.planning.kernels import _jit


@_jit
def between_pads_hits(
    points: np.ndarray, poses: np.ndarray, half_widths: np.ndarray, box: np.ndarray
) -> np.ndarray:
    """(B,) bool: whether a point lies between the pads of each grasp: in the grasp frame ``|x| <= box[0]``,
    ``|y| < half_widths[g]``, ``box[1] <= z <= box[2]``. points : (N, 3) world m; poses : (B, 4, 4) world;
    half_widths : (B,) m. A grasp's scan ends at its first such point."""
    out = np.zeros(poses.shape[0], dtype=np.bool_)
    hx, zlo, zhi = box[0], box[1], box[2]
    for g in range(poses.shape[0]):
        p = poses[g]
        tx, ty, tz, h = p[0, 3], p[1, 3], p[2, 3], half_widths[g]
        for i in range(points.shape[0]):
            dx, dy, dz = points[i, 0] - tx, points[i, 1] - ty, points[i, 2] - tz
            z = p[0, 2] * dx + p[1, 2] * dy + p[2, 2] * dz
            if z < zlo or z > zhi:
                continue
            x = p[0, 0] * dx + p[1, 0] * dy + p[2, 0] * dz
            if abs(x) > hx:
                continue
            if abs(p[0, 1] * dx + p[1, 1] * dy + p[2, 1] * dz) < h:
                out[g] = True
                break
    return out
