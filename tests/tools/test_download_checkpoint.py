"""graspexp download_checkpoint against a local http.server on 127.0.0.1 serving the VGN checkpoint from
``../shared/peers/vgn`` (copied into a temporary folder; no other address is contacted)."""

from __future__ import annotations

import functools
import os
import shutil
import threading
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer

import pytest
from helpers.config import shared_data_root

from graspexp.core import checkpoints
from graspexp.tools import download_checkpoint

SHARED_VGN = shared_data_root().parent / "peers" / "vgn" / checkpoints.VGN.filename


class _Quiet(SimpleHTTPRequestHandler):
    def log_message(self, *args):
        pass


@pytest.fixture
def served(tmp_path, monkeypatch):
    """(folder served, its base URL): ``vgn_conv.pth`` on 127.0.0.1."""
    if not SHARED_VGN.is_file():
        pytest.skip(f"the VGN checkpoint is not at {SHARED_VGN}")
    for var in ("http_proxy", "https_proxy", "HTTP_PROXY", "HTTPS_PROXY", "ALL_PROXY", "all_proxy"):
        monkeypatch.delenv(var, raising=False)
    monkeypatch.setenv("NO_PROXY", "127.0.0.1,localhost")
    folder = tmp_path / "serve"
    folder.mkdir()
    shutil.copyfile(SHARED_VGN, folder / checkpoints.VGN.filename)
    httpd = ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(_Quiet, directory=str(folder)))
    thread = threading.Thread(target=httpd.serve_forever, daemon=True)
    thread.start()
    try:
        yield folder, f"http://127.0.0.1:{httpd.server_address[1]}/{checkpoints.VGN.filename}"
    finally:
        httpd.shutdown()
        httpd.server_close()
        thread.join(timeout=5)


def test_download_verifies_the_hash_and_lands_where_the_planner_looks(served, tmp_path, monkeypatch, capsys):
    _, url = served
    monkeypatch.setenv(checkpoints.CHECKPOINTS_ENV, str(tmp_path / "ckpt"))
    assert checkpoints.missing_reason(checkpoints.VGN).startswith("checkpoint ")
    assert download_checkpoint.main(["vgn", "--url", url, "--quiet"]) == 0
    assert f"SHA-256 {checkpoints.VGN.sha256} verified" in capsys.readouterr().out
    assert checkpoints.missing_reason(checkpoints.VGN) == ""
    assert len(checkpoints.read_verified(checkpoints.VGN)) == checkpoints.VGN.size_bytes


def test_a_tampered_download_is_one_line_and_not_kept(served, tmp_path, capsys):
    folder, url = served
    path = folder / checkpoints.VGN.filename
    data = bytearray(path.read_bytes())
    data[1000] ^= 0x01
    path.write_bytes(bytes(data))
    assert download_checkpoint.main(["vgn", "--url", url, "--dir", str(tmp_path / "ckpt"), "--quiet"]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("graspexp download_checkpoint: error: checksum mismatch for ") and "\n" not in err
    assert not (tmp_path / "ckpt" / checkpoints.VGN.filename).exists()


def test_a_missing_or_resized_checkpoint_names_the_download_command(tmp_path, monkeypatch):
    monkeypatch.setenv(checkpoints.CHECKPOINTS_ENV, str(tmp_path))
    why = checkpoints.missing_reason(checkpoints.VGN)
    assert why.startswith(f"checkpoint {tmp_path / 'vgn_conv.pth'} not found: download it with ")
    assert "`python -m graspexp download_checkpoint vgn`" in why
    (tmp_path / "vgn_conv.pth").write_bytes(b"<html>not found</html>")
    assert "has 22 bytes, not the published 1255822" in checkpoints.missing_reason(checkpoints.VGN)
    with pytest.raises(checkpoints.CheckpointError, match="has 22 bytes"):
        checkpoints.read_verified(checkpoints.VGN)


def test_a_checkpoint_is_found_in_any_folder_of_the_variable(tmp_path, monkeypatch):
    """``$GRASPEXP_CHECKPOINTS`` may name several folders (one per learned planner), searched in order; a
    download goes to the first."""
    first, second = tmp_path / "giga", tmp_path / "vgn"
    second.mkdir()
    (second / checkpoints.VGN.filename).write_bytes(b"x")
    monkeypatch.setenv(checkpoints.CHECKPOINTS_ENV, f"{first}{os.pathsep}{second}")
    assert checkpoints.checkpoint_dirs() == [first, second] and checkpoints.checkpoint_dir() == first
    assert checkpoints.checkpoint_path(checkpoints.VGN) == second / checkpoints.VGN.filename
    assert "has 1 bytes" in checkpoints.missing_reason(checkpoints.VGN)
    monkeypatch.setenv(checkpoints.CHECKPOINTS_ENV, str(first))
    assert checkpoints.checkpoint_path(checkpoints.VGN) == first / checkpoints.VGN.filename
