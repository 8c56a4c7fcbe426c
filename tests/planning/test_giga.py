"""planner=giga and the single-view VGN checkpoints of GIGA's release (the optional extra ``learned``): GIGA's
checkpoints load strictly into the network written here and give the same outputs every time, its queries sit
where VGN places its grasps, ``scatter_mean`` is a mean, the detection's wall margin and forced candidate
(GIGA's additions, off for VGN by default) keep the right voxels, a plan on a rendered object holds it between
the pads; ``planner.checkpoint`` names VGN's weights (``vgn_pile`` loads strictly into VGN's network), each
pinned by its hash, and a wrong name is one line.

The main suite skips this module without torch and Open3D (``nox -s learned`` installs them); the checkpoints
come from ``$GRASPEXP_CHECKPOINTS``, else ``peers/giga`` and ``peers/vgn`` beside the shared data root."""

from __future__ import annotations

import dataclasses
import hashlib
import os

import numpy as np
import pytest
import trimesh

torch = pytest.importorskip(
    "torch", reason="planner=giga needs the optional extra: pip install -e '.[learned]'"
)
o3d = pytest.importorskip(
    "open3d", reason="planner=giga needs the optional extra: pip install -e '.[learned]'"
)

from helpers.config import compose_cfg, shared_data_root  # noqa: E402
from omegaconf import OmegaConf  # noqa: E402

from graspexp.config import ConfigError  # noqa: E402
from graspexp.config.planner import giga as giga_schema  # noqa: E402
from graspexp.config.planner import vgn as vgn_schema  # noqa: E402
from graspexp.config.plugins import planner_names  # noqa: E402
from graspexp.config.validate import validate  # noqa: E402
from graspexp.core import checkpoints  # noqa: E402
from graspexp.grippers import GripperGeometry  # noqa: E402
from graspexp.perception.camera import BoxBody, MeshBody  # noqa: E402
from graspexp.perception.observe import observe  # noqa: E402
from graspexp.planning import PlanRequest, plan  # noqa: E402
from graspexp.planning.learned import giga, giga_network, vgn, vgn_network  # noqa: E402

pytestmark = pytest.mark.learned
PEERS = shared_data_root().parent / "peers"
"""``../shared/peers``: GIGA's release in ``giga/``, VGN's own checkpoint in ``vgn/``."""
TABLE_Z = 0.1
"""Support top, m (``mode.support_height_m``)."""
GIGA = tuple(giga_schema.GIGA_CHECKPOINTS.values())


@pytest.fixture(autouse=True)
def _checkpoint_dirs(monkeypatch: pytest.MonkeyPatch) -> None:
    """``$GRASPEXP_CHECKPOINTS`` (one folder or several, ``os.pathsep``), else the shared peers' folders; a
    test skips when GIGA's release is not there (never a copy inside the repository)."""
    default = os.pathsep.join(str(PEERS / d) for d in ("giga", "vgn"))
    monkeypatch.setenv(checkpoints.CHECKPOINTS_ENV, os.environ.get(checkpoints.CHECKPOINTS_ENV, default))
    missing = [c.filename for c in (*GIGA, checkpoints.VGN_PILE) if checkpoints.missing_reason(c)]
    if missing:
        pytest.skip(f"{', '.join(missing)} not in ${checkpoints.CHECKPOINTS_ENV}: download_checkpoint NAME")


@pytest.fixture
def registered() -> None:
    """``planner=giga`` composes only where graspexp's install metadata holds its entry point."""
    if "giga" not in planner_names():
        pytest.skip("graspexp's install metadata predates planner=giga's entry point: pip install -e .")


def _planner(*overrides: str):
    return OmegaConf.to_object(compose_cfg(*overrides)).planner


