"""Collision shapes: the outside-distance measure on cases with a known answer, the cache, the
prepare step, and the 1 mm target on real meshes."""

import numpy as np
import pytest
import trimesh
from helpers.config import compose_cfg
from omegaconf import OmegaConf

from graspexp.config import SimConfig
from graspexp.datasets.loader import object_mesh
from graspexp.run.prepare import prepare_shapes
from graspexp.sim.collision_accuracy import (
    shape_accuracy,
    signed_distance_m,
    surface_points,
    uncovered_m,
    union_surface_points,
)
from graspexp.sim.collision_shapes import collision_shape, is_cached, shape_params
from graspexp.sim.scene import build_scene
from graspexp.sim.shape import CollisionShape

R = 0.05
"""Radius of the test sphere, m."""


def _sphere() -> trimesh.Trimesh:
    return trimesh.creation.icosphere(subdivisions=4, radius=R)


def _part_of(vertices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    hull = trimesh.convex.convex_hull(vertices)
    return np.asarray(hull.vertices, dtype=np.float32), np.asarray(hull.faces)


def _box_vertices(half: float, centre=(0.0, 0.0, 0.0)) -> np.ndarray:
    return np.asarray(trimesh.creation.box(extents=[2 * half] * 3).vertices + centre, dtype=np.float32)


def test_signed_distance_is_the_radial_gap_outside_and_negative_inside():
    pts = np.random.default_rng(0).normal(size=(500, 3))
    pts /= np.linalg.norm(pts, axis=1, keepdims=True)
    radii = np.random.default_rng(1).uniform(0.5 * R, 1.5 * R, size=500)
    d = signed_distance_m(pts * radii[:, None], _sphere())
    # the icosphere's faces lie up to R (1 - cos(edge angle / 2)) ~ 0.06 mm inside the true sphere
    np.testing.assert_allclose(d, radii - R, atol=1e-4)


def test_signed_distance_sign_holds_on_an_open_mesh():
    sphere = _sphere()
    open_mesh = trimesh.Trimesh(sphere.vertices, sphere.faces[sphere.triangles_center[:, 2] < 0.9 * R])
    assert not open_mesh.is_watertight
    pts = np.array([[R + 0.002, 0, 0], [R - 0.002, 0, 0], [0, -R - 0.001, 0], [0, 0, -R + 0.003]])
    d = signed_distance_m(pts, open_mesh)
    np.testing.assert_allclose(d, [0.002, -0.002, 0.001, -0.003], atol=5e-5)


def test_box_hull_around_a_sphere_has_the_analytic_outside_distance():
    # a cube of half-size R around the sphere: a face point (x, y, R) lies sqrt(x^2 + y^2 + R^2) - R out
    acc = shape_accuracy(
        union_surface_points([_box_vertices(R)], 5000, rng=np.random.default_rng(0)), _sphere()
    )
    u = np.random.default_rng(2).uniform(-R, R, size=(200000, 2))
    exact = (np.sqrt((u**2).sum(axis=1) + R**2) - R) * 1e3
    # sampling error of a percentile from 5000 samples: about 1 %
    assert acc.outside_p50_mm == pytest.approx(np.median(exact), rel=0.03)
    assert acc.outside_p90_mm == pytest.approx(np.percentile(exact, 90), rel=0.03)
    corner = (np.sqrt(3) - 1) * R * 1e3  # the largest gap, at the cube's corners (samples come near)
    assert 0.97 * corner <= acc.outside_max_mm <= corner + 0.1
    assert acc.inside_p90_mm == 0.0


def test_union_surface_drops_samples_inside_or_on_another_hull():
    a, b = _box_vertices(0.01), _box_vertices(0.01, (0.01, 0.0, 0.0))  # overlap in x in [0, 0.01]
    pts = union_surface_points([a, b], 5000, rng=np.random.default_rng(0))
    union = trimesh.creation.box(
        extents=[0.03, 0.02, 0.02], transform=trimesh.transformations.translation_matrix([0.005, 0, 0])
    )
    assert np.abs(signed_distance_m(pts, union)).max() < 1e-6
    # the union's area is 2 * (3*2 + 3*2 + 2*2) cm^2 = 32 of the two boxes' 48: about 2/3 of the samples kept
    assert len(pts) / 5000 == pytest.approx(32 / 48, abs=0.03)


def test_mesh_shape_is_closed_cached_and_keyed_by_parameters(tmp_path):
    sim = SimConfig(cache_dir=str(tmp_path), mesh_max_faces=1000)
    mesh = trimesh.creation.torus(0.04, 0.01, major_sections=64, minor_sections=32)  # 4096 faces, not convex
    assert not is_cached(mesh, sim)
    shape = collision_shape(mesh, sim)
    assert not shape.convex and len(shape.parts) == 1 and shape.mesh_file.is_file()
    closed = shape.meshes()[0]
    assert closed.is_watertight and len(closed.faces) < len(mesh.faces)  # decimated within the tolerance
    assert is_cached(mesh, sim)
    again = collision_shape(mesh, sim)
    np.testing.assert_array_equal(again.parts[0][0], shape.parts[0][0])
    assert not is_cached(mesh, SimConfig(cache_dir=str(tmp_path), mesh_max_faces=800))


def test_convex_mesh_is_its_own_hull_under_every_method(tmp_path):
    box = trimesh.creation.box(extents=[0.02, 0.03, 0.04])
    for method in ("mesh", "coacd", "vhacd"):
        shape = collision_shape(box, SimConfig(cache_dir=str(tmp_path), collision_method=method))
        assert shape.convex and len(shape.parts) == 1


def test_unknown_method_names_the_key_and_the_choices():
    with pytest.raises(
        ValueError, match=r"sim.collision_method='sdf' is invalid: expected one of mesh, coacd, vhacd"
    ):
        shape_params(SimConfig(collision_method="sdf"))


@pytest.mark.slow
def test_prepare_builds_every_missing_shape_in_parallel(tmp_path):
    cfg = compose_cfg("dataset=primitives", f"sim.cache_dir={tmp_path}", "sim.prepare_workers=2")
    names = ["mug", "banana", "can"]
    prepare_shapes(cfg.dataset, cfg.sim, names, progress=False)
    assert all(is_cached(object_mesh(cfg.dataset, n)[0].mesh, cfg.sim) for n in names)


def _prepare_and_check(cache_dir: str) -> bool:
    cfg = compose_cfg("dataset=primitives", f"sim.cache_dir={cache_dir}", "sim.prepare_workers=2")
    names = ["mug", "banana"]
    prepare_shapes(cfg.dataset, cfg.sim, names, progress=False)
    return all(is_cached(object_mesh(cfg.dataset, n)[0].mesh, cfg.sim) for n in names)


@pytest.mark.slow
def test_prepare_inside_a_joblib_worker_builds_in_process(tmp_path):
    """A benchmark job runs in a loky worker, whose children cannot be spawned by multiprocessing."""
    from joblib import Parallel, delayed

    assert Parallel(n_jobs=2, backend="loky")([delayed(_prepare_and_check)(str(tmp_path))]) == [True]


@pytest.mark.parametrize("name", ["025_mug", "005_tomato_soup_can"])
def test_default_shape_is_within_1_mm_of_real_meshes(data_root, name):
    cfg = OmegaConf.create({"name": "ycb", "root": str(data_root), "objects": []})
    mesh = object_mesh(cfg, name)[0].mesh
    shape = collision_shape(mesh, SimConfig())
    acc = shape_accuracy(surface_points(shape, 5000, rng=np.random.default_rng(0)), mesh)
    assert acc.outside_p90_mm <= 1.0
    assert acc.inside_p90_mm <= 1.0


def test_mesh_rests_on_the_support_and_sdf_spacing_changes_no_contact(tmp_path):
    cfg = compose_cfg("dataset=primitives", "mode=bin")  # a wide table: the mug may roll
    mode = OmegaConf.to_object(cfg.mode)
    mesh = object_mesh(cfg.dataset, "mug")[0].mesh
    lying = np.array([[1.0, 0, 0, 0], [0, 0, -1, 0], [0, 1, 0, mode.support_height_m + 0.08], [0, 0, 0, 1]])
    poses = []
    for spacing in (0.01, 0.003):
        sim = SimConfig(cache_dir=str(tmp_path / str(spacing)), sdf_spacing_m=spacing)
        shape = collision_shape(mesh, sim)
        assert not shape.convex
        ts = build_scene(shape, 0.2, lying, mode, sim)
        for _ in range(480):
            ts.scene.step()
        poses.append(ts.object_pose())
        lowest = (mesh.vertices @ poses[-1][:3, :3].T + poses[-1][:3, 3])[:, 2].min()
        assert lowest == pytest.approx(mode.support_height_m, abs=5e-4)
    # contacts with boxes use the triangles, not the SDF grid: the same landing, bit for bit
    np.testing.assert_array_equal(poses[0], poses[1])


def test_uncovered_distance_of_a_sphere_around_a_small_cube():
    # sphere points outside a cube of half-size R/2: R/2 out along the axes, R (1 - sqrt(3)/2) on diagonals
    shape = CollisionShape("coacd", (_part_of(_box_vertices(R / 2)),), True)
    pts, _ = trimesh.sample.sample_surface(_sphere(), 4000, seed=0)
    d = uncovered_m(pts, shape)
    assert d.max() == pytest.approx(R / 2, rel=0.03)
    assert d.min() == pytest.approx(R * (1 - np.sqrt(3) / 2), rel=0.05)
    assert uncovered_m(pts * 0.5, shape).max() == 0.0  # a sphere inside the cube is covered


def test_mesh_shape_keeps_every_sizeable_part(tmp_path):
    cfg = compose_cfg("dataset=primitives")
    mesh = object_mesh(cfg.dataset, "mug")[0].mesh  # body and handle are separate parts
    shape = collision_shape(mesh, SimConfig(cache_dir=str(tmp_path)))
    pts, _ = trimesh.sample.sample_surface(mesh, 3000, seed=0)
    assert np.percentile(uncovered_m(pts, shape), 90) < 2e-4


@pytest.mark.parametrize("damage", ["truncate_npz", "garbage_npz", "cut_obj"])
def test_a_damaged_cache_entry_is_rebuilt_never_used(tmp_path, damage):
    from graspexp.sim.collision_shapes import mesh_key

    cfg = SimConfig(cache_dir=str(tmp_path), collision_method="mesh")
    mesh = trimesh.creation.annulus(r_min=0.02, r_max=0.04, height=0.06, sections=32)  # concave: a ring
    first = collision_shape(mesh, cfg)
    assert not first.convex and first.key == mesh_key(mesh, shape_params(cfg))
    npz = tmp_path / "collision" / f"{first.key}.npz"
    obj = npz.with_suffix(".obj")
    good_obj = obj.read_bytes()
    if damage == "truncate_npz":
        npz.write_bytes(npz.read_bytes()[:100])
    elif damage == "garbage_npz":
        npz.write_bytes(b"PK\x03\x04 not a zip")
    else:
        lines = obj.read_text().splitlines()
        faces = [i for i, ln in enumerate(lines) if ln.startswith("f ")]
        obj.write_text("\n".join(ln for i, ln in enumerate(lines) if i not in set(faces[::2])) + "\n")
    assert damage == "cut_obj" or not is_cached(mesh, cfg)
    again = collision_shape(mesh, cfg)
    for (v0, f0), (v1, f1) in zip(first.parts, again.parts, strict=True):
        np.testing.assert_array_equal(v0, v1)
        np.testing.assert_array_equal(f0, f1)
    assert obj.read_bytes() == good_obj and is_cached(mesh, cfg)


def test_the_cache_key_holds_the_library_versions(monkeypatch):
    from graspexp.sim import collision_shapes

    mesh, params = _sphere(), shape_params(SimConfig())
    key = collision_shapes.mesh_key(mesh, params)
    monkeypatch.setattr(collision_shapes, "_library_versions", lambda method: {"pymeshfix": "99"})
    assert collision_shapes.mesh_key(mesh, params) != key


def test_an_unrepairable_mesh_falls_back_once_then_reads_its_note_from_the_cache(tmp_path, monkeypatch):
    from graspexp.sim import collision_shapes

    cross = np.array(
        [[-4, 0, 0], [4, 0, 0], [4, 0, 10], [-4, 0, 10], [0, -4, 0], [0, 4, 0], [0, 4, 10], [0, -4, 10]]
    )
    mesh = trimesh.Trimesh(cross / 100.0, [[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]])  # two crossed sheets
    cfg = SimConfig(cache_dir=str(tmp_path), collision_method="mesh")
    shape, note = collision_shapes.shape_with_fallback(mesh, cfg)
    assert shape.method == "coacd" and note.startswith(
        "collision: coacd (fallback: sim.collision_method=mesh"
    )
    assert len(list(tmp_path.rglob("*.fallback.json"))) == 1

    def no_repair(*args, **kwargs):
        raise AssertionError("the failed repair was tried again")

    monkeypatch.setattr(collision_shapes, "_closed_mesh", no_repair)
    monkeypatch.setattr(collision_shapes, "shape_accuracy", no_repair)
    again, again_note = collision_shapes.shape_with_fallback(mesh, cfg)
    assert again_note == note and again.key == shape.key
    next(tmp_path.rglob("*.fallback.json")).write_text("{")  # a damaged record: the repair is tried again
    with pytest.raises(AssertionError, match="tried again"):
        collision_shapes.shape_with_fallback(mesh, cfg)
