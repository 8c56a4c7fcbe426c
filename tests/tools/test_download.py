"""graspexp.tools.download against a local http.server on 127.0.0.1 (no other address is contacted)."""

from __future__ import annotations

import functools
import hashlib
import io
import json
import signal
import subprocess
import sys
import tarfile
import threading
import time
import zipfile
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path

import numpy as np
import pytest
import trimesh

from graspexp.config import DatasetConfig
from graspexp.datasets import DatasetError, download, load_object
from graspexp.datasets.ycb_objects import GOOGLE_16K_EXTENTS_MM
from graspexp.tools import download as download_tool

YCB_ID = "061_foam_brick"


def cube_bytes(size: float, file_type: str) -> bytes:
    data = trimesh.creation.box(extents=[size] * 3).export(file_type=file_type)
    return data.encode() if isinstance(data, str) else data


def google_16k_bytes(scale: float) -> bytes:
    """An OBJ with the 16,384 faces every google_16k model has: a cylinder stretched to the foam brick's
    published extents (mm, ``GOOGLE_16K_EXTENTS_MM``) times ``scale``, in metres."""
    can = trimesh.creation.cylinder(radius=0.5, height=1.0, sections=4096)
    assert len(can.faces) == 16384
    can.apply_scale(np.asarray(GOOGLE_16K_EXTENTS_MM[YCB_ID]) * scale / 1000.0)
    return can.export(file_type="obj").encode()


def write_tgz(path: Path, files: dict[str, bytes]) -> None:
    with tarfile.open(path, "w:gz") as tar:
        for name, data in files.items():
            info = tarfile.TarInfo(name)
            info.size = len(data)
            tar.addfile(info, io.BytesIO(data))


def write_zip(path: Path, files: dict[str, bytes]) -> None:
    with zipfile.ZipFile(path, "w") as zf:
        for name, data in files.items():
            zf.writestr(name, data)


class _Handler(SimpleHTTPRequestHandler):
    requests: list[str] = []

    def do_GET(self):  # noqa: N802 (http.server naming)
        type(self).requests.append(self.path)
        super().do_GET()

    def log_message(self, *args):  # keep the test output clean
        pass


@pytest.fixture
def server(tmp_path, monkeypatch):
    """Serve ``tmp_path/serve`` on 127.0.0.1 (free port) from a thread; yields (folder, base URL, log)."""
    for var in ("http_proxy", "https_proxy", "HTTP_PROXY", "HTTPS_PROXY", "ALL_PROXY", "all_proxy"):
        monkeypatch.delenv(var, raising=False)
    monkeypatch.setenv("NO_PROXY", "127.0.0.1,localhost")
    for var in download.URL_ENV.values():
        monkeypatch.delenv(var, raising=False)
    folder = tmp_path / "serve"
    folder.mkdir()
    handler = type("Handler", (_Handler,), {"requests": []})
    httpd = ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(handler, directory=str(folder)))
    thread = threading.Thread(target=httpd.serve_forever, daemon=True)
    thread.start()
    try:
        yield folder, f"http://127.0.0.1:{httpd.server_address[1]}/", handler.requests
    finally:
        httpd.shutdown()
        httpd.server_close()
        thread.join(timeout=5)


def ycb_archive(folder: Path, scale: float = 1.0) -> Path:
    path = folder / f"{YCB_ID}_google_16k.tgz"
    write_tgz(
        path,
        {
            f"{YCB_ID}/google_16k/textured.obj": google_16k_bytes(scale),
            f"{YCB_ID}/google_16k/textured.mtl": b"newmtl material_0\n",
        },
    )
    return path


def linemod_archive(folder: Path) -> Path:
    path = folder / download.LINEMOD_ARCHIVE
    ply_mm = cube_bytes(40.0, "ply")  # BOP models are in millimetres
    write_zip(
        path,
        {
            "models/obj_000001.ply": ply_mm,
            "models/models_info.json": json.dumps(
                {"1": {"diameter": 69.3, "size_x": 40.0, "size_y": 40.0, "size_z": 40.0}}
            ).encode(),
            "models_eval/obj_000001.ply": ply_mm,
        },
    )
    return path


