"""A full disk and read-only output end in one line naming the problem and the fix (exit 2, no traceback),
and nothing written before is lost or left half-written. Real filesystems: a 1 MiB tmpfs and a read-only
bind mount, each in a private mount namespace (``unshare -m``; skipped where that is not allowed)."""

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from graspexp.record import read_trial

pytestmark = pytest.mark.slow
REPO = Path(__file__).resolve().parents[2]
JOB = [sys.executable, "-m", "graspexp", "dataset=primitives", "objects=[can]", "progress=false"]


def _namespaced(setup: str, cmd: list[str], after: str = "") -> subprocess.CompletedProcess:
    """``cmd`` in a private mount namespace after the shell commands ``setup``; ``after`` runs there next."""
    script = f'{setup} && {{ "$@"; rc=$?; {after} exit $rc; }}'
    return subprocess.run(
        ["unshare", "-m", "sh", "-c", script, "sh", *cmd],
        cwd=REPO,
        capture_output=True,
        text=True,
        timeout=300,
    )


@pytest.fixture(scope="module", autouse=True)
def _mount_namespaces(tmp_path_factory):
    probe = tmp_path_factory.mktemp("probe")
    if not shutil.which("unshare"):
        pytest.skip("no unshare(1)")
    if _namespaced(f"mount -t tmpfs none {probe}", ["true"]).returncode != 0:
        pytest.skip("mount namespaces are not allowed here (needs root or user namespaces)")


def _one_error_line(proc: subprocess.CompletedProcess) -> str:
    assert "Traceback" not in proc.stderr, proc.stderr[-3000:]
    lines = [ln for ln in proc.stderr.splitlines() if "error:" in ln]
    assert len(lines) == 1, proc.stderr[-3000:]
    return lines[0]


def test_a_full_disk_stops_the_run_in_one_line_and_keeps_every_finished_log(tmp_path: Path) -> None:
    disk, kept = tmp_path / "disk", tmp_path / "kept"
    disk.mkdir()
    run = disk / "run"
    proc = _namespaced(
        f"mount -t tmpfs -o size=256k none {disk}",
        [*JOB, "trials=40", f"hydra.run.dir={run}"],
        after=f"cp -a {disk}/. {kept}/;",
    )
    assert proc.returncode == 2, proc.stderr[-3000:]
    line = _one_error_line(proc)
    assert line.startswith(f"graspexp: error: cannot write the trial log {run}/trials/can/")
    assert line.endswith(
        "the disk may be full: free space, then run the same command again (finished trials are kept and reused)"
    )
    logs = sorted((kept / "run" / "trials" / "can").glob("*"))
    assert logs and all(p.suffix == ".mcap" for p in logs), logs  # no half-written file left behind
    assert [read_trial(p).result["trial"] for p in logs] == list(range(len(logs)))
    before = {p.name: p.read_bytes() for p in logs}
    again = subprocess.run(  # the same command with space: resumes, the finished logs are reused as they are
        [*JOB, f"trials={len(logs) + 2}", f"hydra.run.dir={kept / 'run'}"],
        cwd=REPO,
        capture_output=True,
        text=True,
    )
    assert again.returncode == 0, again.stderr[-3000:]
    assert all((kept / "run" / "trials" / "can" / n).read_bytes() == b for n, b in before.items())
    assert len(list((kept / "run" / "trials" / "can").glob("*.mcap"))) == len(logs) + 2


@pytest.fixture(scope="module")
def finished_run(tmp_path_factory) -> Path:
    run = tmp_path_factory.mktemp("finished") / "run"
    proc = subprocess.run(
        [*JOB, "trials=2", f"hydra.run.dir={run}"], cwd=REPO, capture_output=True, text=True
    )
    assert proc.returncode == 0, proc.stderr[-3000:]
    return run


def _read_only(folder: Path) -> str:
    return f"mount --bind {folder} {folder} && mount -o remount,bind,ro {folder}"


def _tree(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_report_into_a_read_only_run_names_the_fix(finished_run: Path) -> None:
    before = _tree(finished_run)
    proc = _namespaced(
        _read_only(finished_run), [sys.executable, "-m", "graspexp", "report", str(finished_run)]
    )
    assert proc.returncode == 2
    assert _one_error_line(proc) == (
        f"graspexp report: error: cannot write the report to {finished_run / 'report'}: Read-only file system; "
        "choose another folder with --out"
    )
    assert _tree(finished_run) == before


def test_a_run_into_a_read_only_directory_is_refused_before_it_starts(finished_run: Path) -> None:
    before = _tree(finished_run)
    proc = _namespaced(_read_only(finished_run), [*JOB, "trials=3", f"hydra.run.dir={finished_run}"])
    assert proc.returncode == 2
    line = _one_error_line(proc)
    assert line.startswith(f"graspexp: error: cannot write the output directory {finished_run}"), line
    assert "Read-only file system" in line
    assert _tree(finished_run) == before


def test_plan_dump_into_a_read_only_folder_names_the_fix(tmp_path: Path) -> None:
    folder = tmp_path / "ro"
    folder.mkdir()
    cmd = [sys.executable, "-m", "graspexp", "plan", "dataset=primitives", "objects=[can]"]
    proc = _namespaced(_read_only(folder), [*cmd, "--dump", str(folder / "can.npz")])
    assert proc.returncode == 2
    assert _one_error_line(proc) == (
        f"graspexp plan: error: cannot write {folder / 'can.npz'}: Read-only file system; "
        "choose another path for --dump"
    )
    assert not any(folder.iterdir())
