"""Issue 51, findings 3, 4 and 6 (clutter): a clutter run's resume compares what decides a round, its pool
(names and each mesh's SHA-256, recorded in every round log and in the run record) as well as its config,
and a ``record=false`` re-run keeps or refuses, never drops, the rounds of rounds.csv."""

import json
import re
from pathlib import Path

import pandas as pd
import pytest
import trimesh
from helpers.cli import one_error_line, run_job
from helpers.config import compose_cfg

from graspexp.core.outcome import TrialResult
from graspexp.core.run_layout import round_log_path
from graspexp.datasets import job_object
from graspexp.record import TrialRecorder, read_trial
from graspexp.run.locks import RunError
from graspexp.run.objects import load_models
from graspexp.run.resim import resimulate
from graspexp.run.runner import run_in_dir

pytestmark = pytest.mark.slow
PILE = ("mode=pile", "mode.objects_per_round=2", "progress=false")


def _pile(*overrides: str):
    return compose_cfg(*PILE, "dataset=primitives", *overrides)


def _snapshot(folder: Path) -> dict[str, bytes]:
    return {
        str(p.relative_to(folder)): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file() and ".graspexp.lock" not in p.name
    }


def test_a_round_log_records_its_pool_with_each_mesh(tmp_path):
    run_in_dir(_pile("objects=[can,box,mug]", "trials=1"), tmp_path)
    meta = read_trial(round_log_path(tmp_path, "pile", 0)).metadata
    pool = json.loads(meta["round_pool"])
    assert [e["name"] for e in pool] == ["can", "box", "mug"]
    assert all(re.fullmatch(r"[0-9a-f]{64}", e["mesh_sha256"]) for e in pool)
    assert set(meta["round_objects"].split()) <= {"can", "box", "mug"}


def test_finding_3_another_pool_into_the_same_folder_is_refused(tmp_path):
    """objects=[A,B,C] trials=2, then objects=[D,E,F] trials=2: refused naming both pools, nothing changed
    (it ran nothing and showed A-B-C's rounds as D-E-F's)."""
    run_in_dir(_pile("objects=[can,box,mug]", "trials=2"), tmp_path)
    before = _snapshot(tmp_path)
    for pool in ("[banana,bottle,block]", "[can,box,banana]"):
        with pytest.raises(RunError) as err:
            run_in_dir(_pile(f"objects={pool}", "trials=2"), tmp_path)
        line = str(err.value)
        assert "\n" not in line and "holds rounds of pile drawn from another pool" in line, line
        assert "trials/pile/000.mcap: can, box, mug; now " in line, line
    assert "only earlier: mug; only now: banana" in line, line
    with pytest.raises(RunError, match="the same objects in another order"):
        run_in_dir(_pile("objects=[box,can,mug]", "trials=4"), tmp_path)
    assert _snapshot(tmp_path) == before
    run_in_dir(_pile("objects=[can,box,mug]", "trials=3"), tmp_path)  # the same pool resumes and extends
    assert len(pd.read_csv(tmp_path / "rounds.csv")) == 3


def test_finding_3_the_cli_refuses_another_pool_in_one_line(tmp_path):
    run_in_dir(_pile("objects=[can,box,mug]", "trials=1"), tmp_path)
    line = one_error_line(
        run_job(tmp_path, *PILE, "dataset=primitives", "objects=[banana,bottle,block]", "trials=1")
    )
    assert "drawn from another pool" in line and "only now: banana, bottle, block" in line


def test_a_round_logged_before_pools_were_recorded_is_compared_by_what_it_drew(tmp_path):
    from graspexp.run.resume import check_same_pool

    path = round_log_path(tmp_path, "pile", 0)
    result = TrialResult("primitives", "pile", "pile", "z", "optimal", 0, 1, True, None)
    with TrialRecorder(path, {"object": "pile", "round_objects": "can mug"}) as rec:
        rec.result(0.0, result.to_dict())
    cfg = _pile("objects=[can,mug]")
    models, _ = load_models(cfg, ["box", "bottle"])
    with pytest.raises(RunError, match=r"drawn from another pool \(trials/pile/000.mcap drew can, mug"):
        check_same_pool(tmp_path, "pile", list(models.values()), {})
    models, _ = load_models(cfg, ["mug", "can", "box"])
    check_same_pool(tmp_path, "pile", list(models.values()), {})  # every drawn object is in the pool


def _meshes(root: Path, brick_x_m: float) -> Path:
    root.mkdir(exist_ok=True)
    trimesh.creation.box(extents=(brick_x_m, 0.04, 0.06)).export(root / "brick.stl")
    trimesh.creation.cylinder(radius=0.025, height=0.08, sections=24).export(root / "tin.stl")
    return root


