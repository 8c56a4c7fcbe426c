"""Read-only output ends in one line naming the problem and the fix (exit 2, no traceback), and nothing
written before is changed. A real read-only bind mount in a private mount namespace (``unshare -m``;
skipped where that is not allowed). The full disk is tests/run/test_disk_full.py."""

import shutil
import subprocess
import sys
from pathlib import Path

import pytest

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
