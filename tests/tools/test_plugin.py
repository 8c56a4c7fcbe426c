"""Planner plugins: the example package registered through the entry-point mechanism (a dist-info on
sys.path, as pip writes it) runs through the benchmark command; a broken plugin is one line naming it."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pandas as pd
import pytest

from graspexp.record import read_result
from graspexp.report.contact_area import finger_contacts_in_area

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = REPO / "examples" / "top_down_planner"
tomllib = pytest.importorskip("tomllib")


def _register(site: Path, name: str, version: str, entry_points: dict[str, str]) -> dict[str, str]:
    """A dist-info for ``name`` in ``site`` declaring ``entry_points`` in the graspexp.planners group; the
    environment of a Python that sees it (and the example's source)."""
    info = site / f"{name.replace('-', '_')}-{version}.dist-info"
    info.mkdir(parents=True)
    (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {name}\nVersion: {version}\n")
    lines = "".join(f"{k} = {v}\n" for k, v in entry_points.items())
    (info / "entry_points.txt").write_text(f"[graspexp.planners]\n{lines}")
    path = os.pathsep.join([str(site), str(EXAMPLE), os.environ.get("PYTHONPATH", "")])
    return {**os.environ, "PYTHONPATH": path}


def _run(args: list[str], env: dict[str, str], cwd: Path) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", *args], cwd=cwd, env=env, capture_output=True, text=True, timeout=120
    )


@pytest.mark.slow
def test_example_plugin_runs_through_the_benchmark_beside_a_builtin_planner(tmp_path):
    project = tomllib.loads((EXAMPLE / "pyproject.toml").read_text())["project"]
    env = _register(
        tmp_path / "site", project["name"], project["version"], project["entry-points"]["graspexp.planners"]
    )
    out = tmp_path / "bench"
    args = [
        "graspexp",
        "benchmark",
        "planner=top_down",
        "dataset=primitives",
        "mode=collab",
        "rot=z",
        "trials=1",
        "objects=[can]",
        "--noise=",
        "--compare=obb",
        "--n-jobs=1",
        f"--out={out}",
        "planner.clearance_m=0.004",
    ]
    proc = _run(args, env, tmp_path)
    assert proc.returncode == 0, proc.stderr[-2000:]
    summary = (out / "top_down" / "summary.md").read_text()
    ranking = summary.split("## Ranking on `primitives`")[1].split("\n\n")[1]
    assert "| top_down " in ranking and "| obb " in ranking
    assert "Same drops: every planner ran the same (trial, seed) pairs" in summary
    record = json.loads((out / "top_down" / "reproduce.json").read_text())
    assert record["planners"]["top_down"] == {
        "package": "top-down-planner 0.1.0",
        "entry_point": "top_down_planner:PLUGIN",
        "version": "0.1.0",
    }
    assert record["planners"]["obb"]["package"].startswith("graspexp ")
    mine = [j for j in record["jobs"] if j["planner"] == "top_down"]
    assert mine[0]["config"]["planner"] == {
        "name": "top_down",
        "sphere_radius_m": 0.1,
        "n_points": 2048,
        "clearance_m": 0.004,
    }
    assert sorted(
        p.name
        for p in (out / "top_down" / "runs" / "primitives" / "collab_z_t0_r0" / "trials" / "can").iterdir()
    ) == ["000.mcap"]
    rank = pd.read_csv(out / "top_down" / "ranking.csv").set_index("planner")
    for planner in ("top_down", "obb"):
        log = out / planner / "runs" / "primitives" / "collab_z_t0_r0" / "trials" / "can" / "000.mcap"
        inside, touching = finger_contacts_in_area(log)
        if read_result(log)["success"]:  # held: both fingers touch the can at the end of closing
            assert touching == 2 and rank.loc[planner, "in-area contact %"] == pytest.approx(50 * inside)
    again = _run(args, env, tmp_path)  # resumes: the trial log is read back, not re-run
    assert again.returncode == 0 and (out / "top_down" / "summary.md").read_text() == summary


@pytest.mark.slow
def test_a_broken_or_unknown_plugin_is_one_line_naming_it(tmp_path):
    env = _register(tmp_path / "site", "broken-planner", "2.0", {"broken": "no_such_module:PLUGIN"})
    proc = _run(["graspexp", "planner=broken"], env, REPO)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    assert proc.stderr.strip() == (
        "graspexp: error: planner 'broken' of broken-planner 2.0 (entry point no_such_module:PLUGIN) failed "
        "to load: ModuleNotFoundError: No module named 'no_such_module'"
    )
    ok = _run(["graspexp", "--cfg", "job", "planner=obb"], env, REPO)  # other planners are unaffected
    assert ok.returncode == 0, ok.stderr
    unknown = _run(["graspexp", "benchmark", "planner=nope"], env, REPO)
    assert unknown.returncode == 2 and unknown.stderr.startswith(
        "graspexp benchmark: error: planner.name='nope' is unknown"
    )


def test_importing_the_planners_loads_neither_hydra_nor_sapien():
    code = "import sys, graspexp.planning; print(sorted({m.split('.')[0] for m in sys.modules} & {'hydra', 'sapien'}))"
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0 and proc.stdout.strip() == "[]", proc.stderr


FAKE_LEARNED = """
from graspexp.config import Learned, PlannerPlugin
from graspexp.config.planner.base import BASE_CONSTRAINTS, PlannerConfig
from graspexp.core.checkpoints import Checkpoint

WEIGHTS = Checkpoint("fakenet_weights", "fakenet.pt", "https://example.invalid/fakenet.pt", "0" * 64, 1, "", "")
PLUGIN = PlannerPlugin(
    plan="fake_learned:plan",
    config=PlannerConfig,
    constraints=BASE_CONSTRAINTS,
    needs_observation=True,
    learned=Learned(gripper="robotiq_2f85", checkpoints=(WEIGHTS,)),
)
"""
"""A learned planner of another package: its plugin module (nothing of graspexp edited)."""
LEARNED_TRACE = """
from graspexp.report.camera import learned_columns
from graspexp.run.result_pages import pages
from graspexp.run.results import learned_pages
from graspexp.tools.bench.learned import bench_jobs
from graspexp.tools.download_checkpoint import known_checkpoints

found = {p.name: [s.name for s in p.sweeps] for p in pages()}
print([c[2] for c in learned_columns()])
print([n for n in found['camera'] + found['learned'] + found['clutter_camera'] if 'fakenet' in n])
print([p.name for p in learned_pages(pages())])
print(bench_jobs([])[0], 'fakenet_weights' in known_checkpoints())
"""


def test_a_learned_plugin_joins_the_learned_pages_through_its_entry_point_alone(tmp_path):
    """A second learned planner is its plugin module and its entry point: the camera page's column, the
    camera, learned and camera clutter pages' sweeps, ``nox -s learned``'s pages, ``bench.learned`` and
    ``download_checkpoint`` take it up."""
    env = _register(tmp_path / "site", "fakenet-planner", "0.1", {"fakenet": "fake_learned:PLUGIN"})
    (tmp_path / "site" / "fake_learned.py").write_text(FAKE_LEARNED)
    proc = subprocess.run(
        [sys.executable, "-c", LEARNED_TRACE], cwd=REPO, env=env, capture_output=True, text=True, timeout=120
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.splitlines() == [
        "['fakenet, gripper=robotiq_2f85, camera views', 'giga, gripper=panda, camera views', "
        "'vgn, gripper=panda, camera views']",
        "['fakenet_robotiq_2f85', 'fakenet_robotiq_2f85', 'fakenet_rg2', 'clutter_camera_fakenet']",
        "['camera', 'learned', 'clutter_camera']",
        "['planner=fakenet', 'gripper=robotiq_2f85', 'dataset=ycb', 'mode=bin'] True",
    ]
