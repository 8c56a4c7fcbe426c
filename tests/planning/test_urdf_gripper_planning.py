"""A URDF gripper in the planner: pieces made of the RG2's boxes give the box model's volume checks exactly;
a rounded fingertip is seen by its real shape; every planner plans with a URDF gripper."""

import numpy as np
import pytest
import trimesh
from helpers.config import compose_cfg
from helpers.objects import write_urdf_gripper
from helpers.planning import full_view
from omegaconf import OmegaConf

from graspexp.config.plugins import LoadedPlanner, load_planners
from graspexp.grippers import GripperGeometry
from graspexp.planning import PlanRequest, plan
from graspexp.planning.collision import cloud_hits, frame_from_axes, lowest_z
from graspexp.run.job_config import make_ready

PLANNERS = tuple(
    sorted(
        n
        for n, p in load_planners().items()
        if isinstance(p, LoadedPlanner) and not p.plugin.needs_observation
    )
)


def _gripper(*overrides: str):
    cfg = compose_cfg(*overrides)
    make_ready(cfg)
    return OmegaConf.to_object(cfg).gripper


def _poses(rng: np.random.Generator, n: int) -> np.ndarray:
    return np.stack(
        [
            frame_from_axes(rng.normal(size=3), rng.normal(size=3), rng.normal(0.0, 0.03, size=3))
            for _ in range(n)
        ]
    )


def test_box_pieces_give_the_box_model_checks(tmp_path):
    rg2 = _gripper("gripper=rg2")
    urdf = _gripper("gripper=urdf", f"gripper.urdf={write_urdf_gripper(tmp_path, curved_tip=False)}")
    assert urdf.max_width_m == pytest.approx(rg2.max_width_m)
    rng = np.random.default_rng(0)
    points = rng.normal(0.0, 0.05, size=(4000, 3))
    poses, widths = _poses(rng, 64), rng.uniform(0.0, 0.11, size=64)
    for margin in (0.0, 0.003):
        box = cloud_hits(points, poses, rg2, widths, sweep_m=0.05, margin_m=margin)
        mesh = cloud_hits(points, poses, urdf, widths, sweep_m=0.05, margin_m=margin)
        assert box.sum() > 100 and np.array_equal(box, mesh)
    np.testing.assert_allclose(
        lowest_z(poses, urdf, widths, 0.05), lowest_z(poses, rg2, widths, 0.05), atol=1e-12
    )


def test_a_rounded_fingertip_is_checked_by_its_shape(tmp_path):
    gripper = _gripper("gripper=urdf", f"gripper.urdf={write_urdf_gripper(tmp_path)}")
    geometry = GripperGeometry.of(gripper)
    tip = geometry.tip_z_m  # the top of the half cylinder: radius 5 mm above the finger box at z = tip - 5 mm
    y = 0.02 + 0.005  # over the left finger's middle at opening 0.04
    pose = np.eye(4)[None]
    inside = np.array([[0.0, y, tip - 0.001]])
    corner = np.array([[0.0, y + 0.0045, tip - 0.001]])  # beside the arc, within the box's corner
    assert cloud_hits(inside, pose, gripper, 0.04, sweep_m=0.0, margin_m=0.0)[0] == 1
    assert cloud_hits(corner, pose, gripper, 0.04, sweep_m=0.0, margin_m=0.0)[0] == 0


@pytest.mark.parametrize("planner", PLANNERS)
def test_every_planner_plans_with_a_urdf_gripper(tmp_path, planner):
    cfg = compose_cfg(
        f"planner={planner}", "mode=bin", "gripper=urdf", f"gripper.urdf={write_urdf_gripper(tmp_path)}"
    )
    make_ready(cfg)
    cfg = OmegaConf.to_object(cfg)
    mesh = trimesh.creation.box(extents=[0.05, 0.04, 0.12])
    pts, faces = trimesh.sample.sample_surface_even(mesh, 768, seed=0)
    pts = pts + [0.0, 0.0, 0.1 + 0.06]
    normals = mesh.face_normals[faces]
    req = PlanRequest(
        pts,
        normals,
        np.ones(len(pts), bool),
        np.eye(4),
        0.1,
        "bin",
        cfg.gripper,
        cfg.planner,
        cfg.cost,
        3,
        observation=full_view(pts, normals),
    )
    grasp = plan(req).grasp
    assert np.isfinite(grasp.pose).all() and 0.0 <= grasp.width_m <= cfg.gripper.max_width_m
