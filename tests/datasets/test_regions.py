"""Grasping-area specs: semantics of the operations, the shipped spec files, MeshLab import."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import trimesh

from graspexp.config import DatasetConfig
from graspexp.datasets import DatasetError, available_objects, import_meshlab_area, load_object
from graspexp.datasets.catalog import DATASETS
from graspexp.datasets.regions import REGIONS_DIR, apply_ops, load_region_specs

UNIT_BOUNDS = np.array([[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]])


def specs_from(tmp_path: Path, text: str) -> dict:
    path = tmp_path / "spec.yaml"
    path.write_text(text)
    return load_region_specs(path)


def grid(n: int = 11) -> np.ndarray:
    axis = np.linspace(0.0, 1.0, n)
    return np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), axis=-1).reshape(-1, 3)


# --- operation semantics ---------------------------------------------------------------------------------


def test_keep_first_starts_empty_and_keeps_add(tmp_path):
    spec = specs_from(
        tmp_path,
        "a:\n  - keep_box: {min: [0, 0, 0], max: [0.2, 1, 1]}\n  - keep_box: {min: [0.8, 0, 0], max: [1, 1, 1]}\n",
    )["a"]
    p = grid()
    mask = apply_ops(spec.ops, p, UNIT_BOUNDS)
    np.testing.assert_array_equal(mask, (p[:, 0] <= 0.2) | (p[:, 0] >= 0.8))


def test_exclude_first_starts_full_and_excludes_remove(tmp_path):
    spec = specs_from(
        tmp_path,
        "a:\n  - exclude_halfspace: {normal: [0, 0, 1], offset: 0.5}\n"
        "  - exclude_sphere: {center: [0, 0, 0], radius: 0.3}\n",
    )["a"]
    p = grid()
    mask = apply_ops(spec.ops, p, UNIT_BOUNDS)
    np.testing.assert_array_equal(mask, (p[:, 2] < 0.5) & (np.linalg.norm(p, axis=1) > 0.3))


def test_cylinder_and_keep_all(tmp_path):
    spec = specs_from(
        tmp_path,
        "a:\n  - keep_all: {}\n  - exclude_cylinder: {p0: [0.5, 0.5, 0.2], p1: [0.5, 0.5, 0.8], radius: 0.25}\n",
    )["a"]
    p = grid()
    mask = apply_ops(spec.ops, p, UNIT_BOUNDS)
    inside = (np.linalg.norm(p[:, :2] - 0.5, axis=1) <= 0.25) & (p[:, 2] >= 0.2) & (p[:, 2] <= 0.8)
    np.testing.assert_array_equal(mask, ~inside)
    assert inside.sum() > 0 and (~inside).sum() > 0


def test_relative_coordinates_are_fractions_of_the_bounds(tmp_path):
    specs = specs_from(
        tmp_path,
        "rel:\n  relative: true\n  ops: [keep_box: {min: [0, 0, 0.5], max: [1, 1, 1]}]\n"
        "mixed:\n  ops:\n    - keep_box: {min: [0, 0, 0.5], max: [1, 1, 1], relative: true}\n"
        "    - exclude_box: {min: [-1, -1, -1], max: [1, 1, 0.3]}\n",
    )
    bounds = np.array([[-1.0, -1.0, 0.0], [1.0, 1.0, 0.4]])
    p = np.array([[0.0, 0.0, 0.1], [0.0, 0.0, 0.25], [0.0, 0.0, 0.35]])
    np.testing.assert_array_equal(apply_ops(specs["rel"].ops, p, bounds), [False, True, True])
    np.testing.assert_array_equal(apply_ops(specs["mixed"].ops, p, bounds), [False, False, True])


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("a:\n  - keep_cube: {min: [0, 0, 0], max: [1, 1, 1]}\n", "unknown operation 'keep_cube'"),
        ("a:\n  - keep_box: {min: [0, 0, 0]}\n", r"keep_box takes exactly \['min', 'max'\]"),
        ("a:\n  - keep_box: {min: [0, 0], max: [1, 1, 1]}\n", "keep_box.min must be 3 finite"),
        ("a:\n  - keep_box: {min: [1, 0, 0], max: [0, 1, 1]}\n", "min > max"),
        ("a:\n  - keep_sphere: {center: [0, 0, 0], radius: -1}\n", "radius must be > 0"),
        ("a:\n  ops: []\n", "needs at least one operation"),
        ("a:\n  colour: red\n  ops: [keep_all: {}]\n", r"unknown keys \['colour'\]"),
        ("a:\n  - {keep_all: {}, keep_box: {}}\n", "one-key mapping"),
    ],
)
def test_bad_specs_name_file_object_and_problem(tmp_path, text, message):
    with pytest.raises(DatasetError, match=message) as err:
        specs_from(tmp_path, text)
    assert str(tmp_path / "spec.yaml") in str(err.value) and "'a'" in str(err.value)


def test_empty_area_names_object_and_spec_file(tmp_path):
    spec_file = tmp_path / "far.yaml"
    spec_file.write_text("can:\n  - keep_sphere: {center: [5, 5, 5], radius: 0.1}\n")
    cfg = DatasetConfig(name="primitives", regions=str(spec_file))
    with pytest.raises(DatasetError, match=f"empty grasping area for object 'can'.*{spec_file}"):
        load_object(cfg, "can", 256, 0)


def test_object_without_spec_entry_is_grasped_anywhere_and_says_so(tmp_path):
    spec_file = tmp_path / "partial.yaml"
    spec_file.write_text("box: [keep_all: {}]\n")
    model = load_object(DatasetConfig(name="primitives", regions=str(spec_file)), "can", 16, 0)
    assert model.area_mask.all()
    assert "area: whole surface (no entry in partial.yaml)" in model.notes


@pytest.mark.parametrize("value", ['"false"', "0", "yes please"])
def test_relative_must_be_a_yaml_boolean(tmp_path, value):
    spec_file = tmp_path / "strict.yaml"
    spec_file.write_text(f"can:\n  relative: {value}\n  ops: [keep_all: {{}}]\n")
    with pytest.raises(DatasetError, match="relative must be true or false"):
        load_object(DatasetConfig(name="primitives", regions=str(spec_file)), "can", 16, 0)


def test_meshlab_scale_must_be_a_positive_number(tmp_path):
    spec_file = tmp_path / "strict.yaml"
    spec_file.write_text("can:\n  meshlab_ply: area.ply\n  scale: abc\n")
    with pytest.raises(DatasetError, match="scale must be a positive number, got 'abc'"):
        load_object(DatasetConfig(name="primitives", regions=str(spec_file)), "can", 16, 0)


def test_unknown_spec_file_lists_the_shipped_ones():
    with pytest.raises(DatasetError, match="ycb.yaml"):
        load_object(DatasetConfig(name="primitives", regions="nope.yaml"), "can", 16, 0)


# --- the shipped spec files ------------------------------------------------------------------------------


@pytest.mark.parametrize("name", sorted(DATASETS))
def test_every_paper_object_has_a_spec(name):
    """Every object of the paper's lists has its area; the rest of the YCB catalogue is grasped anywhere."""
    specs = load_region_specs(REGIONS_DIR / f"{name}.yaml")
    assert set(DATASETS[name].default_objects) <= set(specs) <= set(DATASETS[name].catalogue)
    assert all(spec.note for spec in specs.values())  # every choice is explained