def test_ycb_download_records_hash_and_loads(server, tmp_path, capsys):
    folder, url, log = server
    archive = ycb_archive(folder)
    root = tmp_path / "data"
    argv = ["dataset=ycb", f"dataset.root={root}", f"objects=[{YCB_ID}]", "--base-url", url, "progress=false"]
    assert download_tool.main(argv) == 0
    assert (root / "ycb" / YCB_ID / "google_16k" / "textured.obj").is_file()
    registry = json.loads((root / download.HASH_REGISTRY).read_text())
    entry = registry[f"ycb/{archive.name}"]
    assert entry["sha256"] == hashlib.sha256(archive.read_bytes()).hexdigest()
    assert entry["url"] == url + archive.name
    assert "recorded SHA-256" in capsys.readouterr().out

    obj = load_object(DatasetConfig(name="ycb", root=str(root), regions="ycb.yaml"), YCB_ID, 256, 0)
    np.testing.assert_allclose(obj.mesh.extents, np.asarray(GOOGLE_16K_EXTENTS_MM[YCB_ID]) / 1000.0)
    assert obj.mass_kg == pytest.approx(0.028) and obj.area_mask.any()

    # A re-run finds the verified archive and downloads nothing.
    assert len(log) == 1
    assert download_tool.main(argv) == 0
    assert len(log) == 1


def test_ycb_tampered_archive_fails_clearly(server, tmp_path, capsys):
    folder, url, _ = server
    ycb_archive(folder)
    root = tmp_path / "data"
    download.download_ycb(root, [YCB_ID], url=url, progress=False)
    mesh = root / "ycb" / YCB_ID / "google_16k" / "textured.obj"
    original = mesh.read_bytes()

    ycb_archive(folder, scale=1.001)  # the server now serves different bytes under the same name
    (root / download.ARCHIVE_DIR / f"{YCB_ID}_google_16k.tgz").unlink()  # e.g. a fresh machine, same root
    argv = ["dataset=ycb", f"dataset.root={root}", f"objects=[{YCB_ID}]", "--base-url", url, "progress=false"]
    assert download_tool.main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith(
        "graspexp download: error: checksum mismatch for " + url + f"{YCB_ID}_google_16k.tgz"
    )
    assert mesh.read_bytes() == original  # nothing was unpacked over the good copy
    with pytest.raises(DatasetError, match="checksum mismatch"):
        download.download_ycb(root, [YCB_ID], url=url, progress=False)


def test_linemod_download_verifies_hash_and_loads(server, tmp_path):
    folder, url, _ = server
    digest = hashlib.sha256(linemod_archive(folder).read_bytes()).hexdigest()
    root = tmp_path / "data"
    models = download.download_linemod(root, url=url, sha256=digest, progress=False)
    assert [p.name for p in models] == ["obj_000001.ply"]
    assert (root / "linemod" / "models_eval" / "obj_000001.ply").is_file()
    ape = load_object(DatasetConfig(name="linemod", root=str(root), regions="linemod.yaml"), "ape", 256, 0)
    np.testing.assert_allclose(ape.mesh.extents, 0.04)  # millimetres -> metres
    assert ape.mass_kg == pytest.approx(0.04**3 * 700.0)


def test_linemod_wrong_hash_fails_clearly(server, tmp_path, capsys):
    folder, url, _ = server
    linemod_archive(folder)  # not the published archive, so the published SHA-256 cannot match
    root = tmp_path / "data"
    assert (
        download_tool.main(["dataset=linemod", f"dataset.root={root}", "--base-url", url, "progress=false"])
        == 2
    )
    err = capsys.readouterr().err
    assert "checksum mismatch for " + url + download.LINEMOD_ARCHIVE in err
    assert download.LINEMOD_SHA256 in err
    assert not (root / "linemod").exists()


