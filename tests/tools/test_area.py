"""The grasping-area tool (python -m graspexp.area): its figure, printed facts, sidecar and errors."""

import re
import subprocess
import sys
from pathlib import Path

import matplotlib.image
import numpy as np
import pytest
import trimesh
import yaml
from helpers.config import compose_cfg, shared_data_root

from graspexp.datasets import ObjectModel, job_object
from graspexp.datasets.folder import read_sidecar
from graspexp.datasets.primitives import PRIMITIVES
from graspexp.datasets.regions import area_mask, parse_entry
from graspexp.report.area_view import MAX_FACES, render_mesh
from graspexp.tools.area import main

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def _run(capsys, *args: str) -> dict[str, str]:
    """Run the tool in-process; its printed facts by their label (``label: value``)."""
    assert main(list(args)) == 0
    return dict(line.split(": ", 1) for line in capsys.readouterr().out.splitlines())


def _extents(text: str) -> np.ndarray:
    """The ``X x Y x Z mm`` sizes at the start of a printed extents line, mm."""
    return np.array([float(v) for v in re.match(r"([-\d.]+) x ([-\d.]+) x ([-\d.]+) mm", text).groups()])


def _check_facts(facts: dict[str, str], model) -> None:
    share = facts["area share of the samples"]
    assert share == f"{model.area_mask.mean():.2%} (area_mask.mean() = {model.area_mask.mean():.4f})"
    assert facts["points"] == f"{len(model.points)} surface samples, {int(model.area_mask.sum())} in the area"
    np.testing.assert_allclose(
        _extents(facts["object extents (mesh bounds, x y z)"]), model.mesh.extents * 1000, atol=0.051
    )
    np.testing.assert_allclose(
        _extents(facts["area extents (its samples, x y z)"]),
        np.ptp(model.area_points, axis=0) * 1000,
        atol=0.051,
    )


def _check_png(path: Path) -> None:
    assert path.read_bytes()[:8] == PNG_SIGNATURE
    image = matplotlib.image.imread(path)[..., :3]
    assert image.shape[0] >= 500 and image.shape[1] >= 500
    red = (image[..., 0] > 0.5) & (image[..., 1] < 0.3) & (image[..., 2] < 0.3)
    grey = (np.ptp(image, axis=-1) < 0.02) & (image[..., 0] > 0.3) & (image[..., 0] < 0.9)
    assert red.mean() > 0.005 and grey.mean() > 0.02  # the area and the rest of the mesh are both drawn


@pytest.mark.parametrize("name", ["mug", "can"])
def test_primitive_figure_and_facts(name, tmp_path, capsys):
    facts = _run(capsys, "dataset=primitives", "--object", name, "--out", str(tmp_path))
    png = tmp_path / f"area_primitives_{name}.png"
    assert facts["figure"].startswith(str(png))
    _check_png(png)
    _check_facts(facts, job_object(compose_cfg("dataset=primitives"), name))


def test_a_fine_mesh_is_decimated_and_its_faces_take_the_area_of_their_samples():
    sphere = trimesh.creation.icosphere(subdivisions=6, radius=0.05)  # 81920 faces
    points, faces = trimesh.sample.sample_surface(sphere, 2048, seed=0)
    model = ObjectModel("ball", "test", sphere, points, sphere.face_normals[faces], points[:, 2] > 0.02, 0.1)
    mesh, in_area = render_mesh(model)
    assert len(mesh.faces) < 1.1 * MAX_FACES  # decimated, then a few long faces split
    cap_share = (0.05 - 0.02) / (2 * 0.05)  # a spherical cap's share of the sphere's area
    assert mesh.area_faces[in_area].sum() / mesh.area == pytest.approx(cap_share, abs=0.02)
    assert np.all(mesh.triangles_center[in_area, 2] > 0.015)


