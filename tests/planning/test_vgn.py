"""planner=vgn (the optional extra ``learned``): the published checkpoint loads strictly and gives the same
outputs every time, the TSDF fusion matches VGN's own route through Open3D, VGN's grasp frame converts to
graspexp's, VGN's detection keeps the right voxels, and a plan on a ray-cast scene straddles the object.

The main suite skips this module without torch and Open3D (``nox -s learned`` installs them); the
checkpoint comes from ``$GRASPEXP_CHECKPOINTS``, else ``peers/vgn`` beside the shared data root."""

from __future__ import annotations

import dataclasses
import os
import types
from pathlib import Path

import numpy as np
import pytest
import trimesh

torch = pytest.importorskip(
    "torch", reason="planner=vgn needs the optional extra: pip install -e '.[learned]'"
)
o3d = pytest.importorskip(
    "open3d", reason="planner=vgn needs the optional extra: pip install -e '.[learned]'"
)

from conftest import compose_cfg, shared_data_root  # noqa: E402
from omegaconf import OmegaConf  # noqa: E402

from graspexp.config import ConfigError  # noqa: E402
from graspexp.config.validate import validate  # noqa: E402
from graspexp.core import checkpoints  # noqa: E402
from graspexp.grippers import GripperGeometry  # noqa: E402
from graspexp.planning import PlanRequest, plan  # noqa: E402
from graspexp.planning.learned import tsdf, vgn, vgn_network  # noqa: E402

pytestmark = pytest.mark.learned
SHARED_VGN = shared_data_root().parent / "peers" / "vgn"
"""``../shared/peers/vgn``: beside the shared data root (``$GRASPEXP_DATA/..``)."""
TABLE_Z = 0.1


@pytest.fixture(autouse=True)
def _checkpoint_dir(monkeypatch: pytest.MonkeyPatch) -> Path:
    """The folder holding ``vgn_conv.pth`` for these tests (never a copy inside the repository)."""
    folder = Path(os.environ.get(checkpoints.CHECKPOINTS_ENV, SHARED_VGN))
    if not (folder / checkpoints.VGN.filename).is_file():
        pytest.skip(f"the VGN checkpoint is not in {folder}: python -m graspexp download_checkpoint vgn")
    monkeypatch.setenv(checkpoints.CHECKPOINTS_ENV, str(folder))
    return folder


def _look_at(eye: np.ndarray, target: np.ndarray) -> np.ndarray:
    """world_from_camera (OpenCV axes) of a camera at ``eye`` looking at ``target``, image x horizontal."""
    z = (target - eye) / np.linalg.norm(target - eye)
    x = np.cross(z, [0.0, 0.0, 1.0])
    x /= np.linalg.norm(x)
    T = np.eye(4)
    T[:3, :3] = np.column_stack([x, np.cross(z, x), z])
    T[:3, 3] = eye
    return T


def _cast(meshes, world_from_camera: np.ndarray, K: np.ndarray, w: int, h: int):
    """Depth (h, w) float32 along the optical axis, and the world points and mesh index of every hit."""
    scene = o3d.t.geometry.RaycastingScene()
    for m in meshes:
        scene.add_triangles(o3d.t.geometry.TriangleMesh.from_legacy(m))
    rays = scene.create_rays_pinhole(
        o3d.core.Tensor(K), o3d.core.Tensor(np.linalg.inv(world_from_camera)), w, h
    ).numpy()
    hit = scene.cast_rays(o3d.core.Tensor(rays))
    t, which = hit["t_hit"].numpy(), hit["geometry_ids"].numpy()
    depth = t * (rays[..., 3:] @ world_from_camera[:3, 2])
    seen = np.isfinite(depth)
    points = rays[..., :3][seen] + t[seen, None] * rays[..., 3:][seen]
    return np.where(seen, depth, 0.0).astype(np.float32), points, which[seen]


