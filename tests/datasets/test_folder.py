"""The folder dataset: your own meshes and URDFs, sidecars, units safety, one-line errors."""

from pathlib import Path

import numpy as np
import pytest
import trimesh
from helpers.config import compose_cfg
from helpers.objects import make_object_folder

from graspexp.datasets import DatasetError, ObjectError, catalogue, load_object, select_objects


@pytest.fixture(scope="module")
def folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return make_object_folder(tmp_path_factory.mktemp("objects"))


def folder_cfg(root: Path, *overrides: str):
    return compose_cfg("dataset=folder", f"dataset.root={root}", *overrides).dataset


def load(root: Path, name: str, *overrides: str):
    return load_object(folder_cfg(root, *overrides), name, 2000, 0)


def test_every_mesh_file_and_urdf_is_an_object_named_by_its_stem(folder):
    # bracket_link.stl is the URDF's mesh, not a seventh object; sidecars are not objects
    assert catalogue(folder_cfg(folder)) == ("arc", "ball", "box", "bracket", "can", "cone")
    assert select_objects(folder_cfg(folder), ["box"]) == ["box"]
    assert select_objects(folder_cfg(folder), []) == ["arc", "ball", "box", "bracket", "can", "cone"]


@pytest.mark.parametrize(
    "name, extents_m",
    [
        ("can", (0.06, 0.06, 0.1)),  # OBJ in metres, no sidecar
        ("arc", (0.096, 0.096, 0.032)),  # OBJ in cm (sidecar units: cm)
        ("box", (0.06, 0.04, 0.09)),  # PLY in mm (sidecar units: mm)
        ("cone", (0.07, 0.07, 0.09)),  # STL in metres
        ("ball", (0.06, 0.06, 0.06)),  # GLB in metres
        ("bracket", (0.07, 0.07, 0.03)),  # URDF: STL in mm, <mesh scale="0.001 ...">
    ],
)
def test_each_format_and_unit_loads_in_metres(folder, name, extents_m):
    model = load(folder, name)
    np.testing.assert_allclose(model.mesh.extents, extents_m, atol=1.5e-3)
    assert model.mesh.is_watertight and model.source


def test_urdf_origin_places_the_mesh_in_the_link_frame(folder):
    bounds = load(folder, "bracket").mesh.bounds
    np.testing.assert_allclose(bounds, [[-0.035, -0.035, 0.0], [0.035, 0.035, 0.03]], atol=1e-9)


def test_masses_come_from_sidecar_urdf_or_density(folder):
    assert load(folder, "box").mass_kg == pytest.approx(0.2)  # sidecar mass_kg
    assert load(folder, "bracket").mass_kg == pytest.approx(0.15)  # URDF <inertial>
    cone = load(folder, "cone")
    assert cone.mass_kg == pytest.approx(cone.mesh.volume * 900)  # sidecar density
    can = load(folder, "can", "dataset.density_kg_m3=1000")
    assert can.mass_kg == pytest.approx(can.mesh.volume * 1000)  # the dataset's density


def test_sidecar_friction_and_area(folder):
    assert load(folder, "cone").friction == pytest.approx(0.8)
    assert load(folder, "can").friction is None
    arc = load(folder, "arc")
    assert 0.2 < arc.area_mask.mean() < 0.9  # the sidecar's sphere around the middle of the arc
    assert load(folder, "ball").area_mask.all()  # no sidecar: the whole surface


def test_every_assumption_is_stated(folder):
    assert load(folder, "can").notes == (
        "units: m (dataset.units)",
        "mass: volume x dataset.density_kg_m3",
        "area: whole surface (no area given)",
    )
    assert "units: cm (arc.yaml)" in load(folder, "arc").notes
    assert "mass: 0.15 kg (URDF <inertial>)" in load(folder, "bracket").notes
    assert "friction: 0.8 (cone.yaml)" in load(folder, "cone").notes