@pytest.mark.parametrize("ckpt", GIGA, ids=lambda c: c.name)
def test_gigas_checkpoints_load_strictly_into_the_network_written_here(ckpt):
    net = giga_network.load_giga(ckpt)
    state = torch.load(checkpoints.checkpoint_path(ckpt), map_location="cpu", weights_only=True)
    assert len(state) == 164 and set(state) == set(net.state_dict())
    heads = {k.split(".")[0] for k in state}
    assert heads == {"encoder", "decoder_qual", "decoder_rot", "decoder_width", "decoder_tsdf"}


def test_gigas_outputs_repeat_bit_for_bit_with_one_thread_count():
    grid = np.random.default_rng(0).uniform(0, 1, (40, 40, 40)).astype(np.float32)
    net = giga.network("giga_pile")
    first = giga.infer(net, grid, threads=1)
    again = giga.infer(giga_network.load_giga(giga_schema.GIGA_PILE), grid, threads=1)
    two = giga.infer(net, grid, threads=2)
    for a, b, c in zip(first, again, two, strict=True):
        assert np.array_equal(a, b)
        np.testing.assert_allclose(a, c, rtol=1e-4, atol=1e-5)  # another thread count: the last digits
    quality, rot, width = first
    assert quality.shape == width.shape == (40, 40, 40) and rot.shape == (4, 40, 40, 40)
    assert 0 <= quality.min() and quality.max() <= 1
    np.testing.assert_allclose(np.linalg.norm(rot, axis=0), 1.0, atol=1e-5)
    packed = giga.infer(giga.network("giga_packed"), grid, threads=1)
    assert not np.array_equal(packed[0], quality)  # each name loads its own weights


def test_scatter_mean_averages_what_each_cell_receives():
    rng = np.random.default_rng(1)
    src = torch.from_numpy(rng.normal(size=(2, 3, 50)).astype(np.float32))
    index = torch.from_numpy(rng.integers(0, 7, size=(2, 50)))
    index[index == 6] = 5  # cells 6 and 7 receive nothing
    out = giga_network.scatter_mean(src, index, 8)
    for b in range(2):
        for cell in range(8):
            mine = src[b][:, index[b] == cell]
            expected = mine.mean(dim=1) if mine.shape[1] else torch.zeros(3)
            torch.testing.assert_close(out[b, :, cell], expected)
    assert out.shape == (2, 3, 8) and not out[:, :, 6:].any()


def test_the_queries_sit_where_vgn_places_the_grasp_of_each_voxel():
    p = giga_network.voxel_queries(40)[0]
    idx = np.argwhere(np.ones((40, 40, 40), bool))  # C order, as the outputs are reshaped
    np.testing.assert_allclose(
        (p.numpy().astype(np.float64) + 0.5) * vgn.SIZE_M, idx * vgn.VOXEL_M, atol=1e-7
    )
    # every voxel of the grid falls in its own cell of each feature plane (the encoder's average is per column)
    coords = torch.linspace(-0.5, 0.5, 40)
    for plane in giga_network.PLANES:
        cells = (giga_network.plane_coordinates(coords[None, :, None].expand(1, 40, 3), plane) * 40).long()
        assert torch.equal(cells[0, :, 0], torch.arange(40)) and torch.equal(cells[0, :, 1], torch.arange(40))


def test_a_changed_giga_checkpoint_is_refused_by_its_hash(tmp_path, monkeypatch):
    ckpt = giga_schema.GIGA_PILE
    data = bytearray(checkpoints.checkpoint_path(ckpt).read_bytes())
    data[-100] ^= 0xFF
    (tmp_path / ckpt.filename).write_bytes(bytes(data))
    monkeypatch.setenv(checkpoints.CHECKPOINTS_ENV, str(tmp_path))
    with pytest.raises(
        checkpoints.CheckpointError, match=r"^checkpoint .* has SHA-256 [0-9a-f]{64}, not the"
    ):
        giga_network.load_giga(ckpt)


