"""Contact queries on a live scene: the one place that decides what "touching" and "holding" mean."""

import numpy as np
import sapien

from graspexp.sim.gripper import FINGER_NAMES
from graspexp.sim.scene import OBJECT_NAME, SUPPORT_NAME

GRIPPER_LINKS = frozenset({*FINGER_NAMES, "palm"})
MIN_IMPULSE_NS = 1e-9
"""Contact points with a smaller impulse are proximity reports inside contact_offset, not touches."""


def _pair_names(contact: sapien.physx.PhysxContact) -> tuple[str, str]:
    return contact.bodies[0].entity.name, contact.bodies[1].entity.name


def _touching(contact: sapien.physx.PhysxContact) -> bool:
    return any(np.linalg.norm(p.impulse) > MIN_IMPULSE_NS for p in contact.points)


def finger_forces(contacts: list, dt: float, closing_axis: np.ndarray) -> dict[str, float]:
    """Squeezing force of each finger on the object over the last step, N: the magnitude of the
    finger-object contact force along the closing axis ((3,) unit, world). A finger resting on the
    object's top, with its force along the approach, does not squeeze it."""
    out = dict.fromkeys(FINGER_NAMES, 0.0)
    for c in contacts:
        a, b = _pair_names(c)
        if OBJECT_NAME in (a, b):
            other = b if a == OBJECT_NAME else a
            if other in out:
                impulse = np.sum([p.impulse for p in c.points], axis=0)
                out[other] += abs(float(impulse @ closing_axis)) / dt
    return out


def gripper_touches_support(contacts: list) -> bool:
    """True if any gripper link presses on the support in the last step."""
    for c in contacts:
        a, b = _pair_names(c)
        if SUPPORT_NAME in (a, b) and (a in GRIPPER_LINKS or b in GRIPPER_LINKS) and _touching(c):
            return True
    return False


def contact_records(contacts: list, dt: float) -> list[dict]:
    """One record per touching body pair for the log (world frame, N, m): the pair's total contact force
    on ``body0``, the force-weighted mean position and normal of its points, and the smallest separation.
    Pairs whose points all carry (near) zero impulse are proximity reports and are left out."""
    out = []
    for c in contacts:
        pts = c.points
        imp = np.array([p.impulse for p in pts], dtype=float)
        w = np.sqrt((imp * imp).sum(axis=1))
        total = float(w.sum())
        if total <= MIN_IMPULSE_NS:
            continue
        a, b = _pair_names(c)
        pos = np.array([p.position for p in pts], dtype=float)
        nrm = (w @ np.array([p.normal for p in pts], dtype=float)) / total
        out.append(
            {
                "body0": a,
                "body1": b,
                "position": ((w @ pos) / total).tolist(),
                "normal": (nrm / (np.linalg.norm(nrm) or 1.0)).tolist(),
                "force_n": (imp.sum(axis=0) / dt).tolist(),
                "separation_m": float(min(p.separation for p in pts)),
            }
        )
    return out
