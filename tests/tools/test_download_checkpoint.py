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


@pytest.mark.parametrize(
    ("make", "what"),
    [
        (lambda p: p.mkdir(), "is a folder, not a regular file: remove it and run `python -m graspexp"),
        (lambda p: p.symlink_to("/dev/zero"), "is a character device, not a regular file: remove it and run"),
        (lambda p: os.mkfifo(p), "is a named pipe, not a regular file"),
        (lambda p: p.symlink_to(p.parent / "gone"), "is a link to nothing, not a regular file"),
    ],
    ids=["folder", "dev-zero", "fifo", "dangling-link"],
)
def test_a_checkpoint_that_is_no_regular_file_says_what_it_is_and_is_never_read(
    tmp_path, monkeypatch, make, what
):
    """A folder or ``/dev/zero`` in the checkpoint's place is named for what it is (not "not found"), and
    refused before a byte is read (hashing ``/dev/zero`` would never end)."""
    monkeypatch.setenv(checkpoints.CHECKPOINTS_ENV, str(tmp_path))
    make(tmp_path / checkpoints.VGN.filename)
    monkeypatch.setattr(type(tmp_path), "read_bytes", lambda self: pytest.fail(f"{self} was read"))
    why = checkpoints.missing_reason(checkpoints.VGN)
    assert why.startswith(f"checkpoint {tmp_path / checkpoints.VGN.filename} {what}") and "\n" not in why
    with pytest.raises(checkpoints.CheckpointError, match="not a regular file"):
        checkpoints.read_verified(checkpoints.VGN)


def test_an_unreadable_checkpoint_or_a_variable_naming_a_file_is_said_so(tmp_path, monkeypatch):
    path = tmp_path / checkpoints.VGN.filename
    path.write_bytes(b"x" * checkpoints.VGN.size_bytes)
    monkeypatch.setenv(checkpoints.CHECKPOINTS_ENV, str(tmp_path))
    monkeypatch.setattr(checkpoints.os, "access", lambda p, mode: False)  # as a non-root user after chmod 0
    assert checkpoints.missing_reason(checkpoints.VGN) == (
        f"checkpoint {path} is unreadable (permission denied): make it readable (chmod a+r) or run "
        "`python -m graspexp download_checkpoint vgn`"
    )
    monkeypatch.setenv(checkpoints.CHECKPOINTS_ENV, "/dev/zero")
    assert checkpoints.missing_reason(checkpoints.VGN).startswith(
        "checkpoint /dev/zero/vgn_conv.pth not found ($GRASPEXP_CHECKPOINTS names /dev/zero, which is not a folder)"
    )


def test_download_refuses_a_target_that_is_no_regular_file_without_reading_it(tmp_path, capsys):
    """``download_checkpoint`` into a folder whose ``vgn_conv.pth`` is ``/dev/zero`` would hash it forever
    (pooch checks a file already there): one line instead, and nothing contacted."""
    (tmp_path / checkpoints.VGN.filename).symlink_to("/dev/zero")
    argv = ["vgn", "--dir", str(tmp_path), "--url", "http://127.0.0.1:9/none", "--quiet"]
    assert download_checkpoint.main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err == (
        f"graspexp download_checkpoint: error: {tmp_path / checkpoints.VGN.filename} is a character device, "
        "not a regular file: remove it"
    )