def test_a_mesh_in_other_units_is_refused_naming_file_extents_and_the_units_key(tmp_path):
    trimesh.creation.box(extents=(120.0, 40.0, 60.0)).export(tmp_path / "part.stl")  # meant as mm
    with pytest.raises(ObjectError) as err:
        load(tmp_path, "part")
    msg = str(err.value)
    assert str(tmp_path / "part.stl") in msg and "120" in msg and "units:" in msg and "in mm (0.12 m)" in msg
    assert "\n" not in msg
    np.testing.assert_allclose(load(tmp_path, "part", "dataset.units=mm").mesh.extents, (0.12, 0.04, 0.06))
    (tmp_path / "part.yaml").write_text("units: 0.001\n")
    np.testing.assert_allclose(load(tmp_path, "part").mesh.extents, (0.12, 0.04, 0.06))


@pytest.mark.parametrize(
    "sidecar, match",
    [
        ("unit: mm\n", r"unknown key\(s\) \['unit'\]; valid keys: units, mass_kg"),
        ("mass_kg: 0.1\ndensity_kg_m3: 500\n", "give mass_kg or density_kg_m3, not both"),
        ("units: inch\n", "units='inch' is invalid: expected m, cm, mm or a positive number"),
        ("mass_kg: '0.1'\n", r"mass_kg='0.1' is invalid: expected a number in \(0, 100\]"),
        ("friction: -1\n", "friction=-1 is invalid"),
        ("area:\n  relative: 'false'\n  ops: [keep_all: {}]\n", "relative must be true or false"),
        ("- 1\n", "must be a mapping"),
    ],
)
def test_a_bad_sidecar_is_one_line_naming_file_and_key(tmp_path, sidecar, match):
    trimesh.creation.box(extents=(0.05, 0.05, 0.05)).export(tmp_path / "cube.obj")
    (tmp_path / "cube.yaml").write_text(sidecar)
    with pytest.raises(ObjectError, match=match) as err:
        load(tmp_path, "cube")
    assert "cube.yaml" in str(err.value) and "\n" not in str(err.value)


def test_urdf_primitives_and_bad_urdfs(tmp_path):
    (tmp_path / "peg.urdf").write_text(
        '<robot name="peg"><link name="peg"><collision><origin xyz="0 0 0.04"/>'
        '<geometry><cylinder radius="0.01" length="0.08"/></geometry></collision>'
        '<collision><origin xyz="0 0 0.0075"/><geometry><box size="0.04 0.04 0.015"/></geometry></collision>'
        "</link></robot>"
    )
    peg = load(tmp_path, "peg")
    np.testing.assert_allclose(peg.mesh.bounds, [[-0.02, -0.02, 0.0], [0.02, 0.02, 0.08]], atol=1e-9)
    assert "mass: volume x dataset.density_kg_m3" in peg.notes
    (tmp_path / "arm.urdf").write_text(
        '<robot name="arm"><link name="a"><collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>'
        '</link><link name="b"/><joint name="j" type="fixed"><parent link="a"/><child link="b"/></joint></robot>'
    )
    with pytest.raises(ObjectError, match="one link that has <collision> geometry and no joints"):
        load(tmp_path, "arm")
    (tmp_path / "lost.urdf").write_text(
        '<robot name="lost"><link name="l"><collision><geometry><mesh filename="nowhere.stl"/>'
        "</geometry></collision></link></robot>"
    )
    with pytest.raises(ObjectError, match="mesh file .*nowhere.stl.* not found"):
        load(tmp_path, "lost")


def test_folder_errors_are_one_line(tmp_path):
    with pytest.raises(
        DatasetError, match="dataset=folder needs the folder of your meshes: dataset.root=DIR"
    ):
        load_object(compose_cfg("dataset=folder").dataset, "x", 16, 0)
    with pytest.raises(DatasetError, match="does not exist"):
        catalogue(folder_cfg(tmp_path / "nope"))
    with pytest.raises(DatasetError, match="holds no mesh file"):
        catalogue(folder_cfg(tmp_path))
    trimesh.creation.box(extents=(0.05, 0.05, 0.05)).export(tmp_path / "cube.obj")
    trimesh.creation.box(extents=(0.05, 0.05, 0.05)).export(tmp_path / "cube.stl")
    with pytest.raises(DatasetError, match="two files .* give object 'cube': cube.obj and cube.stl"):
        catalogue(folder_cfg(tmp_path))


def test_a_catalogued_name_is_refused_for_another_layout(folder):
    with pytest.raises(DatasetError, match="dataset.name='ycb' is the catalogued ycb set"):
        catalogue(folder_cfg(folder, "dataset.name=ycb"))
