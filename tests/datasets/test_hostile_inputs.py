"""Issue 39: object folders from other people. Each test is one class of the probe's failing cases; each
must end in one clear line (a refusal, or the object failing alone with its reason), fast, on tiny files."""

import time
from pathlib import Path

import pytest
import trimesh
from helpers.config import compose_cfg

from graspexp.core.userinput import UserInputError, check_object_name, load_user_yaml
from graspexp.datasets import ObjectError, catalogue, load_object

BOMB = "    - &a [x, x, x, x, x, x, x, x, x]\n" + "".join(
    f"    - &{c} [*{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}]\n"
    for p, c in zip("abcdefgh", "bcdefghi", strict=True)
)
"""A YAML alias graph ("billion laughs") as a list: 9^9 strings once expanded, a few hundred bytes on disk."""


def _folder(tmp_path: Path, **files: str) -> Path:
    trimesh.creation.box(extents=(0.05, 0.04, 0.06)).export(tmp_path / "box.stl")
    for name, text in files.items():
        (tmp_path / name).write_text(text)
    return tmp_path


def _load(root: Path, name: str = "box"):
    return load_object(compose_cfg("dataset=folder", f"dataset.root={root}").dataset, name, 200, 0)


def test_an_alias_bomb_in_a_sidecar_area_note_is_refused_at_once(tmp_path):
    root = _folder(tmp_path, **{"box.yaml": "area:\n  ops: [{keep_all: {}}]\n  note:\n" + BOMB})
    t0 = time.perf_counter()
    with pytest.raises(ObjectError, match=r"box\.yaml: YAML alias at line 5: aliases .* not accepted") as err:
        _load(root)
    assert time.perf_counter() - t0 < 5 and "\n" not in str(err.value)


def test_a_non_text_area_note_or_op_is_named_by_type_not_expanded(tmp_path):
    root = _folder(tmp_path, **{"box.yaml": "area:\n  ops: [{keep_all: {}}]\n  note: [1, 2]\n"})
    with pytest.raises(ObjectError, match="note must be text, got list"):
        _load(root)
    big = "[" + ", ".join(["123456789"] * 5000) + "]"
    (root / "box.yaml").write_text(f"area:\n  ops: [{big}]\n")
    with pytest.raises(ObjectError, match=r"got \[123456789, .*\.\.\.\]") as err:
        _load(root)
    assert len(str(err.value)) < 400
    with pytest.raises(UserInputError, match="more than"):
        load_user_yaml("a: " + "x" * (2 << 20), "f.yaml")


def test_a_zero_normal_halfspace_is_refused(tmp_path):
    spec = "area:\n  ops:\n    - keep_halfspace: {normal: [0, 0, 0], offset: -1}\n"
    root = _folder(tmp_path, **{"box.yaml": spec})
    with pytest.raises(ObjectError, match="keep_halfspace.normal must not be zero"):
        _load(root)


@pytest.mark.parametrize("stem", [".", "..", ".quarantine", "a\nb", "x\\y"])
def test_a_file_whose_stem_is_not_an_object_name_is_no_object(tmp_path, stem, caplog):
    root = _folder(tmp_path)
    trimesh.creation.box(extents=(0.05, 0.04, 0.06)).export(tmp_path / "tmp.stl")
    (tmp_path / "tmp.stl").rename(tmp_path / f"{stem}.stl")
    assert catalogue(compose_cfg("dataset=folder", f"dataset.root={root}").dataset) == ("box",)
    assert "not an object" in caplog.text
    with pytest.raises(UserInputError, match="not a valid object name"):
        check_object_name(stem)


def test_a_dangling_symlinked_mesh_fails_alone_saying_so(tmp_path):
    root = _folder(tmp_path)
    (root / "gone.obj").symlink_to(root / "missing.obj")
    assert catalogue(compose_cfg("dataset=folder", f"dataset.root={root}").dataset) == ("box", "gone")
    with pytest.raises(
        ObjectError, match=r"gone\.obj is a symbolic link to .*missing\.obj, which does not exist"
    ):
        _load(root, "gone")


URDF = """<robot name="r"><link name="l">
  <inertial><mass value="{mass}"/></inertial>
  <collision><geometry><mesh filename="{mesh}"/></geometry></collision>
</link></robot>"""


@pytest.mark.parametrize(
    "mass, mesh, match",
    [
        ("1e6", "box.stl", r"mass value=1e\+06> is invalid: expected"),
        ("0.1", "../outside/box.stl", "leaves the URDF's folder"),
        ("0.1", "/etc/box.stl", "leaves the URDF's folder"),
    ],
)
def test_urdf_masses_are_bounded_and_its_meshes_stay_in_the_folder(tmp_path, mass, mesh, match):
    (tmp_path / "outside").mkdir()
    trimesh.creation.box(extents=(0.05, 0.04, 0.06)).export(tmp_path / "outside" / "box.stl")
    root = tmp_path / "objects"
    root.mkdir()
    _folder(root, **{"thing.urdf": URDF.format(mass=mass, mesh=mesh)})
    with pytest.raises(ObjectError, match=match):
        _load(root, "thing")


@pytest.mark.parametrize(
    "ply, match",
    [("../area.ply", "leaves its folder"), ("/tmp/area.ply", "leaves its folder"), ("nope.ply", "not found")],
)
def test_a_meshlab_area_error_fails_its_object_alone(tmp_path, ply, match):
    root = tmp_path / "objects"
    root.mkdir()
    trimesh.PointCloud([[0, 0, 0], [0.01, 0, 0]]).export(tmp_path / "area.ply")
    _folder(root, **{"box.yaml": f"area:\n  meshlab_ply: {ply}\n"})
    with pytest.raises(ObjectError, match=match):
        _load(root)


def test_a_mesh_above_the_face_cap_fails_alone_before_it_is_read(tmp_path):
    root = _folder(tmp_path)  # a 12-face box under a cap of 10 (a 2.6M-face scan under the default)
    cfg = compose_cfg("dataset=folder", f"dataset.root={root}", "dataset.max_faces=10").dataset
    with pytest.raises(ObjectError, match=r"has 12 faces, more than dataset.max_faces=10: decimate it first"):
        load_object(cfg, "box", 200, 0)