def test_a_missing_giga_checkpoint_or_extra_stops_the_config_with_one_line(registered, tmp_path, monkeypatch):
    monkeypatch.setenv(checkpoints.CHECKPOINTS_ENV, str(tmp_path))
    with pytest.raises(ConfigError) as err:
        validate(compose_cfg("planner=giga"))
    assert str(err.value).startswith("planner=giga cannot run here: checkpoint ")
    assert "python -m graspexp download_checkpoint giga_pile" in str(err.value) and "\n" not in str(err.value)
    monkeypatch.setattr(vgn_schema, "find_spec", lambda name: None if name == "torch" else object())
    with pytest.raises(
        ConfigError, match=r"needs torch, the optional extra 'learned': pip install -e '\.\[learned\]'$"
    ):
        validate(compose_cfg("planner=giga"))


def _peaks(quality_of: dict[tuple[int, int, int], float]):
    """A grid whose free space above a floor at k = 10 is seen, and a raw quality of ``quality_of`` at those
    voxels (0 elsewhere), identity rotations and 37.5 mm widths: the inputs of :func:`vgn.detect`."""
    grid = np.zeros((40, 40, 40), np.float32)
    grid[:, :, 10:14] = 0.9
    grid[:, :, 8:10] = 0.3
    quality = np.zeros((40, 40, 40), np.float32)
    for at, q in quality_of.items():
        quality[at] = q
    rot = np.zeros((4, 40, 40, 40), np.float32)
    rot[3] = 1.0
    return grid, quality, rot, np.full((40, 40, 40), 5.0, np.float32)


def _found(found) -> list[tuple[int, ...]]:
    return sorted(tuple(int(v) for v in np.rint(p[:3, 3] / vgn.VOXEL_M)) for p in found.poses)


def test_the_forced_candidate_is_the_best_one_above_the_force_threshold_when_none_reaches_the_threshold():
    low = {(10, 10, 11): 0.6, (30, 30, 11): 0.7, (20, 20, 11): 0.4}
    inputs = _peaks(low)
    plain = _planner("planner=vgn", "planner.quality_sigma_voxels=0")
    assert plain.force_threshold is None and len(vgn.detect(*inputs, plain).poses) == 0  # VGN's default
    forced = dataclasses.replace(plain, force_threshold=0.5)
    found = vgn.detect(*inputs, forced)
    assert _found(found) == [(30, 30, 11)] and found.quality.tolist() == pytest.approx([0.7])
    assert len(vgn.detect(*inputs, dataclasses.replace(plain, force_threshold=0.75)).poses) == 0
    # one candidate reaching the threshold: the usual detection, every such candidate, nothing forced
    high = _peaks({**low, (5, 30, 11): 0.95, (30, 5, 11): 0.92})
    assert _found(vgn.detect(*high, forced)) == [(5, 30, 11), (30, 5, 11)]


def test_the_wall_margin_drops_the_outer_voxel_layers_along_x_and_y():
    along = {(i, 20, 11): 1.0 for i in (0, 1, 2, 37, 38, 39)} | {(20, j, 11): 1.0 for j in (1, 2, 38)}
    inputs = _peaks(along)
    plain = _planner("planner=vgn", "planner.quality_sigma_voxels=0", "planner.nms_size_voxels=1")
    assert plain.wall_margin_m == 0 and len(_found(vgn.detect(*inputs, plain))) == 9  # VGN's default: off
    margin = dataclasses.replace(plain, wall_margin_m=0.02)  # GIGA's 2 cm: int(0.02 / 0.0075) = 2 layers
    assert _found(vgn.detect(*inputs, margin)) == [(2, 20, 11), (20, 2, 11), (37, 20, 11)]


