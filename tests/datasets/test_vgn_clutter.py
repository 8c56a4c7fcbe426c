"""VGN's and GIGA's clutter test objects (``dataset=vgn_pile``, ``dataset=vgn_packed``): the manifest graspexp
carries, the shared copy checked against it, every object loaded in metres with its URDF mass, and the
download from a local http.server on 127.0.0.1 (no other address is contacted), checked file by file."""

from __future__ import annotations

import functools
import hashlib
import re
import shutil
import threading
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path

import numpy as np
import pytest
import trimesh
from helpers.config import compose_cfg, shared_data_root

from graspexp.config import DatasetConfig
from graspexp.datasets import DatasetError, download, load_object, select_objects, vgn_clutter
from graspexp.datasets.catalog import DATASETS
from graspexp.datasets.folder import read_urdf
from graspexp.tools import download as download_tool

SETS = {"vgn_pile": ("pile", 40), "vgn_packed": ("packed", 16)}
"""dataset -> (scene, number of objects): VGN's and GIGA's pile/test and packed/test."""


@pytest.fixture(scope="module")
def vgn_root() -> Path:
    """The data root holding the shared copy (``vgn_clutter/``); skips when it is absent."""
    root = shared_data_root()
    if not (root / vgn_clutter.FOLDER).is_dir():
        pytest.skip(f"the VGN/GIGA test objects (vgn_clutter/) not found at {root}: set GRASPEXP_DATA")
    return root


def _sha256(path: Path) -> str:
    return hashlib.sha256(path.read_bytes()).hexdigest()


def test_the_manifest_graspexp_carries_is_the_published_one():
    assert hashlib.sha256(vgn_clutter.MANIFEST.encode()).hexdigest() == vgn_clutter.MANIFEST_SHA256
    files = vgn_clutter.manifest_files()
    assert len(files) == 168 and all(re.fullmatch(r"[0-9a-f]{64}", d) for d in files.values())
    for dataset, (scene, n) in SETS.items():
        assert DATASETS[dataset].catalogue == vgn_clutter.object_names(scene)
        assert len(vgn_clutter.object_names(scene)) == n
        assert len(vgn_clutter.scene_files(scene)) == 3 * n  # URDF, collision and visual mesh each


def test_the_shared_copy_matches_the_manifest(vgn_root):
    published = vgn_root / vgn_clutter.FOLDER / "MANIFEST.sha256"
    if published.is_file():
        assert published.read_text() == vgn_clutter.MANIFEST
    for path, digest in vgn_clutter.manifest_files().items():
        assert _sha256(vgn_root / vgn_clutter.FOLDER / path) == digest, path


@pytest.mark.parametrize("dataset", SETS)
def test_every_object_loads_in_metres_with_its_urdf_mass(vgn_root, dataset):
    cfg = compose_cfg(f"dataset={dataset}", f"dataset.root={vgn_root}").dataset
    names = select_objects(cfg, None)
    assert len(names) == SETS[dataset][1]
    for name in names:
        model = load_object(cfg, name, 200, 0)
        urdf = vgn_root / vgn_clutter.set_folder(SETS[dataset][0]) / f"{name}.urdf"
        parts, mass = read_urdf(urdf)
        assert model.mass_kg == mass and [p.file.name for p in parts] == [f"{name}_collision.obj"]
        extents = np.sort(model.mesh.extents)
        assert 0.005 < extents[0] and extents[-1] < 0.3, (name, extents)  # metres: 1.2 to 24.6 cm
        assert np.all(np.abs(trimesh.proximity.signed_distance(model.mesh, model.points[:20])) < 1e-4)


def test_dataset_vgn_takes_the_objects_of_the_scene():
    for mode, name in (("pile", "vgn_pile"), ("packed", "vgn_packed"), ("collab", "vgn_pile")):
        cfg = compose_cfg("dataset=vgn", f"mode={mode}").dataset
        assert (cfg.name, cfg.regions) == (name, f"{name}.yaml")


def test_a_missing_set_names_its_download_command(tmp_path):
    cfg = DatasetConfig(name="vgn_packed", root=str(tmp_path))
    with pytest.raises(
        DatasetError, match=r"download it with: python -m graspexp download dataset=vgn_packed"
    ):
        load_object(cfg, "wooden_block", 16, 0)


@pytest.fixture
def mirror(tmp_path, monkeypatch, vgn_root):
    """A local mirror of the pinned commit's ``data/urdfs/`` on 127.0.0.1 (a copy of two packed objects):
    (its folder, its base URL)."""
    for var in ("http_proxy", "https_proxy", "HTTP_PROXY", "HTTPS_PROXY", "ALL_PROXY", "all_proxy"):
        monkeypatch.delenv(var, raising=False)
    monkeypatch.setenv("NO_PROXY", "127.0.0.1,localhost")
    monkeypatch.delenv(download.URL_ENV["vgn_clutter"], raising=False)
    served = tmp_path / "serve"
    (served / "packed" / "test").mkdir(parents=True)
    for name in ("wooden_block", "BakingVanilla_800_tex"):
        for fname in vgn_clutter.object_files(name):
            src = vgn_root / vgn_clutter.set_folder("packed") / fname
            shutil.copy(src, served / "packed" / "test" / fname)
    handler = type("Quiet", (SimpleHTTPRequestHandler,), {"log_message": lambda *a: None})
    httpd = ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(handler, directory=str(served)))
    thread = threading.Thread(target=httpd.serve_forever, daemon=True)
    thread.start()
    try:
        yield served, f"http://127.0.0.1:{httpd.server_address[1]}/"
    finally:
        httpd.shutdown()
        httpd.server_close()
        thread.join(timeout=5)


def test_download_fetches_each_file_checked_against_the_manifest(mirror, tmp_path):
    _, url = mirror
    root = tmp_path / "data"
    names = ["wooden_block", "BakingVanilla_800_tex"]
    paths, missing = download.download_dataset("vgn_packed", root, names, url=url)
    assert missing == [] and paths == [root / "vgn_clutter/packed/test" / f"{n}.urdf" for n in names]
    for name in names:
        for fname in vgn_clutter.object_files(name):
            assert (
                _sha256(root / "vgn_clutter/packed/test" / fname) == vgn_clutter.scene_files("packed")[fname]
            )
    model = load_object(DatasetConfig(name="vgn_packed", root=str(root)), "wooden_block", 16, 0)
    assert model.mass_kg == pytest.approx(1.089, abs=1e-3)


def test_a_file_that_differs_from_the_manifest_is_refused(mirror, tmp_path):
    served, url = mirror
    (served / "packed/test/wooden_block.urdf").write_text("<robot name='tampered'/>\n")
    with pytest.raises(
        DatasetError, match=r"checksum mismatch for http://127\.0\.0\.1:\d+/packed/test/wooden_block\.urdf"
    ):
        download.download_dataset("vgn_packed", tmp_path / "data", ["wooden_block"], url=url)


def test_the_download_tool_fetches_a_vgn_set(mirror, tmp_path, capsys):
    _, url = mirror
    root = tmp_path / "data"
    argv = ["dataset=vgn_packed", f"dataset.root={root}", "objects=[wooden_block]", "--base-url", url]
    assert download_tool.main(argv) == 0
    assert "1 vgn_packed model(s) ready" in capsys.readouterr().out
    assert (root / "vgn_clutter/packed/test/wooden_block_collision.obj").is_file()
