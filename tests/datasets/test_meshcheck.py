"""Damaged meshes are refused with one line naming the file: cut OBJ/PLY files (against their headers),
extents that disagree with BOP's models_info.json, absurd sizes, closed meshes with impossible volumes."""

import json
import shutil
from pathlib import Path

import numpy as np
import pytest
import trimesh

from graspexp.config import DatasetConfig
from graspexp.datasets import DatasetError, load_object


def _cfg(name: str, root: Path) -> DatasetConfig:
    return DatasetConfig(name=name, root=str(root), regions=f"{name}.yaml")


def _ycb_mug(root: Path, data: bytes) -> Path:
    path = root / "ycb" / "025_mug" / "google_16k" / "textured.obj"
    path.parent.mkdir(parents=True)
    path.write_bytes(data)
    return path


def test_obj_cut_in_the_middle_is_refused(data_root: Path, tmp_path: Path) -> None:
    lines = (data_root / "ycb" / "025_mug" / "google_16k" / "textured.obj").read_bytes().split(b"\n")
    faces = [i for i, ln in enumerate(lines) if ln.startswith(b"f ")]
    path = _ycb_mug(tmp_path, b"\n".join(lines[: faces[3848]]))  # all vertices, 3,848 of 16,384 faces
    with pytest.raises(DatasetError) as err:
        load_object(_cfg("ycb", tmp_path), "025_mug", 64, 0)
    assert str(err.value) == (
        f"broken mesh {path.resolve()}: its header declares 16384 faces, the file holds 3848 "
        "(a cut or damaged file?); download it again"
    )


def test_obj_cut_to_a_few_hundred_bytes_is_the_same_clear_error(data_root: Path, tmp_path: Path) -> None:
    data = (data_root / "ycb" / "025_mug" / "google_16k" / "textured.obj").read_bytes()[:400]
    path = _ycb_mug(tmp_path, data)
    with pytest.raises(
        DatasetError, match=rf"^broken mesh {path.resolve()}: its header declares 8188 vertices"
    ):
        load_object(_cfg("ycb", tmp_path), "025_mug", 64, 0)


def _linemod_ape(root: Path, data: bytes) -> Path:
    path = root / "linemod" / "models" / "obj_000001.ply"
    path.parent.mkdir(parents=True)
    path.write_bytes(data)
    return path


def test_ascii_ply_cut_short_is_refused(data_root: Path, tmp_path: Path) -> None:
    data = (data_root / "linemod" / "models" / "obj_000001.ply").read_bytes()
    path = _linemod_ape(tmp_path, data[: len(data) // 2])
    with pytest.raises(
        DatasetError, match=rf"^broken mesh {path.resolve()}: its header declares 5841 vertex, 11678"
    ):
        load_object(_cfg("linemod", tmp_path), "ape", 64, 0)


def test_binary_ply_cut_short_is_refused(tmp_path: Path) -> None:
    data = trimesh.creation.icosphere(subdivisions=3, radius=40.0).export(file_type="ply", encoding="binary")
    path = _linemod_ape(tmp_path, data[:-200])
    with pytest.raises(
        DatasetError, match=rf"^broken mesh {path.resolve()}: its header declares 642 vertex, 1280 face"
    ):
        load_object(_cfg("linemod", tmp_path), "ape", 64, 0)
    path.write_bytes(data)
    assert load_object(_cfg("linemod", tmp_path), "ape", 64, 0).mesh.extents.max() == pytest.approx(
        0.08, rel=0.01
    )


def test_bop_model_must_match_its_published_size(data_root: Path, tmp_path: Path) -> None:
    models = tmp_path / "linemod" / "models"
    models.mkdir(parents=True)
    shutil.copy(data_root / "linemod" / "models" / "obj_000001.ply", models)
    shutil.copy(data_root / "linemod" / "models" / "models_info.json", models)
    assert load_object(_cfg("linemod", tmp_path), "ape", 64, 0).name == "ape"
    info = json.loads((models / "models_info.json").read_text())
    info["1"]["size_z"] *= 2  # a model of another object, or another scale
    (models / "models_info.json").write_text(json.dumps(info))
    with pytest.raises(DatasetError, match=r"extents \[75.87, 77.6, 91.77\] differ from the published size"):
        load_object(_cfg("linemod", tmp_path), "ape", 64, 0)


def test_absurd_size_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "models" / "061_foam_brick" / "textured.obj"
    path.parent.mkdir(parents=True)
    trimesh.creation.box(extents=[2.0, 0.05, 0.05]).export(path)  # 2 m: millimetres read as metres?
    with pytest.raises(DatasetError, match=r"largest extent 2 m is outside \[0.005, 1.0\] m \(wrong units"):
        load_object(_cfg("ycb", tmp_path), "061_foam_brick", 64, 0)


def test_closed_mesh_enclosing_more_than_its_hull_is_refused(tmp_path: Path) -> None:
    a = trimesh.creation.box(extents=[0.05] * 3)
    b = a.copy()
    b.apply_translation([0.001, 0.0, 0.0])  # two overlapping closed shells: twice the volume in one hull
    path = tmp_path / "models" / "061_foam_brick" / "textured.obj"
    path.parent.mkdir(parents=True)
    trimesh.util.concatenate([a, b]).export(path)
    with pytest.raises(DatasetError, match=r"it is closed but encloses 0.00025 m\^3 against a convex hull"):
        load_object(_cfg("ycb", tmp_path), "061_foam_brick", 64, 0)
    assert np.isclose(a.volume, 0.05**3)


def test_an_ascii_ply_with_more_rows_than_declared_is_refused(tmp_path):
    path = tmp_path / "cube.ply"
    text = trimesh.creation.box(extents=(0.05, 0.05, 0.05)).export(file_type="ply", encoding="ascii")
    path.write_bytes(text + b"3 0 1 2\n")  # a face the header does not declare
    cfg = DatasetConfig(name="cube", layout="folder", root=str(tmp_path))
    with pytest.raises(
        DatasetError, match=r"its header declares 8 vertex, 12 face \(20 rows\), the file holds 21"
    ):
        load_object(cfg, "cube", 16, 0)