def test_gigas_schema_is_vgns_with_gigas_checkpoints_widths_and_wall_margin(registered):
    cfg = _planner("planner=giga")
    assert (cfg.checkpoint, cfg.wall_margin_m, cfg.force_threshold, cfg.selection) == (
        "giga_pile",
        0.02,
        None,
        "random",
    )
    assert (cfg.min_width_m, cfg.max_width_m) == (0.0099, 0.0699)  # 0.033 and 0.233 of the 30 cm workspace
    assert _planner("planner=giga", "planner.checkpoint=giga_packed").checkpoint == "giga_packed"
    with pytest.raises(ConfigError) as err:
        validate(compose_cfg("planner=giga", "planner.checkpoint=vgn_pile"))
    assert str(err.value) == (
        "planner.checkpoint='vgn_pile' is invalid: expected one of giga_pile, giga_packed"
    )


def _upright(mesh: trimesh.Trimesh, azimuths=(0.0,)):
    """``mesh`` upright at the support's centre in bin mode, seen by the simulated depth camera (the D435
    preset, its noise model on) from ``azimuths``: the observation (target id 1) and the object's pose."""
    cfg = OmegaConf.to_object(compose_cfg("mode=bin", f"perception.camera.azimuths_deg={list(azimuths)}"))
    pose = np.eye(4)
    pose[:3, 3] = [0.0, 0.0, TABLE_Z - mesh.bounds[0, 2]]
    half = tuple(cfg.mode.support_half_size_m)
    support = BoxBody(np.array([-half[0], -half[1], 0.0]), np.array([half[0], half[1], TABLE_Z]))
    obs = observe(
        cfg.perception, [MeshBody(mesh, pose, 1)], [support], TABLE_Z, 1, rng=np.random.default_rng(0)
    )
    return obs, pose


def _request(obs, *overrides: str, seed: int = 3) -> PlanRequest:
    cfg = OmegaConf.to_object(compose_cfg("planner=giga", "gripper=panda", "mode=bin", *overrides))
    empty = np.zeros((0, 3))
    req = PlanRequest(
        empty, empty, np.zeros(0, bool), np.eye(4), TABLE_Z, "bin", cfg.gripper, cfg.planner, cfg.cost, seed
    )
    return dataclasses.replace(req, observation=obs)


def _holds(grasp, req: PlanRequest, mesh: trimesh.Trimesh, pose: np.ndarray) -> bool:
    """Whether ``mesh`` at ``pose`` lies between the pads of ``grasp`` (points of its surface within the
    opening between the finger roots and tips) and none of it where a pad is (within a finger's thickness
    beyond the opening)."""
    surface = trimesh.sample.sample_surface_even(mesh, 20000, seed=1)[0] @ pose[:3, :3].T + pose[:3, 3]
    thickness = GripperGeometry.of(req.gripper).finger_thickness_m
    between = vgn.target_points_between_pads(grasp.pose, grasp.width_m, req.gripper, surface)
    with_pads = vgn.target_points_between_pads(
        grasp.pose, grasp.width_m + 2 * thickness, req.gripper, surface
    )
    return between > 50 and with_pads == between


PILE_MEDIAN_BOX_M = (0.044, 0.07, 0.087)
"""A box of the median extents of the pile test objects of GIGA's protocol (issue 49), m."""


def test_planner_giga_holds_a_rendered_box_between_its_pads_and_repeats(registered):
    """A box of the pile objects' median size upright on the support, three D435 views (test_vgn's box
    scene): GIGA's grasp (``giga_pile``, the default) holds it between its pads, the same every time."""
    mesh = trimesh.creation.box(PILE_MEDIAN_BOX_M)
    obs, pose = _upright(mesh, (0.0, 120.0, 240.0))
    result = plan(_request(obs))
    g = result.grasp
    req = _request(obs)
    assert g.planner == "giga" and g.width_m == req.gripper.max_width_m and g.extras["trained_for"] == "panda"
    np.testing.assert_allclose(g.pose[:3, :3].T @ g.pose[:3, :3], np.eye(3), atol=1e-6)
    assert _holds(g, req, mesh, pose)
    assert g.extras["quality"] >= 0.9 and g.extras["infer_cpu_s"] > 0
    assert result.details["quality"].shape == (40, 40, 40)
    again = plan(_request(obs)).grasp
    np.testing.assert_array_equal(g.pose, again.pose)
    assert again.extras["quality"] == g.extras["quality"]
    best = plan(_request(obs, "planner.selection=best")).grasp
    assert best.extras["quality"] >= g.extras["quality"]


