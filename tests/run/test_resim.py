"""Re-simulating a logged trial (``python -m graspexp replay LOG --resim``) on a trial whose object was
re-dropped: its log keeps one clock across the drops, and re-simulation reproduces every logged pose."""

import numpy as np
import pytest
from helpers.config import shared_data_root

from graspexp.config.compose import compose_config
from graspexp.record import read_trial
from graspexp.run.resim import resimulate
from graspexp.run.runner import run_in_dir

pytestmark = pytest.mark.slow


def test_a_redropped_trial_logs_one_clock_and_resimulates(tmp_path):
    root = shared_data_root()
    if not (root / "ycb" / "005_tomato_soup_can").is_dir():
        pytest.skip(f"no YCB meshes under {root}")
    # Trial 0 of the soup can, bin XYZ, seed 0: the first drop rolls off the table (redrops = 1).
    cfg = compose_config(
        ["mode=bin", "rot=xyz", "dataset=ycb", f"dataset.root={root}", "objects=[005_tomato_soup_can]"]
        + ["trials=1", "progress=false"]
    )
    run_in_dir(cfg, tmp_path)
    log = read_trial(tmp_path / "trials" / "005_tomato_soup_can" / "000.mcap")
    assert log.result["redrops"] == 1
    drops = [t for t, name, _ in log.phases if name == "drop"]
    assert len(drops) == 2 and drops[1] > 0
    times = log.transforms["object"][0]
    assert np.all(np.diff(times) > 0)  # the second drop's samples follow the first's
    phase_times = [t for t, _, _ in log.phases]
    assert phase_times == sorted(phase_times)
    agrees, why = resimulate(log)
    assert agrees, why


def test_resim_without_the_mesh_is_one_line(tmp_path, monkeypatch, capsys):
    from graspexp.tools.replay import main as replay_main

    root = shared_data_root()
    if not (root / "ycb" / "025_mug").is_dir():
        pytest.skip(f"no YCB meshes under {root}")
    cfg = compose_config(["dataset=ycb", "objects=[025_mug]", "trials=1", "progress=false"])
    monkeypatch.setenv("GRASPEXP_DATA", str(root))
    run_in_dir(cfg, tmp_path / "run")
    monkeypatch.setenv("GRASPEXP_DATA", str(tmp_path / "nowhere"))
    assert replay_main([str(tmp_path / "run" / "trials" / "025_mug" / "000.mcap"), "--resim"]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith("graspexp replay: error: cannot re-simulate ")
    assert "download it with: python -m graspexp download" in err[0]


@pytest.mark.parametrize(
    "meta, message",
    [
        (
            {"config_yaml": "- 1\n- 2", "object": "can", "trial": "0", "trial_seed": "1"},
            "not a graspexp job config",
        ),
        (
            {"config_yaml": "{{{", "object": "can", "trial": "0", "trial_seed": "1"},
            "not a graspexp job config",
        ),
        ({"config_yaml": "{}"}, "metadata lacks a valid object, trial, trial_seed"),
    ],
)
def test_resim_of_a_log_with_a_junk_config_is_one_line(tmp_path, capsys, meta, message):
    from graspexp.core.outcome import TrialResult
    from graspexp.record import TrialRecorder
    from graspexp.tools.replay import main as replay_main

    path = tmp_path / "junk.mcap"
    with TrialRecorder(path, meta) as rec:
        rec.result(
            0.0, TrialResult("primitives", "can", "collab", "z", "optimal", 0, 1, True, None).to_dict()
        )
    assert replay_main([str(path), "--resim"]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and message in err[0]


def test_resim_finds_the_mesh_in_the_recorded_data_root(tmp_path, monkeypatch):
    root = shared_data_root()
    if not (root / "ycb" / "025_mug").is_dir():
        pytest.skip(f"no YCB meshes under {root}")
    monkeypatch.setenv("GRASPEXP_DATA", str(root))
    run_in_dir(compose_config(["dataset=ycb", "objects=[025_mug]", "trials=1", "progress=false"]), tmp_path)
    monkeypatch.delenv("GRASPEXP_DATA")
    log = read_trial(tmp_path / "trials" / "025_mug" / "000.mcap")
    assert log.metadata["data_root"] == str(root.resolve())
    agrees, why = resimulate(log)
    assert agrees, why
