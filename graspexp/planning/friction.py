"""The friction-cone test of two contacts, the one formula the antipodal planner and the force-closure
check share.

Contacts ``p1``, ``p2`` with outward normals ``n1``, ``n2``: with Coulomb friction ``mu`` a finger can push
along any direction inside the cone of half-angle ``atan(mu)`` about the inward normal, and the two
contacts are in force closure exactly when the line joining them lies inside both cones (Nguyen 1988):
``angle(v, -n1) <= atan(mu)`` and ``angle(-v, -n2) <= atan(mu)``, ``v = (p2 - p1) / |p2 - p1|``.
"""

import numpy as np


def line_cone_cosines(
    p1: np.ndarray, n1: np.ndarray, p2: np.ndarray, n2: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(d, cos1, cos2)`` of contact pairs, broadcast over the leading axes of (..., 3) inputs (m; normals
    outward, used as given): ``d = |p2 - p1|`` (m) and the cosines of ``angle(v, -n1)`` and
    ``angle(-v, -n2)`` (divide by the normals' norms for non-unit normals); nan where ``d == 0``."""
    v = np.asarray(p2, dtype=np.float64) - np.asarray(p1, dtype=np.float64)
    d = np.linalg.norm(v, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        v = v / d[..., None]
    cos1 = -np.einsum("...j,...j->...", n1, v)
    cos2 = np.einsum("...j,...j->...", n2, v)
    return d, cos1, cos2


def cone_cosine(mu: float) -> float:
    """Cosine of the friction cone's half-angle ``atan(mu)``: a line is inside the cone when the cosine
    of its angle to the inward normal is at least this."""
    return float(np.cos(np.arctan(mu)))