def _box(size, centre) -> o3d.geometry.TriangleMesh:
    m = o3d.geometry.TriangleMesh.create_box(*size)
    return m.translate(np.asarray(centre) - np.asarray(size) / 2)


def _scene(size=(0.05, 0.08, 0.12), xy=(0.4, 0.1), n_views: int = 6):
    """A box standing on a table at TABLE_Z seen by ``n_views`` cameras 0.6 m away, 30 degrees off vertical
    (VGN's viewpoints), 640 x 480 px, fx = 540 px: an observation as the camera gives one (target id 1)."""
    centre = np.array([*xy, TABLE_Z])
    meshes = [_box((1.0, 1.0, 0.02), centre - [0, 0, 0.01]), _box(size, centre + [0, 0, size[2] / 2])]
    K = np.array([[540.0, 0.0, 320.0], [0.0, 540.0, 240.0], [0.0, 0.0, 1.0]])
    views, points, ids = [], [], []
    for phi in 2 * np.pi * np.arange(n_views) / n_views:
        eye = centre + 0.6 * np.array([0.5 * np.cos(phi), 0.5 * np.sin(phi), np.sqrt(3) / 2])
        pose = _look_at(eye, centre)
        depth, pts, which = _cast(meshes, pose, K, 640, 480)
        views.append(types.SimpleNamespace(depth=depth, K=K, world_from_camera=pose, name=f"v{len(views)}"))
        points.append(pts)
        ids.append(which.astype(np.int32))  # mesh 0 (table) -> id 0, mesh 1 (box) -> id 1
    cloud = np.concatenate(points)
    obs = types.SimpleNamespace(views=tuple(views), points=cloud, point_ids=np.concatenate(ids), target_id=1)
    return obs, centre + [0, 0, size[2] / 2], np.asarray(size)


def _request(obs, seed: int = 3, *overrides: str) -> PlanRequest:
    cfg = OmegaConf.to_object(compose_cfg("planner=vgn", "gripper=panda", "mode=bin", *overrides))
    empty = np.zeros((0, 3))
    req = PlanRequest(
        empty, empty, np.zeros(0, bool), np.eye(4), TABLE_Z, "bin", cfg.gripper, cfg.planner, cfg.cost, seed
    )
    if "observation" in {f.name for f in dataclasses.fields(PlanRequest)}:
        return dataclasses.replace(req, observation=obs)
    object.__setattr__(req, "observation", obs)  # before the camera's PlanRequest.observation lands
    return req


def test_the_checkpoint_loads_strictly_and_its_outputs_are_deterministic():
    net = vgn_network.load_vgn()
    state = torch.load(checkpoints.checkpoint_path(checkpoints.VGN), map_location="cpu", weights_only=True)
    assert len(state) == 18 and set(state) == set(net.state_dict())
    grid = np.random.default_rng(0).uniform(0, 1, (40, 40, 40)).astype(np.float32)
    first = vgn.infer(net, grid, threads=1)
    again = vgn.infer(vgn_network.load_vgn(), grid, threads=1)
    two_threads = vgn.infer(net, grid, threads=2)
    for a, b, c in zip(first, again, two_threads, strict=True):
        assert np.array_equal(a, b) and np.array_equal(a, c)
    quality, rot, width = first
    assert quality.shape == width.shape == (40, 40, 40) and rot.shape == (4, 40, 40, 40)
    assert 0 <= quality.min() and quality.max() <= 1
    np.testing.assert_allclose(np.linalg.norm(rot, axis=0), 1.0, atol=1e-5)


def test_a_changed_checkpoint_is_refused_by_its_hash(tmp_path, monkeypatch):
    data = bytearray(checkpoints.checkpoint_path(checkpoints.VGN).read_bytes())
    data[-100] ^= 0xFF
    (tmp_path / checkpoints.VGN.filename).write_bytes(bytes(data))
    monkeypatch.setenv(checkpoints.CHECKPOINTS_ENV, str(tmp_path))
    with pytest.raises(
        checkpoints.CheckpointError, match=r"^checkpoint .* has SHA-256 [0-9a-f]{64}, not the"
    ):
        vgn_network.load_vgn()


