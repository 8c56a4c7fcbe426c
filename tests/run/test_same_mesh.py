"""Resume never mixes trials made on two meshes: each log records its mesh file and the SHA-256 of the
geometry used; a run whose data root now gives another geometry of an object is refused in one line."""

import shutil
import subprocess
from pathlib import Path

import pytest
from helpers.cli import run_job
from helpers.config import shared_data_root

from graspexp.record import read_trial

pytestmark = pytest.mark.slow
REPO = Path(__file__).resolve().parents[2]
MUG = "025_mug"


def _run(run_dir: Path, data: Path, trials: int) -> subprocess.CompletedProcess:
    return run_job(
        run_dir, "dataset=ycb", f"objects=[{MUG}]", f"trials={trials}", env={"GRASPEXP_DATA": str(data)}
    )


def test_a_rescaled_mesh_under_another_data_root_is_refused(tmp_path):
    source = shared_data_root() / "ycb" / MUG
    if not source.is_dir():
        pytest.skip(f"no YCB meshes under {shared_data_root()}")
    roots = {}
    for name, scale in (("real", 1.0), ("scaled", 1.005)):  # within the published size's tolerance
        folder = tmp_path / name / "ycb" / MUG
        shutil.copytree(source, folder)
        obj = folder / "google_16k" / "textured.obj"
        lines = obj.read_text().splitlines()
        obj.write_text(
            "\n".join(
                "v " + " ".join(f"{float(v) * scale:.6f}" for v in ln.split()[1:4])
                if ln.startswith("v ")
                else ln
                for ln in lines
            )
            + "\n"
        )
        roots[name] = tmp_path / name
    run_dir = tmp_path / "run"
    first = _run(run_dir, roots["real"], 1)
    assert first.returncode == 0, first.stderr[-2000:]
    meta = read_trial(run_dir / "trials" / MUG / "000.mcap").metadata
    assert meta["mesh_source"].endswith("google_16k/textured.obj") and len(meta["mesh_sha256"]) == 64
    area, faces = float(meta["mesh_area_m2"]), int(meta["mesh_faces"])  # readable facts beside the hash
    assert 0.05 < area < 0.06 and faces == 16384  # google_16k: 16k faces; the mug's 5.6 dm^2 of surface
    assert meta["mesh_volume_m3"] == ""  # its loaded surface is open: no volume is claimed
    refused = _run(run_dir, roots["scaled"], 2)
    assert refused.returncode == 2
    lines = refused.stderr.strip().splitlines()
    assert len(lines) == 1 and f"holds trials of {MUG} made on another mesh" in lines[0], refused.stderr
    assert f"area {area:.4g} m^2" in lines[0] and lines[0].count(" m^2") == 2, lines[0]
    assert not (run_dir / "trials" / MUG / "001.mcap").exists()
    again = _run(run_dir, roots["real"], 2)  # the same mesh: resumes
    assert again.returncode == 0, again.stderr[-2000:]