def test_sidecar_template_parses_and_is_not_overwritten(tmp_path, capsys):
    sidecar = tmp_path / "side" / "mug.yaml"
    args = ["dataset=primitives", "--object", "mug", "--out", str(tmp_path), "--write-sidecar", str(sidecar)]
    assert _run(capsys, *args)["sidecar"] == str(sidecar)
    text = sidecar.read_text()
    data = yaml.safe_load(text)
    assert read_sidecar(sidecar) == data
    model = job_object(compose_cfg("dataset=primitives"), "mug")
    assert set(data) == {"units", "mass_kg", "area"} and "# friction:" in text and "# density_kg_m3:" in text
    assert data["units"] == "m"
    assert data["mass_kg"] == pytest.approx(model.mass_kg, rel=1e-3)
    spec = parse_entry("mug", data["area"], sidecar)
    mask = area_mask(spec, model.points, model.mesh.bounds)
    z_rel = (model.points[:, 2] - model.mesh.bounds[0, 2]) / model.mesh.extents[2]
    np.testing.assert_array_equal(mask, (z_rel >= 0.25) & (z_rel <= 0.75))

    with pytest.raises(SystemExit) as done:
        main(args)
    assert done.value.code == 2
    assert capsys.readouterr().err == f"graspexp area: error: {sidecar} exists; add --force to overwrite it\n"
    assert sidecar.read_text() == text
    sidecar.write_text("edited\n")
    _run(capsys, *args, "--force")
    assert sidecar.read_text() == text


def test_sidecar_round_trip_on_a_folder_of_millimetre_meshes(tmp_path, capsys):
    """The folder dataset's workflow: author a sidecar for a mesh in mm, then load the object by it."""
    mesh = PRIMITIVES["mug"]()
    mesh.apply_scale(1000.0)
    mesh.export(tmp_path / "mug.obj")
    sidecar = tmp_path / "mug.yaml"
    folder = ["dataset=folder", f"dataset.root={tmp_path}"]
    args = ["dataset.units=mm", "--object", "mug", "--out", str(tmp_path), "--write-sidecar", str(sidecar)]
    before = _run(capsys, *folder, *args)
    data = read_sidecar(sidecar)
    assert data["units"] == "mm" and "friction" not in data
    model = job_object(compose_cfg(*folder), "mug")  # dataset.units is m: the sidecar's units apply
    np.testing.assert_allclose(model.mesh.extents, mesh.extents / 1000.0, rtol=1e-9)
    assert f"{model.mass_kg:.4g} kg" == before["mass"]
    z_rel = (model.points[:, 2] - model.mesh.bounds[0, 2]) / model.mesh.extents[2]
    np.testing.assert_array_equal(model.area_mask, (z_rel >= 0.25) & (z_rel <= 0.75))


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["dataset=primitives", "--object", "teapot"], "unknown object 'teapot' in dataset 'primitives'"),
        (["dataset=nope", "--object", "mug"], "Could not find 'dataset/nope'"),
    ],
)
def test_errors_are_one_line(args, message, capsys):
    with pytest.raises(SystemExit) as done:
        main(args)
    assert done.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith("graspexp area: error: ") and message in err and err.count("\n") == 1


@pytest.mark.slow
def test_module_alias_exits_2_without_a_traceback(tmp_path):
    proc = subprocess.run(
        [sys.executable, "-m", "graspexp.area", "dataset=primitives", "--object", "teapot"],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert proc.returncode == 2 and proc.stdout == ""
    assert (
        proc.stderr.startswith("graspexp area: error: unknown object 'teapot'")
        and proc.stderr.count("\n") == 1
    )


def test_real_ycb_mug(tmp_path, capsys):
    root = shared_data_root()
    if not (root / "ycb" / "025_mug").is_dir():
        pytest.skip(f"no YCB 025_mug under {root}: set GRASPEXP_DATA")
    overrides = ["dataset=ycb", f"dataset.root={root}"]
    facts = _run(capsys, *overrides, "--object", "025_mug", "--out", str(tmp_path))
    _check_png(tmp_path / "area_ycb_025_mug.png")
    model = job_object(compose_cfg(*overrides), "025_mug")
    assert len(model.mesh.faces) > 10_000  # the google_16k scan, not a coarse stand-in
    _check_facts(facts, model)