def test_a_missing_checkpoint_or_extra_stops_the_config_with_one_line(tmp_path, monkeypatch):
    monkeypatch.setenv(checkpoints.CHECKPOINTS_ENV, str(tmp_path))
    with pytest.raises(ConfigError) as err:
        validate(compose_cfg("planner=vgn"))
    assert str(err.value).startswith("planner=vgn cannot run here: checkpoint ")
    assert "python -m graspexp download_checkpoint vgn" in str(err.value) and "\n" not in str(err.value)
    from graspexp.config.planner import vgn as schema

    monkeypatch.setattr(schema, "find_spec", lambda name: None if name == "torch" else object())
    with pytest.raises(
        ConfigError, match=r"needs torch, the optional extra 'learned': pip install -e '\.\[learned\]'$"
    ):
        validate(compose_cfg("planner=vgn"))


def test_the_fused_grid_is_vgns_voxel_cloud_of_open3d():
    """The grid read from Open3D's volume equals VGN's route: the voxel point cloud (values in its
    colours) placed at floor(point / voxel)."""
    obs, _, _ = _scene(n_views=2)
    corner = vgn.world_from_volume(obs.points[obs.point_ids == 1], TABLE_Z)
    views = [tsdf.DepthView(v.depth, v.K, v.world_from_camera) for v in obs.views]
    grid = tsdf.fuse(views, corner, 0.3, 40, 2.0)
    volume = o3d.pipelines.integration.UniformTSDFVolume(
        length=0.3,
        resolution=40,
        sdf_trunc=0.03,
        color_type=o3d.pipelines.integration.TSDFVolumeColorType.NoColor,
    )
    for v in views:
        rgbd = o3d.geometry.RGBDImage.create_from_color_and_depth(
            o3d.geometry.Image(np.zeros_like(v.depth)), o3d.geometry.Image(v.depth), 1.0, 2.0, False
        )
        intrinsic = o3d.camera.PinholeCameraIntrinsic(640, 480, 540.0, 540.0, 320.0, 240.0)
        volume.integrate(rgbd, intrinsic, np.linalg.inv(v.world_from_camera) @ corner)
    cloud = volume.extract_voxel_point_cloud()
    expected = np.zeros((40, 40, 40), np.float32)
    expected[tuple(np.floor(np.asarray(cloud.points) / 0.0075).astype(int).T)] = np.asarray(cloud.colors)[
        :, 0
    ]
    assert (grid > 0).sum() > 1000
    np.testing.assert_array_equal(grid, expected)
    # beside the box, the table top (0.05 m above the floor: 6.67 voxels) crosses 0.5 between the voxel
    # centres of layers 6 (48.75 mm) and 7 (56.25 mm), rising with height
    column = grid[5, 20, :]
    assert 0 < column[5] < column[6] < 0.5 < column[7] < column[8]


def test_vgns_grasp_frame_converts_to_graspexps_with_the_fingertips_in_place():
    gripper = OmegaConf.to_object(compose_cfg("gripper=panda")).gripper
    T = vgn.graspexp_from_vgn(gripper)
    np.testing.assert_array_equal(T[:3, :3], np.eye(3))  # same axes: +Z approach, +Y closing, X = Y x Z
    tip_in_graspexp = np.array([0.0, 0.0, GripperGeometry.of(gripper).tip_z_m, 1.0])
    np.testing.assert_allclose((T @ tip_in_graspexp)[:3], [0.0, 0.0, vgn.VGN_FINGER_DEPTH_M])
    assert T[2, 3] == pytest.approx(0.05 - gripper.tcp_from_tip_m)


