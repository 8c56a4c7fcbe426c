"""The simulated depth camera: exact ray-cast depth of known geometry, the noise model's mean and spread on
a known box at a known distance, missing pixels, per-pixel ids, and seeded determinism."""

import dataclasses

import numpy as np
import pytest
import trimesh

from graspexp.config.perception import DEPTH_NOISE_MODELS, CameraConfig, DepthNoiseConfig, PerceptionConfig
from graspexp.perception import depth_noise
from graspexp.perception.camera import BoxBody, MeshBody, back_project, look_at, render, view_poses
from graspexp.perception.depth_noise import axial_sigma_m, noisy_depth
from graspexp.perception.observe import observe

CAM = CameraConfig(width_px=96, height_px=72, fx_px=80.0, fy_px=80.0, cx_px=47.5, cy_px=35.5)
"""A small camera (fast tests)."""
DISTANCE_M = 0.6
EYE = np.array([0.0, 0.0, 0.5])


def _facing_wall() -> tuple[np.ndarray, BoxBody]:
    """A camera looking along world +X at a box whose face x = 0.6 m fills the image."""
    return look_at(EYE, EYE + [1.0, 0.0, 0.0]), BoxBody(
        np.array([DISTANCE_M, -5, -5]), np.array([1.0, 5, 5]), 3
    )