def test_every_primitive_area_is_a_proper_subset():
    for name in DATASETS["primitives"].catalogue:
        obj = load_object(DatasetConfig(name="primitives", regions="primitives.yaml"), name, 1024, 0)
        assert 0.1 < obj.area_mask.mean() < 0.8, name


def test_every_real_mesh_has_a_non_empty_area(data_root):
    for ds in ("ycb", "linemod"):
        cfg = DatasetConfig(
            name=ds, root=str(data_root), regions=f"{ds}.yaml", objects=list(DATASETS[ds].catalogue)
        )
        for name in available_objects(cfg):
            share = load_object(cfg, name, 1024, 0).area_mask.mean()
            assert 0.1 < share <= 1.0, (name, share)


def test_ycb_mug_area_is_the_body_without_the_handle(data_root):
    cfg = DatasetConfig(name="ycb", root=str(data_root), regions="ycb.yaml")
    mug = load_object(cfg, "025_mug", 4096, 1)
    handle = mug.points[:, 0] > 0.022  # the handle sticks out on +x beyond the body (x <= 0.0196 m)
    assert handle.sum() > 50
    assert not np.any(mug.area_mask & handle)
    radial = np.linalg.norm(mug.area_points[:, :2] - [-0.0211, 0.0173], axis=1)
    assert radial.min() > 0.0395  # outer wall only, the cavity is excluded
    assert mug.area_mask.sum() > 500


def test_primitive_mug_area_excludes_the_handle():
    mug = load_object(DatasetConfig(name="primitives", regions="primitives.yaml"), "mug", 4096, 2)
    assert np.any(mug.points[:, 0] > 0.045)  # the handle exists
    assert mug.area_points[:, 0].max() <= 0.02
    assert np.linalg.norm(mug.area_points[:, :2], axis=1).min() > 0.0375  # not inside the cup