def test_detection_keeps_thresholded_local_maxima_near_the_surface_with_widths_in_range():
    grid = np.zeros((40, 40, 40), np.float32)
    grid[:, :, 10:14] = 0.9  # free space seen within the truncation band above a floor at k = 10
    grid[:, :, 8:10] = 0.3  # behind the surface
    quality = np.zeros((40, 40, 40), np.float32)
    rot = np.zeros((4, 40, 40, 40), np.float32)
    rot[3] = 1.0  # identity (x, y, z, w)
    width = np.full((40, 40, 40), 5.0, np.float32)  # 37.5 mm
    for peak in [(10, 10, 11), (11, 10, 11), (30, 30, 11), (20, 20, 30), (20, 30, 11)]:
        quality[peak] = 1.0
    width[20, 30, 11] = 0.5  # 3.75 mm: below min_width_m
    cfg = OmegaConf.to_object(compose_cfg("planner=vgn", "planner.quality_sigma_voxels=0")).planner
    found = vgn.detect(grid, quality, rot, width, cfg)
    got = sorted(tuple(int(v) for v in np.rint(p[:3, 3] / vgn.VOXEL_M)) for p in found.poses)
    # (11, 10, 11) ties with (10, 10, 11) inside one 4-voxel cube: both are maxima of equal value;
    # (20, 20, 30) is 16 voxels above the band; (20, 30, 11) has too small a width
    assert got == [(10, 10, 11), (11, 10, 11), (30, 30, 11)]
    np.testing.assert_allclose(found.widths_m, 5 * vgn.VOXEL_M)
    smoothed = vgn.detect(grid, quality, rot, width, OmegaConf.to_object(compose_cfg("planner=vgn")).planner)
    assert len(smoothed.poses) == 0  # a lone voxel of 1.0 smooths to about 0.06 < 0.9


def test_a_plan_on_a_rendered_box_straddles_it_and_repeats():
    obs, centre, size = _scene()
    req = _request(obs)
    g = plan(req).grasp
    assert g.planner == "vgn" and g.width_m == req.gripper.max_width_m
    R = g.pose[:3, :3]
    np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-6)
    # the fingers straddle the box: points of its surface lie between the pads, none where a pad is
    geo = GripperGeometry.of(req.gripper)
    box = trimesh.creation.box(size, trimesh.transformations.translation_matrix(centre))
    local = (trimesh.sample.sample_surface_even(box, 20000, seed=1)[0] - g.position) @ R
    slab = (
        (np.abs(local[:, 0]) <= geo.finger_width_m / 2)
        & (local[:, 2] >= geo.root_z_m)
        & (local[:, 2] <= geo.tip_z_m)
    )
    between = slab & (np.abs(local[:, 1]) < g.width_m / 2)
    in_pad = (
        slab
        & (np.abs(local[:, 1]) >= g.width_m / 2)
        & (np.abs(local[:, 1]) <= g.width_m / 2 + geo.finger_thickness_m)
    )
    assert between.sum() > 50 and in_pad.sum() == 0
    approach = R[:, 2]
    assert approach[2] < -0.5  # from above, as VGN's training grasps (normals pointing up)
    assert g.extras["quality"] >= 0.9 and g.extras["infer_cpu_s"] > 0
    again = plan(_request(obs)).grasp
    np.testing.assert_array_equal(g.pose, again.pose)
    best = plan(_request(obs, 3, "planner.selection=best")).grasp
    assert best.extras["quality"] >= g.extras["quality"]


def test_no_observation_or_no_target_point_is_a_recorded_reason():
    from graspexp.planning import NoFeasibleGrasp

    obs, _, _ = _scene(n_views=1)
    req = _request(obs)
    object.__setattr__(req, "observation", None)
    with pytest.raises(NoFeasibleGrasp, match="no observation"):
        plan(req)
    blind = types.SimpleNamespace(**{**vars(obs), "target_id": 7})
    with pytest.raises(NoFeasibleGrasp, match=r"saw no point of the target \(id 7\)"):
        plan(_request(blind))
