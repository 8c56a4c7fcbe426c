"""Random baseline (a lower bound): a random approach through a random grasping-area point.

With ``rng = np.random.default_rng(req.seed)``, up to ``planner.n_candidates`` draws of:

- a grasp point uniformly among the grasping-area points (world frame, metres);
- an approach direction uniformly on the unit sphere;
- a rotation about it: the closing axis +Y uniformly on the circle orthogonal to the approach;
- the opening = ``gripper.max_width_m``.

The first draw whose gripper boxes (fingers and palm, over the straight approach from the pre-grasp
point ``planner.sphere_radius_m`` back) stay at or above ``table_z + planner.collision_margin_m`` is
returned, after moving it back along its approach by at most 80 % of the fingertip reach where that
clears the support (as every planner here may; :func:`graspexp.planning.collision.place_grasps`). The
approach is thus uniform conditioned on coming from above the support. No cloud check.
"""

import numpy as np

from graspexp.planning.collision import frame_from_axes, max_lift_m, support_lift_m
from graspexp.planning.grasp import Grasp, NoFeasibleGrasp
from graspexp.planning.request import PlanRequest, PlanResult

NAME = "random"

DRAW_BATCH = 64
"""Draws checked together."""


def plan_random(req: PlanRequest) -> PlanResult:
    """Plan one random grasp; see the module doc.

    Raises
    ------
    NoFeasibleGrasp
        Empty grasping area, or no draw clears the support within ``planner.n_candidates`` draws.
    """
    pl, gr = req.planner, req.gripper
    if pl.n_candidates < 1:
        raise ValueError(f"planner.n_candidates={pl.n_candidates!r} is invalid: expected a positive integer")
    points = np.asarray(req.points, dtype=np.float64)
    area = points[np.asarray(req.area_mask, dtype=bool)]
    if len(area) == 0:
        raise NoFeasibleGrasp("random: the grasping area is empty: no point of the cloud is in area_mask")
    rng = np.random.default_rng(req.seed)
    width = float(gr.max_width_m)
    drawn = 0
    while drawn < pl.n_candidates:
        n = min(DRAW_BATCH, int(pl.n_candidates) - drawn)
        centres = area[rng.integers(len(area), size=n)]
        approach = rng.normal(size=(n, 3))
        closing = rng.normal(size=(n, 3))
        poses = []
        for c, a, y in zip(centres, approach, closing, strict=True):
            if np.linalg.norm(np.cross(a, y)) < 1e-9:  # measure-zero: nudge the closing seed
                y = y + np.array([1.0, 0.0, 0.0])
            poses.append(frame_from_axes(a, y, c))
        poses = np.array(poses)
        lift = support_lift_m(
            poses, gr, width, sweep_m=pl.sphere_radius_m, table_z=req.table_z, margin_m=pl.collision_margin_m
        )
        ok = lift <= max_lift_m(gr)
        poses[ok, :3, 3] -= lift[ok, None] * poses[ok, :3, 2]
        if ok.any():
            j = int(np.argmax(ok))
            grasp = Grasp(
                pose=poses[j],
                width_m=width,
                cost=0.0,
                cluster=-1,
                path=-1,
                n_feasible=int(ok.sum()),
                planner=NAME,
                extras={"draws": drawn + j + 1},
            )
            return PlanResult(
                grasp=grasp, details={"cloud": points, "pose": poses[j], "width": np.float64(width)}
            )
        drawn += n
    raise NoFeasibleGrasp(
        f"random: none of {drawn} random approaches keeps the gripper above the support plane "
        f"z = {req.table_z + pl.collision_margin_m:.4f} m"
    )
