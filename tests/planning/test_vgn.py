"""planner=vgn (the optional extra ``learned``): the published checkpoint loads strictly and gives the same
outputs every time, the TSDF fusion matches VGN's own route through Open3D, VGN's grasp frame converts to
graspexp's, VGN's detection keeps the right voxels, and a plan on a ray-cast scene straddles the object.

The main suite skips this module without torch and Open3D (``nox -s learned`` installs them); the
checkpoint comes from ``$GRASPEXP_CHECKPOINTS``, else ``peers/vgn`` beside the shared data root."""

from __future__ import annotations

import dataclasses
import os
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

from helpers.config import compose_cfg, shared_data_root  # noqa: E402
from omegaconf import OmegaConf  # noqa: E402

from graspexp.config import ConfigError  # noqa: E402
from graspexp.config.validate import validate  # noqa: E402
from graspexp.core import checkpoints  # noqa: E402
from graspexp.grippers import GripperGeometry  # noqa: E402
from graspexp.perception.camera import BoxBody, MeshBody  # noqa: E402
from graspexp.perception.observe import observe  # noqa: E402
from graspexp.perception.tsdf import fuse  # noqa: E402
from graspexp.planning import PlanRequest, plan  # noqa: E402
from graspexp.planning.learned import vgn, vgn_network  # noqa: E402

pytestmark = pytest.mark.learned
SHARED_VGN = shared_data_root().parent / "peers" / "vgn"
"""``../shared/peers/vgn``: beside the shared data root (``$GRASPEXP_DATA/..``)."""
TABLE_Z = 0.1
"""Support top, m (``mode.support_height_m``)."""


@pytest.fixture(autouse=True)
def _checkpoint_dir(monkeypatch: pytest.MonkeyPatch) -> Path:
    """The folder holding ``vgn_conv.pth`` for these tests (never a copy inside the repository):
    ``$GRASPEXP_CHECKPOINTS`` (one folder or several, ``os.pathsep``), else :data:`SHARED_VGN`."""
    monkeypatch.setenv(
        checkpoints.CHECKPOINTS_ENV, os.environ.get(checkpoints.CHECKPOINTS_ENV, str(SHARED_VGN))
    )
    path = checkpoints.checkpoint_path(checkpoints.VGN)
    if not path.is_file():
        pytest.skip(f"the VGN checkpoint is not in {path.parent}: python -m graspexp download_checkpoint vgn")
    return path.parent


def _scene(size=(0.05, 0.08, 0.12), azimuths=(0.0, 120.0, 240.0), mesh=None, seed: int = 0, noise=True):
    """A box (or ``mesh``, resting on the support) at the support's centre in bin mode, seen by the
    simulated depth camera (the D435 preset, its noise model on unless ``noise`` is False) from
    ``azimuths``: the camera's observation (target id 1), the object's world pose and its mesh in its own
    frame."""
    cfg = OmegaConf.to_object(
        compose_cfg(
            "mode=bin",
            f"perception.camera.azimuths_deg={list(azimuths)}",
            f"perception.depth_noise.enabled={noise}",
        )
    )
    mesh = trimesh.creation.box(size) if mesh is None else mesh
    pose = np.eye(4)
    pose[:3, 3] = [0.0, 0.0, TABLE_Z - mesh.bounds[0, 2]]
    half = tuple(cfg.mode.support_half_size_m)
    support = BoxBody(np.array([-half[0], -half[1], 0.0]), np.array([half[0], half[1], TABLE_Z]))
    rng = np.random.default_rng(seed)
    obs = observe(cfg.perception, [MeshBody(mesh, pose, 1)], [support], TABLE_Z, 1, rng=rng)
    return obs, pose, mesh


def _request(obs, seed: int = 3, *overrides: str) -> PlanRequest:
    cfg = OmegaConf.to_object(compose_cfg("planner=vgn", "gripper=panda", "mode=bin", *overrides))
    empty = np.zeros((0, 3))
    req = PlanRequest(
        empty, empty, np.zeros(0, bool), np.eye(4), TABLE_Z, "bin", cfg.gripper, cfg.planner, cfg.cost, seed
    )
    return dataclasses.replace(req, observation=obs)


