"""Live view: the SDK's WebSocket server on loopback streams what the trial logs (client bounded in time)."""

import asyncio
import base64
import json
import struct

import pytest
import websockets
from mcap.records import Schema
from mcap_protobuf.decoder import DecoderFactory

from graspexp.config.compose import compose_config
from graspexp.record import trial_recorder
from graspexp.record.live import live_port, stop_live
from graspexp.sim.trial import NullRecorder, plain_config

TIMEOUT_S = 20.0
MESSAGE_DATA = 1
"""Binary opcode of a message on a subscribed channel (Foxglove WebSocket protocol)."""


async def _first_tf(port: int, recorder) -> tuple[int, object]:
    """Connect, subscribe to /tf, log transforms until one arrives; (log time ns, decoded message)."""
    url = f"ws://127.0.0.1:{port}"
    async with websockets.connect(url, subprotocols=["foxglove.sdk.v1", "foxglove.websocket.v1"]) as ws:
        advertised: dict[str, dict] = {}
        while "/tf" not in advertised:
            msg = await ws.recv()
            if isinstance(msg, str) and json.loads(msg)["op"] == "advertise":
                advertised.update({c["topic"]: c for c in json.loads(msg)["channels"]})
        tf = advertised["/tf"]
        assert tf["schemaName"] == "foxglove.FrameTransforms" and tf["encoding"] == "protobuf"
        await ws.send(json.dumps({"op": "subscribe", "subscriptions": [{"id": 7, "channelId": tf["id"]}]}))
        schema = Schema(id=1, name=tf["schemaName"], encoding="protobuf", data=base64.b64decode(tf["schema"]))
        decode = DecoderFactory().decoder_for("protobuf", schema)
        for i in range(10_000):
            recorder.transforms(0.01 * i, {"object": ((0.0, 0.0, 0.1), (1.0, 0.0, 0.0, 0.0))})
            try:
                data = await asyncio.wait_for(ws.recv(), 0.02)
            except TimeoutError:
                continue
            if isinstance(data, bytes) and data[0] == MESSAGE_DATA:
                sub, log_time = struct.unpack_from("<IQ", data, 1)
                assert sub == 7
                return log_time, decode(data[13:])
    raise AssertionError("no /tf message received")


def test_live_view_streams_tf_to_a_loopback_client():
    cfg = plain_config(compose_config(["live=true", "live_port=0"]))
    recorder = trial_recorder(None, {"object": "can"}, cfg)  # live only: no file
    try:
        with recorder as rec:
            log_time, msg = asyncio.run(asyncio.wait_for(_first_tf(live_port(0), rec), TIMEOUT_S))
    finally:
        stop_live(0)
    (tf,) = msg.transforms
    assert tf.child_frame_id == "object" and tf.parent_frame_id == "world"
    assert tf.translation.z == 0.1 and tf.timestamp.ToNanoseconds() == log_time


def test_live_off_by_default_starts_nothing():
    cfg = plain_config(compose_config([]))
    assert cfg.live is False
    with trial_recorder(None, {}, cfg) as rec:
        assert isinstance(rec, NullRecorder)


def test_a_clutter_round_streams_live_with_its_own_body_names():
    """The live server serves a trial, then a clutter round (one /contacts body per object), then a trial
    again: each log's contacts are named by its own bodies, in the live channel's metadata too."""
    from graspexp.record.live import live_channels
    from graspexp.record.scene import round_bodies

    cfg = plain_config(compose_config(["mode=pile", "live=true", "live_port=0"]))
    contact = {
        "body0": "object_2",
        "body1": "tray",
        "position": (0, 0, 0),
        "normal": (0, 0, 1),
        "force_n": 1.0,
    }
    try:
        with trial_recorder(None, {}, cfg) as rec:  # a single-object trial: no object_2
            with pytest.raises(ValueError, match="'object_2' is not one of"):
                rec.contacts(0.0, [contact])
        with trial_recorder(None, {}, cfg, round_bodies(3)) as rec:
            rec.contacts(0.0, [contact])
        assert live_channels(0).contacts.metadata()["bodies"] == ",".join(round_bodies(3))
        with trial_recorder(None, {}, cfg) as rec:
            assert live_channels(0).contacts.metadata()["bodies"].split(",")[0] == "object"
    finally:
        stop_live(0)
