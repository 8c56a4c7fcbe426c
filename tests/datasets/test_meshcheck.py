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


def test_obj_cut_together_with_its_header_is_refused(data_root: Path, tmp_path: Path) -> None:
    """A google_16k file that lost its ``# Faces:`` header still has its dataset's published face count."""
    lines = (data_root / "ycb" / "025_mug" / "google_16k" / "textured.obj").read_bytes().split(b"\n")
    faces = [i for i, ln in enumerate(lines) if ln.startswith(b"f ")]
    kept = [ln for ln in lines[: faces[6099]] if not ln.startswith(b"#")]  # 6,099 of 16,384 faces, no header
    path = _ycb_mug(tmp_path, b"\n".join(kept))
    with pytest.raises(DatasetError) as err:
        load_object(_cfg("ycb", tmp_path), "025_mug", 64, 0)
    assert str(err.value) == (
        f"broken mesh {path.resolve()}: it holds 6099 faces, its dataset's models have 16384 "
        "(a cut or damaged file?); download it again"
    )


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


def _folder_ply(root: Path, data: bytes) -> tuple[Path, DatasetConfig]:
    path = root / "ball.ply"
    path.write_bytes(data)
    return path, DatasetConfig(name="mine", layout="folder", root=str(root), units="mm")


@pytest.mark.parametrize(
    "cut, held", [(-200, "the body ends early"), (+13, "the file holds 13 bytes more than those")]
)
def test_binary_ply_with_other_than_its_declared_bytes_is_refused(
    tmp_path: Path, cut: int, held: str
) -> None:
    data = trimesh.creation.icosphere(subdivisions=3, radius=40.0).export(file_type="ply", encoding="binary")
    body = data[:cut] if cut < 0 else data + bytes([3]) + bytes(12)  # cut short / one undeclared triangle
    path, cfg = _folder_ply(tmp_path, body)
    with pytest.raises(
        DatasetError,
        match=rf"^broken mesh {path.resolve()}: its header declares 642 vertex, 1280 face; {held}",
    ):
        load_object(cfg, "ball", 64, 0)
    path.write_bytes(data)
    assert load_object(cfg, "ball", 64, 0).mesh.extents.max() == pytest.approx(0.08, rel=0.01)


def test_binary_ply_of_quads_is_counted_by_its_length_fields(tmp_path: Path) -> None:
    vertices = np.array([[x, y, z] for x in (0, 50) for y in (0, 50) for z in (0, 50)], dtype="<f4")
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    header = (
        "ply\nformat binary_little_endian 1.0\nelement vertex 8\nproperty float x\nproperty float y\n"
        "property float z\nelement face 6\nproperty list uchar int vertex_indices\nend_header\n"
    )
    body = vertices.tobytes() + b"".join(bytes([4]) + np.array(q, "<i4").tobytes() for q in quads)
    path, cfg = _folder_ply(tmp_path, header.encode() + body)
    assert load_object(cfg, "ball", 64, 0).mesh.extents.tolist() == pytest.approx([0.05] * 3)
    path.write_bytes(header.encode() + body[:-4])  # 96 + 6 x 17 bytes declared, 4 fewer held
    with pytest.raises(
        DatasetError, match=r"declares 8 vertex, 6 face; the body ends early, after 194 bytes"
    ):
        load_object(cfg, "ball", 64, 0)


def test_bop_model_must_match_its_published_size(data_root: Path, tmp_path: Path) -> None:
    models = tmp_path / "linemod" / "models"
    models.mkdir(parents=True)
    shutil.copy(data_root / "linemod" / "models" / "obj_000001.ply", models)
    shutil.copy(data_root / "linemod" / "models" / "models_info.json", models)
    assert load_object(_cfg("linemod", tmp_path), "ape", 64, 0).name == "ape"
    info = json.loads((models / "models_info.json").read_text())
    info["1"]["size_z"] *= 2  # a model of another object, or another scale
    (models / "models_info.json").write_text(json.dumps(info))
    with pytest.raises(
        DatasetError, match=r"extents \[75.87, 77.6, 91.77\] mm differ from the published size"
    ):
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


def test_a_google_16k_model_at_another_scale_is_refused(data_root: Path, tmp_path: Path) -> None:
    path = tmp_path / "ycb" / "011_banana" / "google_16k" / "textured.obj"
    path.parent.mkdir(parents=True)
    text = (data_root / "ycb" / "011_banana" / "google_16k" / "textured.obj").read_text()
    lines = [
        "v " + " ".join(f"{0.1 * float(x):.7g}" for x in ln.split()[1:4]) if ln.startswith("v ") else ln
        for ln in text.splitlines()
    ]
    path.write_text("\n".join(lines) + "\n")  # a 1.8 cm banana: inside [5 mm, 1 m], the published mass
    with pytest.raises(DatasetError, match=r"mm differ from the published size \[108.9, 178.4, 36.7\] mm"):
        load_object(_cfg("ycb", tmp_path), "011_banana", 64, 0)