def test_the_checkpoint_loads_strictly_and_its_outputs_are_deterministic():
    net = vgn_network.load_vgn()
    state = torch.load(checkpoints.checkpoint_path(checkpoints.VGN), map_location="cpu", weights_only=True)
    assert len(state) == 18 and set(state) == set(net.state_dict())
    grid = np.random.default_rng(0).uniform(0, 1, (40, 40, 40)).astype(np.float32)
    first = vgn.infer(net, grid, threads=1)
    again = vgn.infer(vgn_network.load_vgn(), grid, threads=1)
    two_threads = vgn.infer(net, grid, threads=2)
    two_again = vgn.infer(net, grid, threads=2)
    # the same thread count gives the same outputs bit for bit; another count may move the last digits (torch
    # splits the convolutions' sums by thread: measured on an Intel Xeon with AVX-512), so ``planner.threads``
    # is part of what decides a result
    for a, b, c, d in zip(first, again, two_threads, two_again, strict=True):
        assert np.array_equal(a, b) and np.array_equal(c, d)
        np.testing.assert_allclose(a, c, rtol=1e-4, atol=1e-5)
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
    obs, _, _ = _scene(azimuths=(0.0, 180.0), noise=False)
    corner = vgn.world_from_volume(obs.points[obs.point_ids == 1], TABLE_Z)
    grid = fuse(obs.views, corner, 0.3, 40, 2.0)
    volume = o3d.pipelines.integration.UniformTSDFVolume(
        length=0.3,
        resolution=40,
        sdf_trunc=0.03,
        color_type=o3d.pipelines.integration.TSDFVolumeColorType.NoColor,
    )
    for v in obs.views:
        rgbd = o3d.geometry.RGBDImage.create_from_color_and_depth(
            o3d.geometry.Image(np.zeros_like(v.depth)), o3d.geometry.Image(v.depth), 1.0, 2.0, False
        )
        (h, w), K = v.depth.shape, v.K
        intrinsic = o3d.camera.PinholeCameraIntrinsic(w, h, K[0, 0], K[1, 1], K[0, 2], K[1, 2])
        volume.integrate(rgbd, intrinsic, np.linalg.inv(v.world_from_camera) @ corner)
    cloud = volume.extract_voxel_point_cloud()
    expected = np.zeros((40, 40, 40), np.float32)
    expected[tuple(np.floor(np.asarray(cloud.points) / 0.0075).astype(int).T)] = np.asarray(cloud.colors)[
        :, 0
    ]
    assert (grid > 0).sum() > 1000
    np.testing.assert_array_equal(grid, expected)
    # beside the box, the exact table top (0.05 m above the floor: 6.67 voxels) crosses 0.5 between the
    # voxel centres of layers 6 (48.75 mm) and 7 (56.25 mm), rising with height
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


def _straddles(g, req: PlanRequest, mesh: trimesh.Trimesh, pose: np.ndarray) -> bool:
    """Whether the fingers of grasp ``g`` straddle ``mesh`` at ``pose``: points of its surface lie between
    the pads, none where a pad is (finger boxes of ``req.gripper``, opened to ``g.width_m``)."""
    geo = GripperGeometry.of(req.gripper)
    surface = trimesh.sample.sample_surface_even(mesh, 20000, seed=1)[0] @ pose[:3, :3].T + pose[:3, 3]
    local = (surface - g.position) @ g.pose[:3, :3]
    slab = (
        (np.abs(local[:, 0]) <= geo.finger_width_m / 2)
        & (local[:, 2] >= geo.root_z_m)
        & (local[:, 2] <= geo.tip_z_m)
    )
    gap = np.abs(local[:, 1]) - g.width_m / 2
    return bool(
        (slab & (gap < 0)).sum() > 50 and not (slab & (gap >= 0) & (gap <= geo.finger_thickness_m)).any()
    )


