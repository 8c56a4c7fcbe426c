"""Contact queries on a live scene: the one place that decides what "touching" and "holding" mean.

These run inside the step loop, so they work on plain Python floats (a few contacts of a few points each:
numpy's per-call overhead would cost more than the arithmetic).
"""

import math

import numpy as np
import sapien

from graspexp.core.bodies import FINGER_NAMES, OBJECT_NAME, PALM_NAME

GRIPPER_LINKS = frozenset({*FINGER_NAMES, PALM_NAME})
MIN_IMPULSE_NS = 1e-9
"""Contact points with a smaller impulse are proximity reports inside contact_offset, not touches."""


def _pair_names(contact: sapien.physx.PhysxContact) -> tuple[str, str]:
    b0, b1 = contact.bodies
    return b0.entity.name, b1.entity.name


def _touching(contact: sapien.physx.PhysxContact) -> bool:
    limit = MIN_IMPULSE_NS * MIN_IMPULSE_NS
    for p in contact.points:
        x, y, z = p.impulse.tolist()
        if x * x + y * y + z * z > limit:
            return True
    return False


def finger_forces(
    contacts: list, dt: float, closing_axis: np.ndarray, target: str = OBJECT_NAME
) -> dict[str, float]:
    """Squeezing force of each finger on the object (the body named ``target``) over the last step, N: the
    magnitude of the finger-object contact force along the closing axis ((3,) unit, world). A finger
    resting on the object's top, with its force along the approach, does not squeeze it."""
    out = dict.fromkeys(FINGER_NAMES, 0.0)
    for c in contacts:
        a, b = _pair_names(c)
        if target in (a, b):
            other = b if a == target else a
            if other in out:
                impulse = np.sum([p.impulse for p in c.points], axis=0)
                out[other] += abs(float(impulse @ closing_axis)) / dt
    return out


class SupportTouch:
    """Whether any gripper link presses on the support in the last step: only the gripper-support pairs are
    inspected (their bodies are matched by identity, without reading names or other pairs' points).

    support : the support's physx component; links : the gripper's link components.
    """

    def __init__(self, support: sapien.physx.PhysxRigidBaseComponent, links: list):
        self.support = support
        self.links = tuple(links)

    def __call__(self, contacts: list) -> bool:
        support, links = self.support, self.links
        for c in contacts:
            b0, b1 = c.bodies
            if (b0 is support and b1 in links) or (b1 is support and b0 in links):
                if _touching(c):
                    return True
        return False


def contact_records(contacts: list, dt: float) -> list[dict]:
    """One record per touching body pair for the log (world frame, N, m): the pair's total contact force
    on ``body0``, the force-weighted mean position and normal of its points, and the smallest separation.
    Pairs whose points all carry (near) zero impulse are proximity reports and are left out. Records are
    sorted by (body0, body1): PhysX reports the same pairs in an order that can change between processes
    (it did between a run that built its collision shapes and one that read them from the cache), and a
    log must not."""
    out = []
    for c in contacts:
        w_sum = px = py = pz = nx = ny = nz = fx = fy = fz = 0.0
        sep = math.inf
        for p in c.points:  # most points are proximity reports: their position and normal are not read
            s = p.separation
            if s < sep:
                sep = s
            ix, iy, iz = p.impulse.tolist()
            if ix == 0.0 and iy == 0.0 and iz == 0.0:
                continue
            w = math.sqrt(ix * ix + iy * iy + iz * iz)
            x, y, z = p.position.tolist()
            a, b, d = p.normal.tolist()
            w_sum += w
            px, py, pz = px + w * x, py + w * y, pz + w * z
            nx, ny, nz = nx + w * a, ny + w * b, nz + w * d
            fx, fy, fz = fx + ix, fy + iy, fz + iz
        if w_sum <= MIN_IMPULSE_NS:
            continue
        n = math.sqrt(nx * nx + ny * ny + nz * nz) or w_sum
        b0, b1 = _pair_names(c)
        out.append(
            {
                "body0": b0,
                "body1": b1,
                "position": [px / w_sum, py / w_sum, pz / w_sum],
                "normal": [nx / n, ny / n, nz / n],
                "force_n": [fx / dt, fy / dt, fz / dt],
                "separation_m": float(sep),
            }
        )
    out.sort(key=lambda r: (r["body0"], r["body1"]))
    return out


def gripper_touches(contacts: list, exclude: str) -> set[str]:
    """Names of the bodies other than the gripper's links and ``exclude`` that a gripper link touches
    (a clutter round's neighbours of the target ``exclude``, the support)."""
    out = set()
    for c in contacts:
        a, b = _pair_names(c)
        if (a in GRIPPER_LINKS) != (b in GRIPPER_LINKS):
            other = b if a in GRIPPER_LINKS else a
            if other != exclude and other not in out and _touching(c):
                out.add(other)
    return out
