"""planner=antipodal_view plans on the camera's cloud only: from a one-sided view (no point of the far
side), without the model, and refuses a request without an observation in one line."""

import dataclasses

import numpy as np
import pytest
from helpers.planning import full_view
from omegaconf import OmegaConf

from graspexp.config.compose import compose_config
from graspexp.config.plugins import get_plugin
from graspexp.planning import NoFeasibleGrasp, PlanRequest, plan

TABLE_Z = 0.1


def _one_sided_box(rng: np.random.Generator) -> tuple[np.ndarray, np.ndarray]:
    """What a camera at -X, above, sees of a 6 x 5 x 10 cm box on the table: its top and its -X face only
    (world, m; outward normals), with 1 mm noise along the normals."""
    n = 600
    top = np.c_[rng.uniform(-0.03, 0.03, n), rng.uniform(-0.025, 0.025, n), np.full(n, TABLE_Z + 0.1)]
    front = np.c_[np.full(n, -0.03), rng.uniform(-0.025, 0.025, n), rng.uniform(TABLE_Z, TABLE_Z + 0.1, n)]
    normals = np.repeat([[0.0, 0.0, 1.0], [-1.0, 0.0, 0.0]], n, axis=0)
    points = np.vstack([top, front]) + normals * rng.normal(0.0, 0.001, (2 * n, 1))
    return points, normals


def _request(points, normals, observation=True, seed=7) -> PlanRequest:
    cfg = OmegaConf.to_object(compose_config(["planner=antipodal_view", "mode=bin"]))
    return PlanRequest(
        np.zeros((0, 3)),  # no model cloud: the planner must not need it
        np.zeros((0, 3)),
        np.zeros(0, dtype=bool),
        np.full((4, 4), np.nan),  # nor the pose
        TABLE_Z,
        "bin",
        cfg.gripper,
        cfg.planner,
        cfg.cost,
        seed,
        observation=full_view(points, normals) if observation else None,
    )


def test_plans_from_a_cloud_without_the_far_side():
    points, normals = _one_sided_box(np.random.default_rng(0))
    assert not ((points[:, 0] > 0.025) & (points[:, 2] < TABLE_Z + 0.095)).any()  # nothing of the +X face
    req = _request(points, normals)
    g = plan(req).grasp
    R = g.pose[:3, :3]
    np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-9)
    assert g.planner == "antipodal_view" and g.n_feasible > 0
    assert g.width_m == pytest.approx(req.gripper.max_width_m)  # full aperture: the far side is unknown
    assert g.extras["n_observed"] == len(points)
    # the pads close across the box: along the visible face's normal (x) or across the top's span (y)
    closing = np.abs(R[:, 1])
    assert closing.max() > 0.9 and np.argmax(closing) in (0, 1)
    assert g.position[2] > TABLE_Z  # above the support
    again = plan(_request(points, normals)).grasp
    np.testing.assert_array_equal(g.pose, again.pose)


def test_the_planner_reads_the_camera():
    assert get_plugin("antipodal_view").plugin.needs_observation
    assert not get_plugin("antipodal").plugin.needs_observation


def test_without_an_observation_it_refuses_in_one_line():
    points, normals = _one_sided_box(np.random.default_rng(0))
    with pytest.raises(ValueError, match="^planner antipodal_view plans on the camera's cloud"):
        plan(_request(points, normals, observation=False))


def test_too_few_observed_points_is_no_feasible_grasp():
    points, normals = _one_sided_box(np.random.default_rng(0))
    req = _request(points[:5], normals[:5])
    req = dataclasses.replace(req, planner=dataclasses.replace(req.planner, min_points=20))
    with pytest.raises(NoFeasibleGrasp, match="^antipodal_view: the camera saw 5 points"):
        plan(req)


def test_the_plan_tool_renders_the_camera_for_a_folder_object(tmp_path, capsys):
    """``python -m graspexp plan`` with a planner that reads the camera, on a folder dataset's object (a mesh
    in mm): the camera renders the object upright on the support and the planner plans on its cloud; with
    ``perception.source=depth`` the paper's planner gets the registered pose."""
    import json

    import trimesh

    from graspexp.tools.plan import main

    trimesh.creation.box(extents=(50.0, 30.0, 80.0)).export(tmp_path / "bracket.stl")
    folder = ["dataset=folder", f"dataset.root={tmp_path}", "dataset.units=mm", "objects=[bracket]"]
    assert main([*folder, "planner=antipodal_view"]) == 0
    grasp = json.loads(capsys.readouterr().out)
    assert grasp["object"] == "bracket" and grasp["n_feasible"] > 0
    assert main([*folder, "perception.source=depth"]) == 0
    registered = json.loads(capsys.readouterr().out)
    assert main(folder) == 0
    exact = json.loads(capsys.readouterr().out)
    assert registered["pose"] != exact["pose"]  # planned on the registered pose, not the exact one
    assert np.allclose(np.array(registered["pose"])[:3, 3], np.array(exact["pose"])[:3, 3], atol=0.02)
