"""The main job end to end: per-trial MCAP logs, deterministic payloads, replay and re-simulation."""

import json
from pathlib import Path

import pytest
from helpers.cli import graspexp, run_job
from helpers.config import compose_cfg
from helpers.logs import strictly_valid
from mcap.reader import make_reader

from graspexp.record import TrialRecorder, read_trial
from graspexp.run.objects import load_sim_object, trial_context
from graspexp.sim.trial import plain_config, run_trial

pytestmark = pytest.mark.slow
REPO = Path(__file__).resolve().parents[2]
WALL_CLOCK_KEYS = {"timings_s"}
"""Result fields that hold wall-clock time: the only payload bytes allowed to differ between two runs."""


@pytest.fixture(scope="module")
def two_runs(tmp_path_factory):
    base = tmp_path_factory.mktemp("job")
    overrides = ("mode=bin", "rot=xyz", "trials=2", "objects=[can,box]")
    runs = [base / "a", base / "b"]
    for d in runs:
        proc = run_job(d, *overrides)
        assert proc.returncode == 0, proc.stderr[-2000:]
    return runs


def _payloads(path: Path) -> list[tuple[str, int, object]]:
    out = []
    with open(path, "rb") as f:
        for _schema, channel, message in make_reader(f).iter_messages(log_time_order=False):
            if channel.message_encoding == "protobuf":  # Foxglove topics: compare the encoded bytes
                out.append((channel.topic, message.log_time, message.data))
                continue
            data = json.loads(message.data)
            if channel.topic == "/result":
                data = {k: v for k, v in data.items() if k not in WALL_CLOCK_KEYS}
            out.append((channel.topic, message.log_time, data))
    return out


def test_job_writes_one_log_per_trial_and_a_results_table(two_runs):
    run = two_runs[0]
    logs = sorted(run.glob("trials/*/*.mcap"))
    assert [p.relative_to(run).as_posix() for p in logs] == [
        "trials/box/000.mcap",
        "trials/box/001.mcap",
        "trials/can/000.mcap",
        "trials/can/001.mcap",
    ]
    assert len((run / "results.csv").read_text().splitlines()) == 5
    assert "Average" in (run / "summary.md").read_text()


def test_log_reads_back_with_expected_topics_and_schemas(two_runs):
    log = read_trial(two_runs[0] / "trials" / "box" / "000.mcap")
    assert log.topics["/tf"] == "foxglove.FrameTransforms"
    assert log.topics["/scene"] == "foxglove.SceneUpdate"
    assert log.topics["/contacts"] == "foxglove.PointCloud"
    assert log.topics["/grasp"] == "graspexp.PlannedGrasp@1"
    assert log.topics["/result"] == "graspexp.TrialResult@5"
    assert {"object", "palm", "finger_left", "finger_right"} <= set(log.transforms)
    assert log.metadata["object"] == "box" and "config_yaml" in log.metadata
    times, _, _ = log.transforms["object"]
    assert times[-1] == pytest.approx(log.result["sim_time_s"], abs=0.05)


def test_same_seed_gives_identical_mcap_payloads(two_runs):
    a, b = two_runs
    for rel in ("trials/can/000.mcap", "trials/box/001.mcap"):
        assert _payloads(a / rel) == _payloads(b / rel)


def test_replay_prints_timeline_and_resim_agrees(two_runs):
    path = two_runs[0] / "trials" / "box" / "000.mcap"
    proc = graspexp("replay", str(path), "--resim", timeout=120)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "approach" in proc.stdout and "reproduced" in proc.stdout


def test_rerun_into_same_directory_resumes_without_rewriting(two_runs):
    run = two_runs[0]
    log = run / "trials" / "can" / "001.mcap"
    before = log.stat().st_mtime_ns
    proc = run_job(run, "mode=bin", "rot=xyz", "trials=2", "objects=[can,box]")
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert log.stat().st_mtime_ns == before


def test_unknown_object_is_one_clear_error(tmp_path):
    proc = run_job(tmp_path, "objects=[teapot]")
    assert proc.returncode == 2
    assert proc.stderr.strip().splitlines()[-1].startswith("graspexp: error: unknown object(s) ['teapot']")


def test_bin_logs_valid_for_independent_readers(two_runs):
    for path in sorted(two_runs[0].glob("trials/*/*.mcap")):
        with open(path, "rb") as f:
            counts = strictly_valid(f)
        assert counts["/tf"] > 0 and counts["/scene"] >= 1 and counts["/result"] == 1, (path, counts)


@pytest.fixture(scope="module")
def collab_log(tmp_path_factory) -> Path:
    """One collab trial that grasps and then removes the support, logged in-process."""
    cfg = compose_cfg("mode=collab")
    plain = plain_config(cfg)
    loaded = load_sim_object(cfg, "can", plain)
    path = tmp_path_factory.mktemp("collab") / "000.mcap"
    with TrialRecorder(path, {"object": "can"}) as rec:
        run_trial(trial_context(plain, loaded, 0, rec))
    return path


def test_collab_log_valid_and_deletes_the_support_when_removed(collab_log):
    with open(collab_log, "rb") as f:
        counts = strictly_valid(f)
    assert counts["/scene"] == 3  # support + hulls, gripper, deletion of the support
    log = read_trial(collab_log)
    removed = [t for t, name, _ in log.phases if name == "remove_support"]
    assert len(removed) == 1, log.phases
    assert log.scene_deletions == [(removed[0], "support")]
    (t0, static), (_, gripper) = log.scenes
    assert t0 == 0.0 and static[0]["id"] == "support" and static[1]["frame_id"] == "object"
    assert [e["id"] for e in gripper] == ["palm", "finger_left", "finger_right"]
    (cube,) = static[0]["cubes"]
    assert set(cube) == {"pose", "size", "color"} and set(cube["pose"]) == {"position", "orientation"}
    (tri,) = static[1]["triangles"]
    assert set(tri["points"][0]) == {"x", "y", "z"} and len(tri["indices"]) % 3 == 0


def test_trial_bench_prints_both_ratios_for_both_modes(capsys):
    from graspexp.tools.bench.trials import main

    main(["objects=[can]", "trials=1", "--repeats", "0"])
    out = capsys.readouterr().out
    for mode in ("collab", "bin"):
        block = out.split(f"[{mode}]")[1]
        assert "overhead ratio logged" in block and "overhead ratio unlogged" in block
        assert "logging per 30 Hz tick" in block and "execution besides physics" in block
