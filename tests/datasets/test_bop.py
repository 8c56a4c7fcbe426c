"""Any BOP dataset: models/obj_NNNNNN.ply in mm + models_info.json, human names where the set has them."""

import json
from pathlib import Path

import numpy as np
import pytest
import trimesh
from helpers.config import compose_cfg

from graspexp.datasets import DatasetError, ObjectError, catalogue, load_object

MODELS = {  # id -> (mesh in mm, symmetries)
    1: (lambda: trimesh.creation.box(extents=(50.0, 30.0, 80.0)), {"symmetries_discrete": [[
        -1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1]]}),
    2: (lambda: trimesh.creation.cylinder(radius=25.0, height=90.0, sections=48), {
        "symmetries_continuous": [{"axis": [0, 0, 1], "offset": [0, 0, 0]}]}),
    4: (lambda: trimesh.creation.icosphere(subdivisions=3, radius=30.0), {}),
}  # fmt: skip


def make_bop_set(folder: Path) -> Path:
    """A BOP-layout set written here: 3 models (ids 1, 2, 4) with their models_info.json."""
    models = folder / "models"
    models.mkdir(parents=True)
    info = {}
    for model_id, (make, symmetries) in MODELS.items():
        mesh = make()
        mesh.export(models / f"obj_{model_id:06d}.ply")
        lo, size = mesh.bounds[0], mesh.extents
        info[str(model_id)] = {
            "diameter": float(np.linalg.norm(size)),
            **{f"min_{a}": float(v) for a, v in zip("xyz", lo, strict=True)},
            **{f"size_{a}": float(v) for a, v in zip("xyz", size, strict=True)},
            **symmetries,
        }
    (models / "models_info.json").write_text(json.dumps(info))
    return folder


def bop_cfg(root: Path, *overrides: str):
    return compose_cfg("dataset=bop", f"dataset.root={root}", *overrides).dataset


def test_names_units_and_extents_follow_models_info(tmp_path):
    root = make_bop_set(tmp_path / "tless")
    cfg = bop_cfg(root)
    assert catalogue(cfg) == ("obj_000001", "obj_000002", "obj_000004")  # tless defines no human names
    info = json.loads((root / "models" / "models_info.json").read_text())
    for name, model_id in zip(catalogue(cfg), ("1", "2", "4"), strict=True):
        model = load_object(cfg, name, 500, 0)
        published = [info[model_id][f"size_{a}"] / 1000 for a in "xyz"]
        np.testing.assert_allclose(model.mesh.extents, published, atol=1e-9)  # mm -> m
        assert model.mass_kg == pytest.approx(model.mesh.volume * 700)
        assert "units: mm (BOP)" in model.notes
    assert (
        "symmetries (models_info.json): continuous about (0, 0, 1)"
        in load_object(cfg, "obj_000002", 16, 0).notes
    )
    assert "symmetries (models_info.json): 1 discrete" in load_object(cfg, "obj_000001", 16, 0).notes


def test_a_set_with_human_names_uses_them(tmp_path):
    root = make_bop_set(tmp_path / "data" / "ycbv")
    assert catalogue(bop_cfg(root)) == ("002_master_chef_can", "003_cracker_box", "005_tomato_soup_can")
    # the common data root and the set's name work as well
    assert catalogue(bop_cfg(root.parent, "dataset.bop_set=ycbv"))[0] == "002_master_chef_can"
    assert catalogue(bop_cfg(root, "dataset.bop_set=lm")) == ("ape", "benchvise", "cam")


def test_a_model_that_disagrees_with_models_info_is_refused(tmp_path):
    root = make_bop_set(tmp_path / "hb")
    trimesh.creation.box(extents=(30.0, 18.0, 48.0)).export(root / "models" / "obj_000001.ply")  # x0.6
    with pytest.raises(ObjectError, match="differ from the published size .* in .*models_info.json"):
        load_object(bop_cfg(root), "obj_000001", 16, 0)


def test_a_linemod_model_without_models_info_is_checked_against_the_published_size(tmp_path):
    """LM-O ships models_info.json with 8 of 15 entries, a user's copy may lack it: the sizes graspexp carries
    for the 13 LINEMOD models still catch a model at the wrong scale."""
    models = tmp_path / "linemod" / "models"
    models.mkdir(parents=True)
    ape = trimesh.creation.box(extents=(75.8686, 77.5992, 91.769))  # ape's published size, mm
    ape.export(models / "obj_000001.ply")
    cfg = compose_cfg("dataset=linemod", f"dataset.root={tmp_path}").dataset
    notes = load_object(cfg, "ape", 16, 0).notes
    assert any(n.startswith("size checked against the linemod set's models_info.json") for n in notes)
    ape.apply_scale(0.6)
    ape.export(models / "obj_000001.ply")
    with pytest.raises(
        ObjectError, match=r"obj_000001.ply: .*differ from the published size \[75.87, 77.6, 91.77\]"
    ):
        load_object(cfg, "ape", 16, 0)
    bop = bop_cfg(tmp_path / "linemod", "dataset.bop_set=lmo")  # any lm/lmo copy, not just the catalogued one
    with pytest.raises(ObjectError, match="carried by graspexp"):
        load_object(bop, "ape", 16, 0)


@pytest.mark.parametrize(
    "entry, match",
    [
        ({"size_x": "50"}, "model 1: size_x must be a positive number"),
        ({"size_y": -1.0}, "model 1: size_y must be a positive number"),
        ({"symmetries_continuous": [{"axis": [0, 1]}]}, "model 1: symmetries_continuous must be"),
        ({"symmetries_discrete": [[1, 0, 0]]}, "model 1: symmetries_discrete must be"),
    ],
)
def test_models_info_is_validated_like_a_config(tmp_path, entry, match):
    root = make_bop_set(tmp_path / "icbin")
    path = root / "models" / "models_info.json"
    info = json.loads(path.read_text())
    info["1"].update(entry)
    path.write_text(json.dumps(info))
    with pytest.raises(DatasetError, match=match):
        catalogue(bop_cfg(root))


def test_linemod_is_the_catalogued_bop_set():
    cfg = compose_cfg("dataset=linemod").dataset
    assert catalogue(cfg)[:3] == ("ape", "benchvise", "cam") and len(catalogue(cfg)) == 13
