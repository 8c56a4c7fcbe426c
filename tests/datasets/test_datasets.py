"""Loaders, catalogues, primitives and error messages of graspexp.datasets."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import trimesh
import yaml
from helpers.config import compose_cfg
from omegaconf import OmegaConf

from graspexp.config import DatasetConfig
from graspexp.datasets import (
    DatasetError,
    ObjectModel,
    available_objects,
    dataset_objects,
    load_object,
    primitives,
    resolve_root,
)
from graspexp.datasets.catalog import DATASETS, YCB_MASS_KG, dataset_spec
from graspexp.datasets.loader import _load_mesh_cached

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture(scope="session")
def manifest(data_root: Path) -> dict[str, dict]:
    files = json.loads((data_root / "manifest.json").read_text())["files"]
    return {f["path"]: f for f in files}


def make_cfg(name: str, root: Path | str | None = None, **kw) -> DatasetConfig:
    return DatasetConfig(name=name, root=None if root is None else str(root), regions=f"{name}.yaml", **kw)


def shared_objects(data_root: Path) -> list[tuple[str, str]]:
    pairs = []
    for ds in ("ycb", "linemod"):
        cfg = make_cfg(ds, data_root, objects=list(DATASETS[ds].catalogue))
        pairs += [(ds, n) for n in available_objects(cfg)]
    return pairs


def write_cube_obj(path: Path, size_m: float = 0.05) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    trimesh.creation.box(extents=[size_m] * 3).export(path)
    return path


# --- real meshes -------------------------------------------------------------------------------------


@pytest.mark.slow
def test_every_shared_object_loads_in_metres(data_root, manifest):
    pairs = shared_objects(data_root)
    assert len(pairs) == 23 + 9  # SOURCES.md: 23 YCB meshes, 9 of 13 LINEMOD meshes
    for ds, name in pairs:
        obj = load_object(make_cfg(ds, data_root), name, n_points=256, seed=3)
        assert isinstance(obj, ObjectModel) and obj.name == name and obj.dataset == ds
        entry = manifest[str(Path(obj.source).relative_to(data_root.resolve()))]
        scale = 1e-3 if ds == "linemod" else 1.0  # manifest keeps file units (mm for LINEMOD)
        np.testing.assert_allclose(obj.mesh.extents, np.asarray(entry["extents"]) * scale, atol=2e-4)
        assert obj.points.shape == (256, 3) and obj.points.dtype == np.float64
        assert obj.normals.shape == (256, 3) and obj.area_mask.shape == (256,)
        np.testing.assert_allclose(np.linalg.norm(obj.normals, axis=1), 1.0, atol=1e-9)
        assert obj.mass_kg > 0
        assert 0.01 < obj.mesh.extents.max() < 0.3, f"{name} is not in metres"


def test_known_extents_and_masses(data_root):
    mug = load_object(make_cfg("ycb", data_root), "025_mug", 64, 0)
    np.testing.assert_allclose(mug.mesh.extents, [0.1170, 0.0931, 0.0813], atol=5e-4)
    assert mug.mass_kg == pytest.approx(0.118)
    ape = load_object(make_cfg("linemod", data_root), "ape", 64, 0)  # file in mm: 75.87 x 77.60 x 91.77
    np.testing.assert_allclose(ape.mesh.extents, [0.07587, 0.07760, 0.09177], atol=5e-5)
    # LINEMOD mass = volume x density; the ape mesh is watertight with 177935 mm^3.
    assert ape.mass_kg == pytest.approx(177935.1e-9 * 700.0, rel=1e-3)
    for name, mass in [("021_bleach_cleanser", 1.131), ("035_power_drill", 0.895), ("011_banana", 0.066)]:
        assert load_object(make_cfg("ycb", data_root), name, 16, 0).mass_kg == pytest.approx(mass)


def test_points_lie_on_the_surface_with_face_normals(data_root):
    for ds, name in [("ycb", "025_mug"), ("ycb", "035_power_drill"), ("linemod", "driller")]:
        obj = load_object(make_cfg(ds, data_root), name, 300, seed=11)
        closest, distance, triangle = trimesh.proximity.closest_point(obj.mesh, obj.points)
        assert distance.max() < 1e-4
        agree = np.einsum("ij,ij->i", obj.normals, obj.mesh.face_normals[triangle]) > 0.99
        assert agree.mean() > 0.97  # a point on a shared edge may report a neighbouring face


def test_same_seed_same_cloud_other_seed_differs(data_root):
    cfg = make_cfg("ycb", data_root)
    a, b = load_object(cfg, "011_banana", 512, 7), load_object(cfg, "011_banana", 512, 7)
    c = load_object(cfg, "011_banana", 512, 8)
    np.testing.assert_array_equal(a.points, b.points)
    np.testing.assert_array_equal(a.normals, b.normals)
    np.testing.assert_array_equal(a.area_mask, b.area_mask)
    assert not np.allclose(a.points, c.points)


def test_global_numpy_random_state_is_untouched():
    np.random.seed(123)
    before = np.random.get_state()[1].copy()
    load_object(make_cfg("primitives"), "bottle", 128, 5)
    np.testing.assert_array_equal(np.random.get_state()[1], before)


def test_meshes_are_cached_and_handed_out_as_copies(data_root):
    cfg = make_cfg("ycb", data_root)
    first = load_object(cfg, "005_tomato_soup_can", 32, 0)
    hits = _load_mesh_cached.cache_info().hits
    first.mesh.apply_translation([1.0, 0.0, 0.0])  # a caller moving its copy must not touch the cache
    second = load_object(cfg, "005_tomato_soup_can", 32, 0)
    assert _load_mesh_cached.cache_info().hits == hits + 1
    assert second.mesh is not first.mesh
    assert second.mesh.bounds[0, 0] == pytest.approx(-0.0431, abs=2e-4)


def test_dictconfig_from_the_yaml_option_works(data_root):
    option = yaml.safe_load((REPO / "conf/dataset/linemod.yaml").read_text())
    option.pop("defaults")  # Hydra's defaults list; the schema itself is what it names
    cfg = OmegaConf.merge(OmegaConf.structured(DatasetConfig), option, {"root": str(data_root)})
    assert dataset_objects(cfg) == list(DATASETS["linemod"].default_objects)
    assert available_objects(cfg) == [
        "ape",
        "can",
        "cat",
        "driller",
        "duck",
        "eggbox",
        "glue",
        "holepuncher",
        "iron",
    ]
    assert load_object(cfg, "glue", 64, 1).mesh.extents.max() == pytest.approx(0.17282, abs=1e-4)


# --- catalogue, roots, layouts -------------------------------------------------------------------------


@pytest.mark.parametrize("name", sorted(DATASETS))
def test_conf_options_take_the_object_list_from_the_catalogue(name):
    conf = yaml.safe_load((REPO / f"conf/dataset/{name}.yaml").read_text())
    assert "objects" not in conf  # the default list is written once, in DATASETS
    assert conf["regions"] == f"{name}.yaml"
    assert set(DATASETS[name].default_objects) <= set(DATASETS[name].catalogue)


def test_ycb_catalogue_is_the_whole_object_set_with_published_masses():
    assert len(YCB_MASS_KG) == 78  # every YCB object that ships a google_16k model
    assert YCB_MASS_KG["010_potted_meat_can"] == 0.370 and YCB_MASS_KG["036_wood_block"] == 0.729
    assert YCB_MASS_KG["014_lemon"] == 0.029 and YCB_MASS_KG["077_rubiks_cube"] == 0.094
    assert all(0.0009 < m < 1.5 for m in YCB_MASS_KG.values())
    assert set(DATASETS["ycb"].default_objects) < set(YCB_MASS_KG)


def test_resolve_root_precedence(tmp_path, monkeypatch):
    monkeypatch.setenv("GRASPEXP_DATA", str(tmp_path / "env"))
    assert resolve_root(make_cfg("ycb", tmp_path / "cfg")) == tmp_path / "cfg"
    assert resolve_root(make_cfg("ycb")) == tmp_path / "env"
    monkeypatch.delenv("GRASPEXP_DATA")
    monkeypatch.chdir(tmp_path)
    assert resolve_root(make_cfg("ycb")) == Path("datasets")


def test_env_variable_root_serves_both_datasets(data_root, monkeypatch):
    monkeypatch.setenv("GRASPEXP_DATA", str(data_root))
    assert len(available_objects(make_cfg("ycb"))) == 9
    assert len(available_objects(make_cfg("linemod"))) == 9


def test_root_may_point_at_the_dataset_folder_itself(data_root):
    ycb = load_object(make_cfg("ycb", data_root / "ycb"), "025_mug", 16, 0)
    lm = load_object(make_cfg("linemod", data_root / "linemod"), "duck", 16, 0)
    assert ycb.mesh.extents.max() < 0.2 and lm.mesh.extents.max() < 0.2


def test_ycb_video_layout(tmp_path):
    write_cube_obj(tmp_path / "models" / "061_foam_brick" / "textured.obj")
    obj = load_object(make_cfg("ycb", tmp_path), "061_foam_brick", 64, 0)
    np.testing.assert_allclose(obj.mesh.extents, 0.05)
    assert obj.source.endswith("models/061_foam_brick/textured.obj") and obj.area_mask.all()


def test_dataset_objects_default_and_subset():
    assert dataset_objects(make_cfg("ycb"))[:2] == ["021_bleach_cleanser", "025_mug"]
    assert dataset_objects(make_cfg("primitives", objects=["mug", "can"])) == ["mug", "can"]
    with pytest.raises(DatasetError, match="valid names: can, box, bottle, mug, banana, block"):
        dataset_objects(make_cfg("primitives", objects=["teapot"]))


# --- errors ---------------------------------------------------------------------------------------------


def test_unknown_object_lists_valid_names():
    with pytest.raises(DatasetError, match=r"unknown object 'mugg'.*valid names: .*025_mug"):
        load_object(make_cfg("ycb", "/nonexistent"), "mugg", 16, 0)
    with pytest.raises(
        DatasetError, match=r"unknown dataset 'shapenet'.*linemod, primitives, vgn_packed, vgn_pile, ycb"
    ):
        load_object(DatasetConfig(name="shapenet", regions="ycb.yaml"), "x", 16, 0)


def test_missing_dataset_folder_names_path_and_download_command(tmp_path):
    root = tmp_path / "nowhere"
    with pytest.raises(DatasetError) as err:
        load_object(make_cfg("linemod", root), "ape", 16, 0)
    message = str(err.value)
    assert str(root.resolve()) in message
    assert f"python -m graspexp download dataset=linemod dataset.root={root}" in message


def test_missing_mesh_file_names_path_and_download_command(data_root):
    with pytest.raises(DatasetError) as err:  # benchvise is one of the 4 LINEMOD meshes not in the test data
        load_object(make_cfg("linemod", data_root), "benchvise", 16, 0)
    message = str(err.value)
    assert str((data_root / "linemod" / "models" / "obj_000002.ply").resolve()) in message
    assert "python -m graspexp download dataset=linemod dataset.root=" in message


@pytest.mark.parametrize(
    ("content", "reason"),
    [
        ("this is not an obj file\n\x00\x01garbage", "no faces|cannot be loaded"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\n", "no faces"),
        ("v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0.1 0.1 0\nf 1 2 3\nf 2 4 3\n", "zero volume"),
        ("v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 nan\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\n", "non-finite"),
    ],
)
def test_broken_mesh_raises_dataset_error(tmp_path, content, reason):
    path = tmp_path / "ycb" / "025_mug" / "google_16k" / "textured.obj"
    path.parent.mkdir(parents=True)
    path.write_text(content)
    with pytest.raises(DatasetError, match=f"broken mesh {path}.*({reason})"):
        load_object(make_cfg("ycb", tmp_path), "025_mug", 16, 0)


@pytest.mark.parametrize("bad", [0, -5, 2.5, True])
def test_bad_point_count_is_rejected(bad):
    with pytest.raises(DatasetError, match="n_points"):
        load_object(make_cfg("primitives"), "can", bad, 0)


# --- primitives -----------------------------------------------------------------------------------------


def test_primitives_match_their_specification():
    expected_extents = {
        "can": [0.066, 0.066, 0.100],
        "box": [0.050, 0.080, 0.120],
        "bottle": [0.060, 0.060, 0.190],
        "block": [0.085, 0.085, 0.200],
    }
    assert tuple(primitives.PRIMITIVES) == DATASETS["primitives"].catalogue
    for name, build in primitives.PRIMITIVES.items():
        mesh = build()
        assert mesh.is_watertight and mesh.volume > 0, name
        assert mesh.bounds[0, 2] == pytest.approx(0.0, abs=1e-12), name
        assert np.all(np.abs(mesh.bounds.mean(axis=0)[:2]) < 0.02), name
        if name in expected_extents:
            np.testing.assert_allclose(mesh.extents, expected_extents[name], atol=1e-9)
        np.testing.assert_array_equal(build().vertices, mesh.vertices)  # deterministic
    mug, banana = primitives.mug(), primitives.banana()
    assert mug.extents[2] == pytest.approx(0.095) and 0.10 < mug.extents[0] < 0.12  # handle on +x
    assert 0.17 < banana.extents[1] < 0.19 and banana.extents[2] == pytest.approx(0.035)


def test_primitive_objects_load_without_data(monkeypatch, tmp_path):
    monkeypatch.setenv("GRASPEXP_DATA", str(tmp_path / "empty"))
    cfg = make_cfg("primitives", density_kg_m3=500.0)
    assert available_objects(cfg) == list(DATASETS["primitives"].default_objects)
    block = load_object(cfg, "block", 128, 0)
    assert block.mass_kg == pytest.approx(0.085 * 0.085 * 0.2 * 500.0)
    assert block.source == ""


def test_any_catalogue_object_can_be_selected_not_only_the_default_list():
    from graspexp.datasets import select_objects

    ycb = compose_cfg("dataset=ycb").dataset
    assert "002_master_chef_can" not in ycb.objects and "002_master_chef_can" in dataset_spec("ycb").catalogue
    assert select_objects(ycb, ["002_master_chef_can", "025_mug"]) == ["002_master_chef_can", "025_mug"]
    with pytest.raises(DatasetError, match=r"unknown object\(s\) \['teapot'\] in dataset 'ycb'; valid: 002_"):
        select_objects(ycb, ["teapot"])


def test_splits_choose_the_objects_and_do_not_overlap() -> None:
    ycb = DATASETS["ycb"]
    assert ycb.splits["train"] == ycb.default_objects  # paper Table 1
    assert len(ycb.splits["test"]) == 14 and not set(ycb.splits["test"]) & set(ycb.splits["train"])
    assert set(ycb.splits["test"]) <= set(ycb.catalogue)
    cfg = compose_cfg("dataset=ycb", "dataset.split=test").dataset
    assert dataset_objects(cfg) == list(ycb.splits["test"])
    with pytest.raises(DatasetError, match="dataset 'linemod' has no 'train' split"):
        dataset_objects(compose_cfg("dataset=linemod", "dataset.split=train").dataset)