def test_finding_4_a_changed_mesh_is_refused_with_both_hashes_and_resim_says_mesh_differs(tmp_path):
    meshes = _meshes(tmp_path / "meshes", 0.05)
    run = tmp_path / "run"

    def cfg():
        return compose_cfg(
            *PILE, "dataset=folder", f"dataset.root={meshes}", "objects=[brick,tin]", "trials=1"
        )

    run_in_dir(cfg(), run)
    log = round_log_path(run, "pile", 0)
    before = _snapshot(run)
    old = job_object(cfg(), "brick").mesh_sha256
    _meshes(meshes, 0.055)  # the same name, another mesh
    new = job_object(cfg(), "brick").mesh_sha256
    assert old != new
    with pytest.raises(RunError) as err:
        run_in_dir(cfg(), run)
    line = str(err.value)
    assert "\n" not in line and "holds rounds of pile made on another mesh of brick" in line, line
    assert f"sha256 {old[:12]}; now " in line and f"sha256 {new[:12]})" in line, line
    assert _snapshot(run) == before  # the old round is neither reused nor replaced
    agrees, why = resimulate(read_trial(log))
    assert not agrees and why.startswith("mesh differs: brick: "), why
    assert old[:12] in why and new[:12] in why, why
    (meshes / "brick.yaml").write_text("mass_kg: -1\n")  # brick cannot be used: the pool lost it
    with pytest.raises(RunError) as err:
        run_in_dir(cfg(), run)
    assert (
        "drawn from another pool (trials/pile/000.mcap: brick, tin; now tin: only earlier: brick; brick "
        "cannot be used now: " in str(err.value)
    ), str(err.value)
    assert _snapshot(run) == before


def test_finding_6_a_second_planner_into_a_record_false_clutter_folder_is_refused(tmp_path):
    """A second planner's record=false round 0 replaced the first's; now refused as a logged run is."""
    run_in_dir(_pile("objects=[can,box,mug]", "trials=2", "record=false"), tmp_path)
    before = _snapshot(tmp_path)
    with pytest.raises(
        RunError, match=r"holds results made with a different config; differing keys: planner.name"
    ):
        run_in_dir(_pile("objects=[can,box,mug]", "trials=1", "record=false", "planner=antipodal"), tmp_path)
    assert _snapshot(tmp_path) == before


def test_finding_6_a_logged_rerun_keeps_the_record_false_rounds(tmp_path):
    """record=false trials=5, then record=true trials=2: rounds 2-4 of rounds.csv (and their attempts) are
    kept beside the two logged rounds (it dropped them)."""
    from graspexp.run.run_record import table_rounds

    run_in_dir(_pile("objects=[can,box,mug]", "trials=5", "record=false"), tmp_path)
    rounds, attempts = (pd.read_csv(tmp_path / n) for n in ("rounds.csv", "attempts.csv"))
    run_in_dir(_pile("objects=[can,box,mug]", "trials=2", "record=true"), tmp_path)
    assert sorted(p.name for p in (tmp_path / "trials" / "pile").glob("*.mcap")) == ["000.mcap", "001.mcap"]
    cols = ["round", "seed", "drawn", "end", "removed"]
    pd.testing.assert_frame_equal(pd.read_csv(tmp_path / "rounds.csv")[cols], rounds[cols])
    cols = ["round", "attempt", "target", "success", "reason"]
    pd.testing.assert_frame_equal(pd.read_csv(tmp_path / "attempts.csv")[cols], attempts[cols])
    assert sorted(table_rounds(tmp_path)) == [2, 3, 4]  # kept as rows: no log behind them
    run_in_dir(_pile("objects=[can,box,mug]", "trials=1", "record=false"), tmp_path)  # and back again
    assert pd.read_csv(tmp_path / "rounds.csv")["round"].tolist() == [0, 1, 2, 3, 4]


def test_rounds_no_log_backs_without_a_record_are_refused_not_overwritten(tmp_path):
    """A rounds.csv written before graspexp kept the run record: its rounds are of an unknown config."""
    run_in_dir(_pile("objects=[can,box,mug]", "trials=2", "record=false"), tmp_path)
    (tmp_path / "run.json").unlink()
    before = _snapshot(tmp_path)
    with pytest.raises(RunError, match=r"rounds.csv holds 2 rows that no log backs \(round 0, round 1\)"):
        run_in_dir(_pile("objects=[can,box,mug]", "trials=1", "record=false"), tmp_path)
    assert _snapshot(tmp_path) == before