def test_a_plan_on_a_rendered_box_straddles_it_and_repeats():
    obs, pose, mesh = _scene()
    req = _request(obs)
    g = plan(req).grasp
    assert g.planner == "vgn" and g.width_m == req.gripper.max_width_m
    R = g.pose[:3, :3]
    np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-6)
    assert _straddles(g, req, mesh, pose)
    approach = R[:, 2]
    assert approach[2] < -0.5  # from above, as VGN's training grasps (normals pointing up)
    assert g.extras["quality"] >= 0.9 and g.extras["infer_cpu_s"] > 0
    again = plan(_request(obs)).grasp
    np.testing.assert_array_equal(g.pose, again.pose)
    best = plan(_request(obs, 3, "planner.selection=best")).grasp
    assert best.extras["quality"] >= g.extras["quality"]


def test_no_observation_or_no_target_point_is_a_recorded_reason():
    from graspexp.planning import NoFeasibleGrasp

    obs, _, _ = _scene(azimuths=(0.0,))
    req = dataclasses.replace(_request(obs), observation=None)
    with pytest.raises(NoFeasibleGrasp, match="no observation"):
        plan(req)
    blind = dataclasses.replace(obs, target_id=7)
    with pytest.raises(NoFeasibleGrasp, match=r"saw no point of the target \(id 7\)"):
        plan(_request(blind))


def test_a_plan_on_a_rendered_ycb_object_straddles_it(data_root):
    """The soup can (Table 1) upright on the support, one D435 view as in a trial."""
    from graspexp.datasets import load_object

    cfg = compose_cfg("dataset=ycb", f"dataset.root={data_root}")
    model = load_object(cfg.dataset, "005_tomato_soup_can", 256, 0)
    obs, pose, mesh = _scene(azimuths=(0.0,), mesh=model.mesh)
    req = _request(obs)
    g = plan(req).grasp
    assert _straddles(g, req, mesh, pose), g


def _three_in_a_row(x0: float, y: float):
    """A clutter scene (mode=pile; a mug, a banana and a box 1 cm apart in a row along x from ``x0``, centred
    on ``y``, m) seen by the camera (:func:`graspexp.perception.scene_view.perceive_scene`): the plain config,
    the support height, slot -> (model, pose) and the scene's view."""
    from graspexp.perception.scene_view import perceive_scene
    from graspexp.run.job_config import make_ready
    from graspexp.run.objects import load_sim_object
    from graspexp.sim.trial import plain_config

    cfg = compose_cfg("mode=pile", "planner=vgn", "gripper=panda", "dataset=primitives")
    make_ready(cfg)
    plain = plain_config(cfg)
    table_z = float(plain.mode.support_height_m)
    models = [load_sim_object(cfg, name, plain).model for name in ("mug", "banana", "box")]
    objects, x = {}, x0
    for slot, model in enumerate(models):
        lo, hi = model.mesh.bounds
        pose = np.eye(4)
        pose[:3, 3] = [x - lo[0], y - (lo[1] + hi[1]) / 2, table_z - lo[2]]
        objects[slot] = (model, pose)
        x += hi[0] - lo[0] + 0.01
    return plain, table_z, objects, perceive_scene(plain, objects, table_z, seed=5)


def test_vgn_plans_each_object_of_a_three_object_pile_from_one_observation():
    """A clutter scene (mode=pile; a mug, a banana and a box 1 cm apart): the camera sees all three
    (:func:`graspexp.perception.scene_view.perceive_scene`), each request names its target, and VGN's grasp
    for a target holds that target between its pads, the same grasp every time."""
    from graspexp.perception.scene_view import slot_id

    plain, table_z, objects, view = _three_in_a_row(-0.1, 0.0)
    assert set(np.unique(view.observation.point_ids)) == {0, 1, 2, 3}

    def grasp_for(slot):
        obs = dataclasses.replace(view.observation, target_id=slot_id(slot))
        req = dataclasses.replace(_request(obs, 7), table_z=table_z, object_pose=view.poses[slot])
        return plan(req).grasp

    for slot, (model, pose) in objects.items():
        grasp = grasp_for(slot)
        truth = model.points @ pose[:3, :3].T + pose[:3, 3]
        assert vgn.target_points_between_pads(grasp.pose, grasp.width_m, plain.gripper, truth) > 0
        assert np.array_equal(grasp.pose, grasp_for(slot).pose)


