"""Planners among neighbours (a clutter round's ``PlanRequest.neighbours``): paths through another object
are dropped like paths through the support (III-D), the swept gripper meets no neighbour, and a planner
written for one object still plans for its target."""

import dataclasses

import numpy as np
import pytest
import trimesh
from helpers.planning import TABLE_Z, plain_cfg, resting_cloud

from graspexp.planning import plan
from graspexp.planning.collision import neighbour_hits
from graspexp.planning.grasp import NoFeasibleGrasp
from graspexp.planning.paths import clear_of
from graspexp.planning.request import Neighbour, PlanRequest


def _request(planner: str, neighbours: tuple[Neighbour, ...]) -> PlanRequest:
    cfg = plain_cfg(planner)
    pts, normals = resting_cloud(trimesh.creation.box([0.04, 0.06, 0.10]), 1024)
    pose = np.eye(4)
    pose[2, 3] = TABLE_Z + 0.05
    return PlanRequest(
        points=pts, normals=normals, area_mask=np.ones(len(pts), bool), object_pose=pose, table_z=TABLE_Z,
        mode="bin", gripper=cfg.gripper, planner=cfg.planner, cost=cfg.cost, seed=3, neighbours=neighbours,
    )  # fmt: skip


def _walls(axis: int = 0, gap_m: float = 0.02) -> tuple[Neighbour, ...]:
    """Two tall boxes ``gap_m`` from the target's faces across ``axis`` (0: x, 1: y): a grasp closing along
    that axis may need a finger where they stand."""
    out = []
    half = (0.02, 0.03)[axis]
    for i, sign in enumerate((1.0, -1.0)):
        size = [0.12, 0.12, 0.14]
        size[axis] = 0.05
        offset = np.zeros(3)
        offset[axis] = sign * (half + gap_m + 0.025)
        pts, _ = resting_cloud(trimesh.creation.box(size), 1024, seed=i)
        pose = np.eye(4)
        pose[:3, 3] = offset + [0.0, 0.0, TABLE_Z + 0.07]
        out.append(Neighbour(i + 1, f"wall{i}", pts + offset, pose))
    return tuple(out)


def test_paths_through_an_obstacle_are_dropped():
    centers = np.array([[0.0, 0.0, 0.0]])
    directions = np.array([[[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, -1.0]]])
    obstacle = np.array(
        [[-0.05, 0.0, 0.0]]
    )  # on the first path only: its sphere point is c - r d = (-0.1, 0, 0)
    ok = clear_of(centers, np.array([0.02]), directions, 0.1, obstacle, 0.01)
    assert ok.tolist() == [[False, True, True]]
    assert clear_of(centers, np.array([0.02]), directions, 0.1, np.zeros((0, 3)), 0.01).all()
    near = np.array([[-0.01, 0.0, 0.0]])  # within the cluster radius: the swept check's part of the path
    assert clear_of(centers, np.array([0.02]), directions, 0.1, near, 0.01).all()


@pytest.mark.parametrize(
    "planner, axis, gap_m", [("optimal", 1, 0.02), ("optimal_plus", 0, 0.02), ("antipodal", 0, 0.01)]
)
def test_the_chosen_grasp_meets_no_neighbour(planner, axis, gap_m):
    req = _request(planner, _walls(axis, gap_m))
    grasp = plan(req).grasp
    hit = neighbour_hits(
        req.neighbour_points, grasp.pose[None], req.gripper, np.array([grasp.width_m]),
        sweep_m=req.planner.sphere_radius_m, margin_m=0.0,
    )  # fmt: skip
    assert not hit[0]
    alone = plan(dataclasses.replace(req, neighbours=())).grasp
    alone_hit = neighbour_hits(
        req.neighbour_points, alone.pose[None], req.gripper, np.array([alone.width_m]),
        sweep_m=req.planner.sphere_radius_m, margin_m=0.0,
    )  # fmt: skip
    assert alone_hit[0]  # alone, the planner's choice would have met a neighbour


@pytest.mark.parametrize("planner", ["random", "obb"])
def test_planners_written_for_one_object_plan_for_the_target(planner):
    req = _request(planner, _walls())
    grasp = plan(req).grasp
    assert np.linalg.norm(grasp.pose[:3, 3] - req.object_pose[:3, 3]) < 0.1


def test_neighbours_between_the_pads_count():
    pose = np.eye(4)
    pose[:3, :3] = np.diag([1.0, -1.0, -1.0])  # approach straight down
    pose[:3, 3] = [0.0, 0.0, 0.2]
    cfg = plain_cfg("optimal")
    inside = np.array([[0.0, 0.0, 0.2]])  # at the TCP, between the open pads
    far = np.array([[0.5, 0.5, 0.0]])
    assert neighbour_hits(inside, pose[None], cfg.gripper, np.array([0.08]), sweep_m=0.1, margin_m=0.0)[0]
    assert not neighbour_hits(far, pose[None], cfg.gripper, np.array([0.08]), sweep_m=0.1, margin_m=0.0)[0]


@pytest.mark.parametrize("planner", ["optimal", "optimal_plus"])
def test_enclosed_target_falls_back_to_its_plan_alone(planner):
    """A neighbour shell around the target blocks every path: with ``planner.neighbour_fallback`` the
    grasp is the one planned for the target alone (optimal_plus) or a path clear of target and support
    (optimal), flagged as touching; without it, no grasp."""
    req = _request(planner, ())
    shell = trimesh.creation.box([0.09, 0.11, 0.15]).sample(6000, seed=5) + [0.0, 0.0, TABLE_Z + 0.05]
    shell = shell[shell[:, 2] > TABLE_Z + 0.005]
    boxed = dataclasses.replace(req, neighbours=(Neighbour(1, "shell", shell, np.eye(4)),))
    grasp = plan(boxed).grasp
    assert grasp.touches_neighbours
    if planner == "optimal_plus":
        alone = plan(req).grasp
        np.testing.assert_array_equal(grasp.pose, alone.pose)
        assert (grasp.width_m, grasp.cost, grasp.n_feasible) == (alone.width_m, alone.cost, alone.n_feasible)
    strict = dataclasses.replace(boxed, planner=dataclasses.replace(boxed.planner, neighbour_fallback=False))
    with pytest.raises(NoFeasibleGrasp):
        plan(strict)