def test_planner_giga_holds_the_rendered_ycb_soup_can(registered, data_root):
    """The soup can (Table 1) upright on the support, one D435 view as in a trial (test_vgn's scene)."""
    from graspexp.datasets import load_object

    model = load_object(
        compose_cfg("dataset=ycb", f"dataset.root={data_root}").dataset, "005_tomato_soup_can", 256, 0
    )
    obs, pose = _upright(model.mesh)
    req = _request(obs)
    g = plan(req).grasp
    assert _holds(g, req, model.mesh, pose), g


@pytest.mark.parametrize("ckpt", [checkpoints.VGN_PILE, checkpoints.VGN_PACKED], ids=lambda c: c.name)
def test_vgns_single_view_checkpoints_load_strictly_into_vgns_network(ckpt):
    net = vgn_network.load_vgn(ckpt)
    state = torch.load(checkpoints.checkpoint_path(ckpt), map_location="cpu", weights_only=True)
    assert len(state) == 18 and set(state) == set(net.state_dict())
    assert checkpoints.CHECKPOINTS[ckpt.name] is ckpt and ckpt.url.endswith(f"/data/models/{ckpt.filename}")


def test_planner_vgn_names_its_checkpoint_and_a_changed_one_is_refused(tmp_path, monkeypatch):
    assert _planner("planner=vgn").checkpoint == "vgn_conv"  # VGN's own model by default
    validate(compose_cfg("planner=vgn", "planner.checkpoint=vgn_packed"))
    grid = np.random.default_rng(0).uniform(0, 1, (40, 40, 40)).astype(np.float32)
    pile = vgn.vgn_outputs(grid, _planner("planner=vgn", "planner.checkpoint=vgn_pile"))
    assert not np.array_equal(pile[0], vgn.vgn_outputs(grid, _planner("planner=vgn"))[0])
    data = bytearray(checkpoints.checkpoint_path(checkpoints.VGN_PILE).read_bytes())
    data[-100] ^= 0xFF
    (tmp_path / checkpoints.VGN_PILE.filename).write_bytes(bytes(data))
    monkeypatch.setenv(checkpoints.CHECKPOINTS_ENV, str(tmp_path))
    with pytest.raises(
        checkpoints.CheckpointError, match=r"^checkpoint .*vgn_pile\.pt has SHA-256 [0-9a-f]{64}, not"
    ):
        vgn_network.load_vgn(checkpoints.VGN_PILE)


def test_a_wrong_checkpoint_name_is_one_line():
    with pytest.raises(ConfigError) as err:
        validate(compose_cfg("planner=vgn", "planner.checkpoint=vgn_conv.pth"))
    assert str(err.value) == (
        "planner.checkpoint='vgn_conv.pth' is invalid: expected one of vgn_conv, vgn_pile, vgn_packed"
    )


def test_download_checkpoint_knows_every_checkpoint_by_name(registered):
    from graspexp.tools.download_checkpoint import known_checkpoints

    known = known_checkpoints()
    for ckpt in (checkpoints.VGN, checkpoints.VGN_PILE, checkpoints.VGN_PACKED, *GIGA):
        assert known[ckpt.name] is ckpt
    for ckpt in (
        *GIGA,
        checkpoints.VGN_PILE,
        checkpoints.VGN_PACKED,
    ):  # the pins are the shared files' hashes
        assert hashlib.sha256(checkpoints.checkpoint_path(ckpt).read_bytes()).hexdigest() == ckpt.sha256