def test_exact_depth_of_a_wall_is_its_distance_along_the_optical_axis():
    pose, wall = _facing_wall()
    view = render(CAM, pose, [], [wall])
    np.testing.assert_allclose(view.depth, DISTANCE_M, atol=1e-12)  # depth, not ray length
    assert (view.ids == 3).all()
    centre = view.cos_incidence[CAM.height_px // 2, CAM.width_px // 2]
    assert centre == pytest.approx(1.0, abs=1e-3) and view.cos_incidence.min() < 0.9


def test_a_mesh_box_renders_like_the_analytic_box():
    pose, wall = _facing_wall()
    mesh = trimesh.creation.box(extents=[0.4, 10.0, 10.0])  # its face at x = -0.2 in its own frame
    placed = np.eye(4)
    placed[:3, 3] = [DISTANCE_M + 0.2, 0.0, 0.0]
    view = render(CAM, pose, [MeshBody(mesh, placed, 7)])
    np.testing.assert_allclose(view.depth, DISTANCE_M, atol=1e-9)
    assert (view.ids == 7).all()


def test_noise_on_a_box_at_a_known_distance_matches_the_models_mean_and_spread():
    """Nguyen et al. 2012: depth unbiased, std sigma_z(z, theta); the lateral shift moves pixels across a
    flat face without changing its depth. Pixels near the image centre (theta < 10 deg) only."""
    pose, wall = _facing_wall()
    view = render(CAM, pose, [], [wall])
    cfg = DepthNoiseConfig()
    samples = []
    for seed in range(12):
        depth, ids = noisy_depth(
            cfg, view.depth, view.ids, view.cos_incidence, rng=np.random.default_rng(seed)
        )
        centre = view.cos_incidence > np.cos(np.radians(10))
        assert (depth[centre] > 0).all() and (ids[centre] == 3).all()
        samples.append(depth[centre].astype(float))
    z = np.concatenate(samples)
    theta = np.arccos(view.cos_incidence[view.cos_incidence > np.cos(np.radians(10))])
    expected = np.sqrt(np.mean(axial_sigma_m(cfg, np.full_like(theta, DISTANCE_M), theta) ** 2))
    assert expected == pytest.approx(0.0012 + 0.0019 * (DISTANCE_M - 0.4) ** 2, rel=0.01)
    assert abs(z.mean() - DISTANCE_M) < 4 * expected / np.sqrt(len(z))
    assert z.std() == pytest.approx(expected, rel=0.05)


def test_grazing_pixels_and_depth_edges_lose_their_return():
    """A floor seen at a grazing angle returns nothing; the silhouette of a box in front of a far wall
    loses a band of pixels; the wall's and the box's inner pixels keep theirs."""
    cfg = DepthNoiseConfig(lateral_px=0.0, lateral_angle_px=0.0)
    pose = look_at(np.array([0.0, 0.0, 0.05]), np.array([1.0, 0.0, 0.05]))  # 5 cm above a floor z = 0
    floor = BoxBody(np.array([-10.0, -10, -1]), np.array([10.0, 10, 0]))
    wall = BoxBody(np.array([1.5, -5, -5]), np.array([2.0, 5, 5]), 0)
    box = BoxBody(np.array([0.6, -0.05, 0.0]), np.array([0.7, 0.05, 0.1]), 2)
    view = render(CAM, pose, [], [floor, wall, box])
    depth, ids = noisy_depth(cfg, view.depth, view.ids, view.cos_incidence, rng=np.random.default_rng(0))
    graze = (view.depth > 0) & (view.cos_incidence < np.cos(np.radians(cfg.max_incidence_deg)))
    assert graze.any() and (depth[graze] == 0).all()
    box_px = view.ids == 2
    rows, cols = np.nonzero(box_px)
    assert (depth[rows.min() + 2 : rows.max() - 1, cols.min() + 2 : cols.max() - 1] > 0).all()
    edge = box_px & ~np.roll(box_px, 1, axis=1)  # the box's left silhouette column
    assert (depth[edge] == 0).all()


def test_the_noise_model_is_chosen_by_name(monkeypatch):
    """``depth_noise.model`` names a registered function (every name the config accepts has one); the
    default ``nguyen`` is :func:`graspexp.perception.depth_noise.nguyen_noise` itself."""
    assert set(depth_noise.NOISE_MODELS) == set(DEPTH_NOISE_MODELS)
    pose, wall = _facing_wall()
    view = render(CAM, pose, [], [wall])
    args = (view.depth, view.ids, view.cos_incidence)
    direct = depth_noise.nguyen_noise(DepthNoiseConfig(), *args, rng=np.random.default_rng(1))
    for a, b in zip(
        noisy_depth(DepthNoiseConfig(), *args, rng=np.random.default_rng(1)), direct, strict=True
    ):
        np.testing.assert_array_equal(a, b)
    monkeypatch.setitem(depth_noise.NOISE_MODELS, "flat", lambda cfg, d, i, c, *, rng: (d + 1, i))
    depth, _ = noisy_depth(DepthNoiseConfig(model="flat"), *args, rng=np.random.default_rng(1))
    np.testing.assert_allclose(depth, DISTANCE_M + 1)


def test_observation_is_seeded_and_back_projects_onto_the_surface():
    cfg = PerceptionConfig(camera=dataclasses.replace(CAM, azimuths_deg=[0.0, 120.0]))
    mesh = trimesh.creation.box(extents=[0.05, 0.08, 0.1])
    pose = np.eye(4)
    pose[:3, 3] = [0.0, 0.0, 0.1 + 0.05]
    support = BoxBody(np.array([-0.15, -0.15, 0.0]), np.array([0.15, 0.15, 0.1]))
    a = observe(cfg, [MeshBody(mesh, pose, 1)], [support], 0.1, 1, rng=np.random.default_rng(4))
    b = observe(cfg, [MeshBody(mesh, pose, 1)], [support], 0.1, 1, rng=np.random.default_rng(4))
    np.testing.assert_array_equal(a.points, b.points)
    assert len(a.views) == 2 and a.views[0].depth.dtype == np.float32 and a.views[0].ids.dtype == np.int32
    pts, nrm = a.target()
    assert len(pts) > 50 and np.allclose(np.linalg.norm(nrm, axis=1), 1.0)
    local = pts - pose[:3, 3]
    # on the box's surface within the noise (a few mm at 0.6 m)
    outside = np.abs(local) - np.array([0.025, 0.04, 0.05])
    assert np.median(np.abs(outside.max(axis=1))) < 0.004
    for v in a.views:  # normals face the camera that saw them; a view's pixels back-project in front of it
        world, _ = back_project(v.depth, cfg.camera, v.world_from_camera)
        in_cam = (world - v.world_from_camera[:3, 3]) @ v.world_from_camera[:3, :3]
        assert (in_cam[:, 2] > 0).all()
    assert len(view_poses(cfg.camera, 0.1)) == 2


def test_the_target_normals_alone_equal_the_whole_clouds(data_root):
    """The registration and the view-based planners read only the target's normals (estimated on the
    target's neighbourhood, :class:`graspexp.perception.observe.ViewNormals`): on the mug (YCB google_16k)
    seen from two sides they are the whole cloud's normals at those points, bit for bit."""
    from omegaconf import OmegaConf

    from graspexp.config.compose import compose_config
    from graspexp.datasets import load_object

    dataset = OmegaConf.to_object(
        compose_config(["dataset=ycb", f"dataset.root={data_root / 'ycb'}"])
    ).dataset
    mesh = load_object(dataset, "025_mug", 256, 0).mesh
    cfg = PerceptionConfig(camera=CameraConfig(azimuths_deg=[0.0, 150.0]))  # the d435 preset
    support = BoxBody(np.array([-0.15, -0.15, 0.0]), np.array([0.15, 0.15, 0.1]))
    for seed, turn in enumerate((0.0, 1.2, 2.5)):
        pose = np.eye(4)
        pose[:3, :3] = trimesh.transformations.rotation_matrix(turn, [0, 0, 1])[:3, :3]
        pose[:3, 3] = [0.01, -0.02, 0.1 - mesh.bounds[0, 2]]
        seen = [
            observe(cfg, [MeshBody(mesh, pose, 1)], [support], 0.1, 1, rng=np.random.default_rng(seed))
            for _ in range(2)
        ]
        pts, nrm = seen[0].target()  # first: only the target's normals are estimated
        assert "normals" not in seen[0].__dict__ and len(pts) > 200
        target = seen[1].point_ids == 1
        assert (~target).sum() > 1000  # the support is in the cloud too
        np.testing.assert_array_equal(pts, seen[1].points[target])
        np.testing.assert_array_equal(nrm, seen[1].normals[target])
