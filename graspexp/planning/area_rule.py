"""Where a grasp's pads may touch: the grasping-area rule of the planners that check their pad contacts
(keys of :class:`graspexp.config.planner.base.AreaContactConfig`).

A try passes when the smaller of its two pads' shares of contact points in the grasping area
(:func:`graspexp.planning.stability.pad_contacts`) is at least the share required: first
``min_contacts_in_area``; when no try passes, in the modes of ``fallback_modes``, the largest share any
otherwise passing try reached, if that is at least ``fallback_contacts_in_area``.
"""

import numpy as np

from graspexp.planning.request import PlanRequest


def area_test(held: np.ndarray, share: np.ndarray, need: float) -> tuple[np.ndarray, int, float]:
    """For (B,) tries ``held`` (passing every other check) and their (B,) in-area ``share``: (B,) the
    tries with at least ``need`` of each pad's contact in the area, how many of ``held`` fail only this,
    and the largest share among ``held`` (0 if none)."""
    ok = held & (share >= need)
    return ok, int((held & ~ok).sum()), float(share[held].max()) if held.any() else 0.0


def fallback_share(req: PlanRequest, best_share: float) -> float | None:
    """The share a second search requires after none passed with ``min_contacts_in_area``, given the
    largest share ``best_share`` (0-1) of the tries that passed every other check; None: no fallback
    (not one of ``fallback_modes``, or ``best_share`` below ``fallback_contacts_in_area``)."""
    pl = req.planner
    if req.mode in pl.fallback_modes and pl.fallback_contacts_in_area <= best_share < pl.min_contacts_in_area:
        return best_share
    return None


def no_grasp_in_area(req: PlanRequest, best_share: float) -> str:
    """The end of a NoFeasibleGrasp message: how close the area came and why no fallback was taken."""
    pl = req.planner
    return (
        f"less than {pl.min_contacts_in_area} of a pad's contact in the grasping area (the best passing try: "
        f"{best_share:.2f}; fallback_contacts_in_area {pl.fallback_contacts_in_area} in the modes "
        f"{list(pl.fallback_modes)}, this is {req.mode})"
    )
