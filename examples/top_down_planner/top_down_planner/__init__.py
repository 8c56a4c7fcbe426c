"""A graspexp planner plugin: approach straight down onto the grasping area's centroid, closing across
the area's narrower horizontal extent."""

from dataclasses import dataclass

import numpy as np

from graspexp.config import BASE_CONSTRAINTS, PlannerConfig, PlannerPlugin
from graspexp.config.constraints import Interval
from graspexp.planning import Grasp, NoFeasibleGrasp, PlanRequest, PlanResult


@dataclass
class TopDownConfig(PlannerConfig):
    clearance_m: float = 0.005
    """Opening = the area's width across the closing axis + 2 * this, m."""


def plan_top_down(req: PlanRequest) -> PlanResult:
    area = req.points[req.area_mask]
    if len(area) == 0:
        raise NoFeasibleGrasp("top_down: the grasping area is empty")
    centre = area.mean(axis=0)
    _, _, vt = np.linalg.svd(area[:, :2] - centre[:2], full_matrices=False)
    x = np.array([*vt[0], 0.0])  # main horizontal axis of the area
    z = np.array([0.0, 0.0, -1.0])  # approach: straight down
    y = np.cross(z, x)  # closing axis
    width = np.ptp(area @ y) + 2 * req.planner.clearance_m
    if width > req.gripper.max_width_m:
        raise NoFeasibleGrasp(f"top_down: the area is {width:.3f} m wide, wider than the stroke")
    pose = np.eye(4)
    pose[:3, :3], pose[:3, 3] = np.column_stack([x, y, z]), centre
    return PlanResult(Grasp(pose=pose, width_m=max(width, req.gripper.min_width_m)))


CONSTRAINTS = {**BASE_CONSTRAINTS, "clearance_m": [Interval(0, 0.05, unit="m")]}
PLUGIN = PlannerPlugin(plan=plan_top_down, config=TopDownConfig, constraints=CONSTRAINTS)