def test_base_url_from_environment(server, tmp_path, monkeypatch, capsys):
    folder, url, log = server
    digest = hashlib.sha256(linemod_archive(folder).read_bytes()).hexdigest()
    monkeypatch.setenv("GRASPEXP_LINEMOD_URL", url.rstrip("/"))
    root = tmp_path / "data"
    argv = ["dataset=linemod", f"dataset.root={root}", f"--sha256={digest}", "progress=false"]
    assert download_tool.main(argv) == 0  # the default list: the 12 models this archive lacks are a warning
    assert "lacks the models of: benchvise" in capsys.readouterr().err
    assert log == ["/" + download.LINEMOD_ARCHIVE]
    assert download_tool.main([*argv, "objects=[ape,cam]"]) == 2  # explicitly requested: an error
    assert "lacks the models of: cam" in capsys.readouterr().err
    assert download.base_url("ycb") == download.YCB_URL


def test_missing_file_on_server_names_the_url(server, tmp_path):
    _, url, _ = server
    with pytest.raises(DatasetError, match=f"download of {url}025_mug_google_16k.tgz failed"):
        download.download_ycb(tmp_path / "data", ["025_mug"], url=url, progress=False)


def test_unsafe_archive_member_is_refused(server, tmp_path):
    folder, url, _ = server
    write_tgz(folder / f"{YCB_ID}_google_16k.tgz", {"../evil.txt": b"x"})
    with pytest.raises(DatasetError, match="unsafe member path '../evil.txt'"):
        download.download_ycb(tmp_path / "data", [YCB_ID], url=url, progress=False)
    assert not (tmp_path / "evil.txt").exists()


@pytest.mark.slow
def test_cli_arguments(monkeypatch, tmp_path):
    monkeypatch.setenv("GRASPEXP_DATA", str(tmp_path))
    args = download_tool.parse_args(["dataset=ycb", "objects=[025_mug, 011_banana]"])
    assert args.root == tmp_path and args.objects == ["025_mug", "011_banana"]
    assert len(download_tool.parse_args(["dataset=ycb", "--all"]).objects) == 78
    assert download_tool.parse_args(["dataset=linemod", "dataset.root=/x"]).root == Path("/x")
    bad_args = (
        ["dataset.root=/x"],
        ["dataset=primitives"],
        ["dataset=ycb", "colour=red"],
        ["dataset=ycb", "objects=x"],
    )
    for bad in bad_args:
        with pytest.raises(SystemExit):
            download_tool.parse_args(bad)
    with pytest.raises(DatasetError, match="unknown object 'teapot'"):
        download.download_ycb(tmp_path, ["teapot"], url="http://127.0.0.1:9/")


def test_html_error_page_is_refused_and_no_hash_is_recorded(server, tmp_path):
    folder, url, _ = server
    page = folder / f"{YCB_ID}_google_16k.tgz"
    page.write_bytes(b"<!DOCTYPE html><html><body>503 Service Unavailable</body></html>")
    root = tmp_path / "data"
    with pytest.raises(
        DatasetError, match=r"is not a tar archive but an HTML page \(an error page\?\); it was deleted"
    ):
        download.download_ycb(root, [YCB_ID], url=url, progress=False)
    assert not (root / download.HASH_REGISTRY).exists()
    assert not (root / download.ARCHIVE_DIR / page.name).exists()
    archive = ycb_archive(folder)  # the server works again: the real archive is accepted and recorded
    download.download_ycb(root, [YCB_ID], url=url, progress=False)
    registry = json.loads((root / download.HASH_REGISTRY).read_text())
    assert registry[f"ycb/{archive.name}"]["sha256"] == hashlib.sha256(archive.read_bytes()).hexdigest()