# --- MeshLab import --------------------------------------------------------------------------------------


def test_meshlab_round_trip_metres_and_millimetres(tmp_path):
    # The paper's workflow: export the object's cloud, delete the non-graspable part in MeshLab, save.
    obj = load_object(DatasetConfig(name="primitives", regions="primitives.yaml"), "bottle", 2048, 4)
    truth = (obj.points[:, 2] > 0.05) & (obj.points[:, 2] < 0.12)
    trimesh.PointCloud(obj.points[truth]).export(tmp_path / "area_m.ply")
    trimesh.PointCloud(obj.points[truth] * 1000.0).export(tmp_path / "area_mm.ply")
    mask_m = import_meshlab_area(tmp_path / "area_m.ply", obj.points)
    mask_mm = import_meshlab_area(tmp_path / "area_mm.ply", obj.points, scale=1e-3)
    np.testing.assert_array_equal(mask_m, mask_mm)
    assert mask_m[truth].all()  # every area point maps onto itself
    extra = mask_m & ~truth  # neighbours within the tolerance, only along the band's two edges
    assert extra.mean() < 0.02
    assert np.all(
        np.minimum(np.abs(obj.points[extra, 2] - 0.05), np.abs(obj.points[extra, 2] - 0.12)) < 0.004
    )


def test_meshlab_area_from_another_sampling_maps_with_a_tolerance(tmp_path):
    obj = load_object(DatasetConfig(name="primitives", regions="primitives.yaml"), "bottle", 2048, 4)
    dense, _ = trimesh.sample.sample_surface(obj.mesh, 20000, seed=99)  # a different, denser cloud
    trimesh.PointCloud(dense[(dense[:, 2] > 0.05) & (dense[:, 2] < 0.12)]).export(tmp_path / "area.ply")
    mask = import_meshlab_area(tmp_path / "area.ply", obj.points, tolerance_m=0.003)
    z = obj.points[:, 2]
    assert mask[(z > 0.055) & (z < 0.115)].all()
    assert not mask[(z < 0.045) | (z > 0.125)].any()


def test_meshlab_ply_entry_in_a_spec_file(tmp_path):
    obj = load_object(DatasetConfig(name="primitives", regions="primitives.yaml"), "box", 1024, 0)
    dense, _ = trimesh.sample.sample_surface(obj.mesh, 20000, seed=5)
    trimesh.PointCloud(dense[dense[:, 0] > 0.0] * 1000.0).export(tmp_path / "box_area.ply")
    spec_file = tmp_path / "regions.yaml"
    spec_file.write_text(
        "box:\n  meshlab_ply: box_area.ply\n  scale: 0.001\n  ops:\n"
        "    - exclude_halfspace: {normal: [0, 0, 1], offset: 0.1}\n"
    )
    box = load_object(DatasetConfig(name="primitives", regions=str(spec_file)), "box", 1024, 0)
    assert box.area_mask.sum() > 200
    assert box.area_points[:, 0].min() > -0.003 and box.area_points[:, 2].max() < 0.1


def test_meshlab_file_found_under_the_data_root(tmp_path):
    root, specs = tmp_path / "data", tmp_path / "specs"
    root.mkdir()
    specs.mkdir()
    obj = load_object(DatasetConfig(name="primitives", regions="primitives.yaml"), "can", 512, 0)
    trimesh.PointCloud(obj.mesh.vertices).export(root / "can_area.ply")
    (specs / "r.yaml").write_text("can:\n  meshlab_ply: can_area.ply\n  tolerance_m: 0.05\n")
    can = load_object(
        DatasetConfig(name="primitives", root=str(root), regions=str(specs / "r.yaml")), "can", 512, 0
    )
    assert can.area_mask.all()
    (specs / "r.yaml").write_text("can:\n  meshlab_ply: missing.ply\n")
    with pytest.raises(DatasetError, match="MeshLab area file for object 'can'.*missing.ply"):
        load_object(
            DatasetConfig(name="primitives", root=str(root), regions=str(specs / "r.yaml")), "can", 512, 0
        )


def test_meshlab_import_rejects_a_single_point(tmp_path):
    trimesh.PointCloud(np.zeros((1, 3))).export(tmp_path / "one.ply")
    with pytest.raises(DatasetError, match="at least 2 finite points"):
        import_meshlab_area(tmp_path / "one.ply", np.zeros((4, 3)))
