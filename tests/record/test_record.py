"""MCAP trial logs: writer/reader round trip, determinism, atomic files, corruption, replay CLI."""

import io
import json
import math
import subprocess
import sys
import types
from pathlib import Path

import numpy as np
import pytest
from helpers.cli import graspexp
from helpers.logs import strictly_valid
from mcap.reader import make_reader
from mcap_protobuf.decoder import DecoderFactory

from graspexp.core.geometry import axis_angle_matrix, matrix_to_quat_wxyz
from graspexp.core.outcome import FailureReason, TrialResult
from graspexp.record import (
    CorruptLogError,
    OldLogFormatError,
    TrialRecorder,
    TrialWriter,
    iter_trial_logs,
    read_result,
    read_trial,
)
from graspexp.record import schemas as S
from graspexp.record.scene import box_entity, mesh_entity

METADATA = {"config": "planner:\n  name: paper\n", "seed": "7", "versions": "graspexp=0.1.0"}
RATE_HZ = 30
DURATION_S = 5.0
# A rotation of 90 degrees about +z: SAPIEN (w, x, y, z) = (cos 45, 0, 0, sin 45).
QUAT_Z90_WXYZ = (math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5))


def _icosphere_like(n_faces: int) -> tuple[np.ndarray, np.ndarray]:
    """A deterministic closed-ish triangle soup with ``n_faces`` faces."""
    rng = np.random.default_rng(0)
    v = rng.normal(size=(n_faces // 2 + 2, 3))
    v = 0.05 * v / np.linalg.norm(v, axis=1, keepdims=True)
    f = np.stack(
        [np.arange(n_faces) % len(v), (np.arange(n_faces) + 1) % len(v), (np.arange(n_faces) + 2) % len(v)], 1
    )
    return v, f


def _result(**overrides) -> dict:
    base = TrialResult(
        dataset="procedural",
        object="box_a",
        mode="table",
        rot="upright",
        planner="paper",
        trial=3,
        seed=7,
        success=False,
        reason=FailureReason.SLIPPED.value,
        grasp_cost=0.25,
        finger_force_n=[12.5, float("nan")],
        timings_s={"plan": 0.5, "settle": float("nan")},
        sim_time_s=DURATION_S,
        steps=int(DURATION_S * 240),
    ).to_dict()
    base.update(overrides)
    return base


def write_typical_trial(writer: TrialWriter, n_faces: int = 500) -> None:
    """30 Hz x 5 s of 4 frames + contacts, one mesh and two boxes, phases, a grasp and the result."""
    v, f = _icosphere_like(n_faces)
    writer.scene(
        0.0,
        [
            mesh_entity("object", "object", v, f, (0.8, 0.3, 0.2, 1.0)),
            box_entity("table", "world", (0, 0, -0.01), (1.0, 1.0, 0.02), (0.5, 0.5, 0.5, 1.0)),
            box_entity("finger_left", "finger_left", (0, 0, 0), (0.01, 0.02, 0.04), (0.2, 0.2, 0.9, 1.0)),
        ],
    )
    phases = {
        0.0: "drop",
        1.0: "settled",
        1.1: "plan",
        1.5: "approach",
        2.5: "close",
        3.0: "hold",
        4.9: "done",
    }
    writer.phase(0.0, "drop", {"height_m": 0.1})
    for i in range(int(RATE_HZ * DURATION_S)):
        t = i / RATE_HZ
        for t_phase, name in phases.items():
            if t_phase > 0 and abs(t - t_phase) < 0.5 / RATE_HZ:
                writer.phase(t, name, {"step": i} if name != "done" else None)
        if abs(t - 1.1) < 0.5 / RATE_HZ:
            pose = np.eye(4)
            pose[:3, 3] = (0.1, 0.0, 0.2)
            writer.grasp(
                t,
                {
                    "pose": pose,
                    "approach": (0, 0, -1),
                    "width_m": 0.04,
                    "cost": float("nan"),
                    "cluster": 2,
                    "path": 5,
                    "planner": "paper",
                    "K": 8,
                    "M": 16,
                    "n_feasible": 11,
                },
            )
        writer.transforms(
            t,
            {
                "object": ((0.0, 0.0, 0.05 + 0.001 * i), QUAT_Z90_WXYZ),
                "gripper": ((0.1, 0.0, 0.3 - 0.0005 * i), (1.0, 0.0, 0.0, 0.0)),
                "finger_left": ((0.1, 0.02, 0.25), (1.0, 0.0, 0.0, 0.0)),
                "finger_right": ((0.1, -0.02, 0.25), (1.0, 0.0, 0.0, 0.0)),
            },
        )
        contacts = [
            {
                "body0": "object",
                "body1": "support",
                "position": (0, 0, 0),
                "normal": (0, 0, 1),
                "force_n": (0.0, 0.0, 2.0),
                "separation_m": -1e-4,
            },
        ]
        if t >= 2.5:
            contacts += [
                {
                    "body0": "object",
                    "body1": "finger_left",
                    "position": (0.1, 0.02, 0.05),
                    "normal": (0, 1, 0),
                    "force_n": 10.0 + i * 0.01,
                },
                {
                    "body0": "finger_right",
                    "body1": "object",
                    "position": (0.1, -0.02, 0.05),
                    "normal": (0, -1, 0),
                    "force_n": (0.0, -9.0, 0.0),
                    "separation_m": 0.0,
                },
            ]
        writer.contacts(t, contacts)
    writer.result(DURATION_S, _result())


def _write_bytes(**kw) -> bytes:
    buf = io.BytesIO()
    w = TrialWriter(buf, METADATA)
    write_typical_trial(w, **kw)
    w.finish()
    return buf.getvalue()


@pytest.fixture(scope="module")
def trial_file(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("run") / "trials" / "box_a" / "3.mcap"
    with TrialRecorder(path, METADATA) as rec:
        write_typical_trial(rec)
    return path


def test_round_trip_file(trial_file):
    log = read_trial(trial_file)
    assert log.path == trial_file
    assert log.metadata == METADATA
    assert log.topics == {
        "/scene": "foxglove.SceneUpdate",
        "/tf": "foxglove.FrameTransforms",
        "/grasp_pose": "foxglove.PoseInFrame",
        "/contacts": "foxglove.PointCloud",
        "/grasp": "graspexp.PlannedGrasp@1",
        "/phase": "graspexp.Phase@1",
        "/result": "graspexp.TrialResult@5",
    }
    n = int(RATE_HZ * DURATION_S)
    assert sorted(log.transforms) == ["finger_left", "finger_right", "gripper", "object"]
    times, pos, quat = log.transforms["object"]
    assert times.shape == (n,) and pos.shape == (n, 3) and quat.shape == (n, 4)
    np.testing.assert_allclose(times, np.arange(n) / RATE_HZ, atol=1e-9)
    np.testing.assert_allclose(pos[:, 2], 0.05 + 0.001 * np.arange(n))
    np.testing.assert_allclose(quat, np.tile(QUAT_Z90_WXYZ, (n, 1)))
    assert [name for _, name, _ in log.phases] == [
        "drop",
        "settled",
        "plan",
        "approach",
        "close",
        "hold",
        "done",
    ]
    assert log.phases[0][2] == {"height_m": 0.1} and log.phases[-1][2] is None
    assert len(log.contacts) == n
    t_close, contacts = log.contacts[-1]
    scalar = contacts[1]
    np.testing.assert_allclose(scalar["force_n"], [0.0, 10.0 + (n - 1) * 0.01, 0.0])  # scalar along normal
    assert scalar["separation_m"] == 0.0
    g = log.grasp
    assert g is not None and g["pose"].shape == (4, 4) and math.isnan(g["cost"])
    assert (g["K"], g["M"], g["n_feasible"], g["cluster"], g["path"]) == (8, 16, 11, 2, 5)
    np.testing.assert_allclose(g["approach"], [0, 0, -1])
    assert log.message_count == 1 + 7 + 2 + n + n + 1  # scene, phases, grasp + pose, tf, contacts, result
    assert len(log.scenes) == 1 and len(log.scenes[0][1]) == 3


def test_round_trip_stream_matches_file(trial_file):
    data = _write_bytes()
    assert data == trial_file.read_bytes()
    log = read_trial(io.BytesIO(data))
    assert log.path is None and log.metadata == METADATA and log.result == read_result(trial_file)


def test_nan_round_trip(trial_file):
    result = read_result(trial_file)
    expected = _result()
    assert math.isnan(result["grasp_width_m"]) and math.isnan(result["slip_m"])
    assert result["finger_force_n"][0] == 12.5 and math.isnan(result["finger_force_n"][1])
    assert result["timings_s"]["plan"] == 0.5 and math.isnan(result["timings_s"]["settle"])
    assert result["reason"] == "slipped" and result["error"] == ""
    assert set(result) == set(expected)
    back = TrialResult.from_dict(result)
    assert back.trial == 3 and back.success is False


def test_success_reason_null_stays_none(tmp_path):
    path = tmp_path / "0.mcap"
    with TrialRecorder(path, {}) as rec:
        rec.result(1.0, _result(success=True, reason=None, slip_m=float("inf")))
    res = read_result(path)
    assert res["reason"] is None and res["success"] is True
    assert math.isnan(res["slip_m"])  # +-inf is stored as null too and reads back as NaN


def test_log_times_are_sim_time_ns(trial_file):
    with open(trial_file, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        for _, _channel, message, body in reader.iter_decoded_messages(topics=["/tf"]):
            assert message.log_time == message.publish_time
            assert all(t.timestamp.ToNanoseconds() == message.log_time for t in body.transforms)
        summary = reader.get_summary()
    assert summary.statistics.message_end_time == 5_000_000_000
    assert summary.statistics.message_start_time == 0
    # 0.1 s -> exactly 100_000_000 ns (rounded, not truncated)
    buf = io.BytesIO()
    w = TrialWriter(buf, {})
    w.phase(0.1, "drop")
    w.phase(1 / 3, "settled")
    w.result(0.7, _result())
    w.finish()
    with pytest.raises(ValueError, match="t_s"):
        TrialWriter(io.BytesIO(), {}).phase(-1.0, "drop")
    buf.seek(0)
    times = [m.log_time for _, _, m in make_reader(buf).iter_messages()]
    assert times == [100_000_000, 333_333_333, 700_000_000]


def test_quaternion_order_converted(trial_file):
    q_wxyz = matrix_to_quat_wxyz(axis_angle_matrix(np.array([0.0, 0.0, 1.0]), math.pi / 2))
    np.testing.assert_allclose(q_wxyz, QUAT_Z90_WXYZ, atol=1e-12)
    with open(trial_file, "rb") as f:
        reader = make_reader(f, decoder_factories=[DecoderFactory()])
        _, _, _, body = next(reader.iter_decoded_messages(topics=["/tf"]))
    (tf,) = [t for t in body.transforms if t.child_frame_id == "object"]
    rot = tf.rotation
    np.testing.assert_allclose([rot.x, rot.y, rot.z, rot.w], [0, 0, math.sqrt(0.5), math.sqrt(0.5)])
    assert tf.parent_frame_id == "world"


def test_every_message_valid_for_independent_readers(trial_file):
    with open(trial_file, "rb") as f:
        counts = strictly_valid(f)
        f.seek(0)
        reader = make_reader(f)
        summary = reader.get_summary()
        metadata = list(reader.iter_metadata())
    assert counts["/tf"] == RATE_HZ * DURATION_S and counts["/result"] == 1 and counts["/grasp_pose"] == 1
    assert [m.name for m in metadata] == ["graspexp"] and metadata[0].metadata == METADATA
    names = sorted(s.name for s in summary.schemas.values())
    no_camera = {n for t, n in S.TOPIC_SCHEMAS.items() if t not in S.CAMERA_TOPICS + S.LAZY_TOPICS}
    assert names == sorted(no_camera)  # each schema registered once; no camera channel without a camera
    assert all(c.compression == "lz4" for c in summary.chunk_indexes)


def test_scene_entities_follow_foxglove_layout(trial_file):
    log = read_trial(trial_file)
    mesh, table, _ = log.scenes[0][1]
    assert (
        mesh["frame_locked"] is True
        and mesh["frame_id"] == "object"
        and mesh["timestamp"] == {"sec": 0, "nsec": 0}
    )
    (tri,) = mesh["triangles"]
    assert len(tri["indices"]) == 3 * 500 and set(tri["points"][0]) == {"x", "y", "z"}
    assert max(tri["indices"]) == len(tri["points"]) - 1  # vertices stored once, triangles by index
    assert tri["color"] == {"r": 0.8, "g": 0.3, "b": 0.2, "a": 1.0}
    assert tri["pose"]["orientation"] == {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}
    # compact: rounded to 1 um
    assert all(round(p["x"], 6) == p["x"] for p in tri["points"])
    (cube,) = table["cubes"]
    assert cube["size"] == {"x": 1.0, "y": 1.0, "z": 0.02}
    assert cube["pose"]["orientation"] == {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0}


def test_result_schema_pinned():
    """Changing TrialResult's fields must come with a new graspexp.TrialResult@N version."""
    assert S.TRIAL_RESULT == "graspexp.TrialResult@5"
    assert list(S.SCHEMAS[S.TRIAL_RESULT]["properties"]) == [
        "dataset",
        "object",
        "mode",
        "rot",
        "planner",
        "trial",
        "seed",
        "success",
        "reason",
        "redrops",
        "error",
        "grasp_cost",
        "grasp_width_m",
        "n_feasible",
        "fc_min_mu",
        "slip_m",
        "finger_force_n",
        "touched_support",
        "timings_s",
        "sim_time_s",
        "steps",
        "at_rest",
        "pose_trans_err_mm",
        "pose_rot_err_deg",
        "pose_adds_mm",
        "registration_fitness",
        "registration_cpu_s",
        "detail",
    ]


def test_deterministic_bytes():
    assert _write_bytes() == _write_bytes()


def test_partial_never_left_at_final_name(tmp_path):
    path = tmp_path / "trials" / "box_a" / "0.mcap"
    path.parent.mkdir(parents=True)
    path.write_bytes(b"stale log from an earlier run")
    with pytest.raises(RuntimeError, match="boom"):
        with TrialRecorder(path, METADATA) as rec:
            rec.phase(0.0, "drop")
            assert rec.partial_path.exists() and not path.exists()
            raise RuntimeError("boom")
    assert not path.exists()
    assert not rec.partial_path.exists()
    assert list(path.parent.iterdir()) == []


def test_close_without_result_discards(tmp_path):
    path = tmp_path / "0.mcap"
    with pytest.raises(RuntimeError, match="without a /result"):
        with TrialRecorder(path, METADATA) as rec:
            rec.phase(0.0, "drop")
    assert list(tmp_path.iterdir()) == []


def test_partial_file_rejected(trial_file, tmp_path):
    partial = tmp_path / "3.mcap.partial"
    partial.write_bytes(trial_file.read_bytes())
    with pytest.raises(CorruptLogError, match=r"3\.mcap\.partial.*unfinished"):
        read_trial(partial)
    with pytest.raises(CorruptLogError, match="unfinished"):
        read_result(partial)


def test_every_truncation_is_corrupt(trial_file, tmp_path):
    data = trial_file.read_bytes()
    bad = tmp_path / "cut.mcap"
    offsets = sorted(
        {0, 1, 7, 8, 9, 20, 100, len(data) // 3, len(data) // 2, len(data) - 38, len(data) - 37}
        | set(range(len(data) - 60, len(data)))
    )
    for n in offsets:
        bad.write_bytes(data[:n])
        for fn in (read_trial, read_result):
            with pytest.raises(CorruptLogError) as info:
                fn(bad)
            assert str(info.value).startswith(str(bad)), (n, str(info.value))
            assert "\n" not in str(info.value)


def _small_log() -> bytes:
    buf = io.BytesIO()
    w = TrialWriter(buf, METADATA)
    w.scene(0.0, [box_entity("table", "world", (0, 0, 0), (1, 1, 0.02), (1, 1, 1, 1))])
    w.transforms(0.0, {"object": ((0, 0, 0.1), QUAT_Z90_WXYZ)})
    w.contacts(
        0.0,
        [{"body0": "object", "body1": "support", "position": (0, 0, 0), "normal": (0, 0, 1), "force_n": 1.0}],
    )
    w.result(0.5, _result())
    w.finish()
    return buf.getvalue()


def _offsets(size: int) -> list[int]:
    """Every offset in the header and the summary/footer end, a stride of 7 through the chunks."""
    return sorted(set(range(0, 200)) | set(range(200, size - 600, 7)) | set(range(max(size - 600, 0), size)))


@pytest.mark.slow
def test_truncations_of_a_small_log_are_corrupt(tmp_path):
    data = _small_log()
    bad = tmp_path / "cut.mcap"
    for n in _offsets(len(data)):
        bad.write_bytes(data[:n])
        for fn in (read_trial, read_result):
            with pytest.raises(CorruptLogError, match=str(bad)):
                fn(bad)


@pytest.mark.slow
def test_byte_flips_are_corrupt(tmp_path):
    data = _small_log()
    bad = tmp_path / "flip.mcap"
    for i in _offsets(len(data)):
        flipped = bytearray(data)
        flipped[i] ^= 0x5A
        bad.write_bytes(bytes(flipped))
        for fn in (read_trial, read_result):
            with pytest.raises(CorruptLogError, match=str(bad)):
                fn(bad)


def test_unreadable_json_and_missing_result(tmp_path):
    buf = io.BytesIO()
    w = TrialWriter(buf, METADATA)
    w.phase(0.0, "drop")
    w._ch.json[S.TOPIC_PHASE].log(b"{not json", log_time=1)
    w.finish()
    bad = tmp_path / "badjson.mcap"
    bad.write_bytes(buf.getvalue())
    with pytest.raises(CorruptLogError, match=r"badjson\.mcap: unreadable JSON on /phase"):
        read_trial(bad)

    buf = io.BytesIO()
    w = TrialWriter(buf, METADATA)
    w.phase(0.0, "drop")
    w.finish()
    nores = tmp_path / "nores.mcap"
    nores.write_bytes(buf.getvalue())
    with pytest.raises(CorruptLogError, match=r"nores\.mcap: no /result message"):
        read_trial(nores)
    with pytest.raises(CorruptLogError, match=r"nores\.mcap: no /result message"):
        read_result(nores)
    assert read_trial(nores, require_result=False).result is None

    notmcap = tmp_path / "x.mcap"
    notmcap.write_bytes(b"PK\x03\x04" + bytes(100))
    with pytest.raises(CorruptLogError, match=r"x\.mcap: not an MCAP file \(bad magic\)"):
        read_trial(notmcap)


def test_iter_trial_logs(tmp_path):
    for obj, idx in [("b", 10), ("b", 2), ("a", 0), ("b", 1)]:
        p = tmp_path / "trials" / obj / f"{idx}.mcap"
        p.parent.mkdir(parents=True, exist_ok=True)
        p.write_bytes(b"")
    (tmp_path / "trials" / "a" / "1.mcap.partial").write_bytes(b"")
    got = [(p.parent.name, p.name) for p in iter_trial_logs(tmp_path)]
    assert got == [("a", "0.mcap"), ("b", "1.mcap"), ("b", "2.mcap"), ("b", "10.mcap")]


def _replay(*args: str) -> subprocess.CompletedProcess:
    return graspexp("replay", *args, timeout=120)


def test_replay_prints_timeline(trial_file):
    proc = _replay(str(trial_file))
    assert proc.returncode == 0, proc.stderr
    out = proc.stdout
    assert "object=box_a" in out and "mode=table" in out and "seed=7" in out and "planner=paper" in out
    for name in ("drop", "settled", "plan", "approach", "close", "hold", "done"):
        assert any(line.split()[1:2] == [name] for line in out.splitlines() if line.startswith("  "))
    assert "   2.500  close" in out
    assert "finger force N min/med/max: finger_left 10.8/10.8/10.9; finger_right 9/9/9" in out
    assert out.count("finger force N") == 3  # close, hold, done; no line for phases without finger contact
    assert "outcome: FAILED (slipped)" in out


def test_replay_corrupt_file_exit_2(trial_file, tmp_path):
    bad = tmp_path / "bad.mcap"
    bad.write_bytes(trial_file.read_bytes()[:-100])
    proc = _replay(str(bad))
    assert proc.returncode == 2
    assert proc.stdout == ""
    lines = proc.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"graspexp replay: error: {bad}")
    proc = _replay(str(tmp_path / "missing.mcap"))
    assert proc.returncode == 2 and len(proc.stderr.splitlines()) == 1 and "missing.mcap" in proc.stderr


def test_replay_resim_delegates(trial_file, monkeypatch, capsys):
    from graspexp.tools import replay

    seen = []

    def fake_resimulate(log):
        seen.append(log)
        return log.result["trial"] == 3, "final object pose within 1 mm of the log"

    fake = types.ModuleType("graspexp.run.resim")
    fake.resimulate = fake_resimulate
    monkeypatch.setitem(sys.modules, "graspexp.run.resim", fake)
    assert replay.main([str(trial_file), "--resim"]) == 0
    assert seen and seen[0].path == trial_file
    assert "resim: agrees: final object pose within 1 mm" in capsys.readouterr().out
    fake.resimulate = lambda log: (False, "object dropped in resim at t=3.2 s")
    assert replay.main([str(trial_file), "--resim"]) == 1
    assert "resim: DISAGREES: object dropped" in capsys.readouterr().out
    assert replay.main([str(trial_file)]) == 0  # without the flag, resim is never imported


def test_old_json_format_log_result_reads_and_trial_is_refused_in_one_line(tmp_path):
    """A log of the format before the Foxglove SDK (JSON /tf): report/compare/resume read its result; replay
    refuses it with one line naming the older format."""
    from mcap.writer import Writer

    path = tmp_path / "old.mcap"
    with open(path, "wb") as f:
        w = Writer(f)
        w.start(profile="", library="graspexp; mcap")
        w.add_metadata(S.METADATA_NAME, METADATA)
        tf_schema = w.register_schema("foxglove.FrameTransform", "jsonschema", b'{"type":"object"}')
        tf = w.register_channel("/tf", "json", tf_schema)
        result_schema = w.register_schema(S.TRIAL_RESULT, "jsonschema", S.schema_bytes(S.TRIAL_RESULT))
        result = w.register_channel("/result", "json", result_schema)
        w.add_message(tf, log_time=0, publish_time=0, data=b'{"child_frame_id":"object"}')
        w.add_message(result, log_time=1, publish_time=1, data=json.dumps(_result()).encode())
        w.finish()
    assert read_result(path)["reason"] == "slipped"
    with pytest.raises(OldLogFormatError, match=r"old\.mcap: .*older format") as info:
        read_trial(path)
    assert "\n" not in str(info.value)
    proc = _replay(str(path))
    assert proc.returncode == 2 and len(proc.stderr.splitlines()) == 1 and "older format" in proc.stderr


def test_foxglove_layout_shows_the_logged_topics():
    """The saved layout names only panels it defines and topics a trial log has."""
    layout = json.loads((Path(S.__file__).parent / "foxglove_layout.json").read_text())

    def leaves(node):
        return [node] if isinstance(node, str) else leaves(node["first"]) + leaves(node["second"])

    panels = leaves(layout["layout"])
    assert sorted(panels) == sorted(layout["configById"])
    used = set(layout["configById"]["3D!graspexp"]["topics"])
    for panel in panels:
        cfg = layout["configById"][panel]
        used |= {cfg["topicPath"]} if "topicPath" in cfg else set()
        used |= {p["value"].split(".")[0] for p in cfg.get("paths", [])}
    assert used == {"/scene", "/contacts", "/grasp_pose", "/phase", "/result", "/grasp"}
    assert used <= set(S.TOPIC_SCHEMAS)