def test_vgn_in_a_pile_infers_once_on_the_workspace_and_assigns_each_detection_to_the_object_it_holds(
    monkeypatch,
):
    """A clutter scene (VGN's ``plan_scene``): VGN's one fixed volume centred on the workspace, one fusion
    and forward pass for every target of the scene, each detection given to the object whose points it
    holds; every target's grasp is one of the scene's candidates assigned to it, and the same computed
    afresh; with ``first_found`` the targets after the first grasp are not planned."""
    from graspexp.perception.scene_view import slot_id
    from graspexp.planning.scene import SceneRequest

    plain, table_z, objects, view = _three_in_a_row(-0.08, 0.03)
    half = np.asarray(plain.mode.workspace_half_size_m, dtype=float)
    workspace = np.stack([-half, half])
    calls = []
    infer = vgn.infer
    monkeypatch.setattr(vgn, "infer", lambda *a, **k: calls.append(1) or infer(*a, **k))

    def target(slot):
        obs = dataclasses.replace(view.observation, target_id=slot_id(slot))
        return dataclasses.replace(_request(obs, 7 + slot), table_z=table_z, workspace_xy=workspace)

    scene_req = SceneRequest(tuple(target(s) for s in objects), tuple(slot_id(s) for s in objects))
    res = vgn.plan_vgn_scene(scene_req)
    assert len(calls) == 1 and [tp.index for tp in res.plans] == list(range(len(objects)))
    results = dict(zip(objects, (tp.result for tp in res.plans), strict=True))
    scene = vgn.scene_grasps(target(0), vgn.world_from_scene_volume(workspace, table_z))
    np.testing.assert_array_equal(scene.volume, vgn.world_from_scene_volume(workspace, table_z))
    np.testing.assert_allclose(scene.volume[:3, 3], [-0.15, -0.15, table_z - vgn.TABLE_IN_VOLUME_M])
    assert set(np.unique(scene.owner)) <= {0, *(slot_id(s) for s in objects)}
    found = {slot: r for slot, r in results.items() if r is not None}
    assert found, "no object of the pile got a grasp"
    paid = [r.grasp.extras["infer_cpu_s"] > 0 for r in found.values()]
    assert sum(paid) <= 1  # the scene's fusion and inference are in the extras of one target only
    for slot, result in found.items():
        g = result.grasp
        mine = [
            i for i in np.flatnonzero(scene.owner == slot_id(slot)) if np.array_equal(scene.poses[i], g.pose)
        ]
        assert len(mine) == 1 and g.n_feasible == int((scene.owner == slot_id(slot)).sum())
        model, pose = objects[slot]
        truth = model.points @ pose[:3, :3].T + pose[:3, 3]
        assert vgn.target_points_between_pads(g.pose, g.width_m, plain.gripper, truth) > 0
        assert g.extras["n_detected"] == len(scene.found.quality)
    for slot in objects:  # a target without a grasp has no detection assigned to it
        if results[slot] is None:
            assert not (scene.owner == slot_id(slot)).any()
    again = vgn.plan_vgn_scene(scene_req)
    for slot, tp in zip(objects, again.plans, strict=True):
        if slot in found:
            np.testing.assert_array_equal(tp.grasp.pose, found[slot].grasp.pose)
    first = vgn.plan_vgn_scene(dataclasses.replace(scene_req, first_found=True))
    assert first.plans[-1].result is not None and all(tp.result is None for tp in first.plans[:-1])