def test_mismatch_says_how_to_reset_a_recorded_hash(server, tmp_path):
    folder, url, _ = server
    root = tmp_path / "data"
    root.mkdir()
    key = f"ycb/{YCB_ID}_google_16k.tgz"
    (root / download.HASH_REGISTRY).write_text(json.dumps({key: {"sha256": "0" * 64, "url": "x"}}))
    ycb_archive(folder)
    with pytest.raises(DatasetError, match=rf"delete the entry '{key}' from {root / download.HASH_REGISTRY}"):
        download.download_ycb(root, [YCB_ID], url=url, progress=False)


class _StallingHandler(SimpleHTTPRequestHandler):
    """Sends the headers of a 10 MB file and 64 kB of it, then stalls (a download to interrupt)."""

    def do_GET(self):  # noqa: N802 (http.server naming)
        self.send_response(200)
        self.send_header("Content-Length", str(10 << 20))
        self.end_headers()
        self.wfile.write(b"\0" * (64 << 10))
        self.wfile.flush()
        time.sleep(30)

    def log_message(self, *args):
        pass


@pytest.mark.slow
@pytest.mark.parametrize("sig", [signal.SIGTERM, signal.SIGKILL], ids=["term", "kill"])
def test_interrupted_download_leaves_no_temporary_file(server, tmp_path, sig):
    httpd = ThreadingHTTPServer(("127.0.0.1", 0), _StallingHandler)
    httpd.daemon_threads = True
    threading.Thread(target=httpd.serve_forever, daemon=True).start()
    root = tmp_path / "data"
    cmd = [sys.executable, "-m", "graspexp", "download", "dataset=ycb", f"dataset.root={root}", f"objects=[{YCB_ID}]",
           "--base-url", f"http://127.0.0.1:{httpd.server_address[1]}/", "progress=false"]  # fmt: skip
    log = tmp_path / "download.log"
    with open(log, "w") as err:
        proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=err)
    archives = root / download.ARCHIVE_DIR
    try:
        deadline = time.monotonic() + 180  # a cold start on a loaded 2-core machine
        while not list(archives.glob("tmp*")) and proc.poll() is None and time.monotonic() < deadline:
            time.sleep(0.05)
        assert list(archives.glob("tmp*")), f"the download never started: {log.read_text()[-2000:]}"
        proc.send_signal(sig)
        proc.wait(timeout=30)
    finally:
        proc.kill()
        httpd.shutdown()
        httpd.server_close()
    if sig == signal.SIGKILL:  # nothing runs on SIGKILL: the next download removes the leftover
        assert list(archives.glob("tmp*"))
        folder, url, _ = server
        ycb_archive(folder)
        download.download_ycb(root, [YCB_ID], url=url, progress=False)
    assert not list(archives.glob("tmp*"))


def test_an_archive_never_unpacks_over_another_object(server, tmp_path, capsys):
    folder, url, _ = server
    write_tgz(
        folder / f"{YCB_ID}_google_16k.tgz",
        {
            f"{YCB_ID}/google_16k/textured.obj": cube_bytes(0.05, "obj"),
            "025_mug/google_16k/textured.obj": cube_bytes(0.01, "obj"),  # another object's mesh
        },
    )
    root = tmp_path / "data"
    argv = ["dataset=ycb", f"dataset.root={root}", f"objects=[{YCB_ID}]", "--base-url", url, "progress=false"]
    assert download_tool.main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert "holds 025_mug/google_16k/textured.obj, outside 061_foam_brick/" in err and "\n" not in err
    assert not (root / "ycb" / "025_mug").exists()


@pytest.mark.parametrize("url", ["http://mirror.example.org/ycb/", "ftp://mirror.example.org/"])
def test_a_first_download_must_come_over_https(tmp_path, capsys, url):
    argv = [
        "dataset=ycb",
        f"dataset.root={tmp_path}",
        f"objects=[{YCB_ID}]",
        "--base-url",
        url,
        "progress=false",
    ]
    assert download_tool.main(argv) == 2
    assert "is not https" in capsys.readouterr().err
