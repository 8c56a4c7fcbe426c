"""Read trial logs back: the whole trial (:func:`read_trial`), only its result (:func:`read_result`), and
the logs of a run directory (:func:`iter_trial_logs`).

The ``mcap`` library parses the file and checks its magic, record lengths, chunk CRCs and the data-section
CRC; the summary CRC in the footer, which it does not check, is checked here. Every problem with a file (a
``.partial`` file, bad magic, truncation, a CRC mismatch, an undecodable message, a missing result or
metadata record) raises :class:`CorruptLogError` with one line that names the file. Protobuf messages (the
Foxglove topics) are decoded with the schema stored in the file (``mcap-protobuf-support``).

Logs from before the Foxglove SDK (``/tf`` and ``/scene`` as JSON) still give their result to
:func:`read_result` (report, compare, resume); :func:`read_trial` refuses them with
:class:`OldLogFormatError`.
"""

import io
import json
import math
import os
import zlib
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any

import numpy as np
from mcap.exceptions import EndOfFile, InvalidMagic
from mcap.reader import SeekingReader
from mcap.records import Channel, DataEnd, Footer, Message, Metadata, Schema
from mcap.stream_reader import MAGIC_SIZE, CRCValidationError, StreamReader
from mcap.writer import MCAP0_MAGIC
from mcap_protobuf.decoder import DecoderFactory

from graspexp.core.run_layout import trials_dir
from graspexp.record import schemas as S

_FOOTER_TAIL = 4 + MAGIC_SIZE
"""Bytes after the last field the summary CRC covers: the CRC itself and the closing magic."""
_FOOTER_SIZE = 1 + 8 + 8 + 8 + 4
"""A footer record: opcode, length, summary_start, summary_offset_start, summary_crc."""
_DATA_END_SIZE = 1 + 8 + 4
"""A data-end record: opcode, length, data_section_crc."""


class CorruptLogError(ValueError):
    """A trial log that cannot be trusted: unfinished, truncated, corrupt or incomplete."""


class OldLogFormatError(CorruptLogError):
    """A trial log written by an older graspexp (JSON ``/tf`` and ``/scene``): its result reads, the rest not."""


@dataclass
class TrialLog:
    """Everything in one trial log. Times are simulation seconds (log_time / 1e9)."""

    path: Path | None
    """The file read (None when read from a stream without a name)."""
    metadata: dict[str, str]
    """The ``graspexp`` metadata record (resolved config, seeds, versions)."""
    result: dict | None
    """TrialResult.to_dict() with NaN restored; None only with ``require_result=False``."""
    grasp: dict | None
    """PlannedGrasp: pose (4, 4) ndarray world frame, approach (3,) ndarray, width_m, cost, cluster, path,
    planner, K, M, n_feasible, t_s. None when no grasp was logged."""
    phases: list[tuple[float, str, dict | None]]
    """(t_s, name, info), in time order."""
    transforms: dict[str, tuple[np.ndarray, np.ndarray, np.ndarray]]
    """child frame -> (times (T,) s, positions (T, 3) world m, quaternions (T, 4) SAPIEN order w, x, y, z)."""
    contacts: list[tuple[float, list[dict]]]
    """(t_s, contacts): body0, body1, position [3], normal [3], force_n [3] (N, world), separation_m."""
    topics: dict[str, str]
    """topic -> schema name."""
    message_count: int
    scenes: list[tuple[float, list[dict]]] = field(default_factory=list)
    """(t_s, entities) for each /scene message that adds entities: foxglove.SceneEntity as dicts in
    Foxglove's field layout (id, frame_id, timestamp {sec, nsec}, lifetime, frame_locked, metadata,
    cubes [{pose {position, orientation}, size, color}], triangles [{pose, points [{x, y, z}], color,
    colors, indices}])."""
    scene_deletions: list[tuple[float, str]] = field(default_factory=list)
    """(t_s, entity id) for each entity a /scene message deletes (e.g. the support when it is removed)."""
    perception: dict | None = None
    """The /perception message (graspexp.Perception@1) of a trial that rendered the camera, its poses as
    (4, 4) ndarrays; None otherwise."""
    round_result: dict | None = None
    """The /round message (graspexp.RoundResult@1) of a clutter round's log, NaN restored; None otherwise.
    Its ``grasp`` is the last attempt's (every attempt's /grasp is in ``grasps``)."""
    grasps: list[dict] = field(default_factory=list)
    """Every /grasp message in time order (a clutter round plans one per attempt)."""


def _name(source: Any) -> str:
    if isinstance(source, (str, os.PathLike)):
        return str(source)
    return str(getattr(source, "name", "<stream>"))


def _reject_partial(name: str) -> None:
    if name.endswith(S.PARTIAL_SUFFIX):
        raise CorruptLogError(
            f"{name}: unfinished trial log (a {S.PARTIAL_SUFFIX} file: the writer did not finish)"
        )


def _corrupt(name: str, data: bytes, exc: Exception) -> CorruptLogError:
    """One line for a failure of the mcap library on the bytes of ``name``."""
    if isinstance(exc, InvalidMagic):
        return CorruptLogError(f"{name}: not an MCAP file (bad magic)")
    if isinstance(exc, EndOfFile):
        return CorruptLogError(f"{name}: truncated MCAP file ({len(data)} bytes)")
    if isinstance(exc, CRCValidationError):
        return CorruptLogError(f"{name}: corrupt MCAP file ({exc})")
    return CorruptLogError(f"{name}: corrupt MCAP data ({type(exc).__name__}: {exc})")


def _check_summary_crc(data: bytes, footer: Footer, name: str) -> None:
    """The footer's summary CRC (summary section and footer fields), which the mcap library does not check."""
    end = len(data) - _FOOTER_TAIL
    start = footer.summary_start or end - (_FOOTER_SIZE - 4)
    if footer.summary_crc and zlib.crc32(data[start:end]) != footer.summary_crc:
        raise CorruptLogError(f"{name}: corrupt MCAP file (summary CRC mismatch)")


def _records(data: bytes, name: str) -> list:
    """Every record of the file, parsed and CRC-checked (chunks, data section) by the mcap library, plus the
    summary CRC."""
    if not data:
        raise CorruptLogError(f"{name}: empty file")
    try:
        records = list(
            StreamReader(io.BytesIO(data), validate_crcs=True, record_size_limit=len(data)).records
        )
    except Exception as exc:  # any parse failure of the bytes means a malformed file
        raise _corrupt(name, data, exc) from exc
    if not records or not isinstance(records[-1], Footer) or not any(isinstance(r, DataEnd) for r in records):
        raise CorruptLogError(f"{name}: truncated or unfinished MCAP file ({len(data)} bytes, no footer)")
    _check_summary_crc(data, records[-1], name)
    return records


def _result_message(
    data: bytes, name: str, topic: str = S.TOPIC_RESULT
) -> tuple[Channel, str, Message] | None:
    """The last message on ``topic`` (/result, or a round log's /round), its channel and schema name, reading only the chunks that hold /result.

    The mcap library parses the footer, the summary and those chunks (their CRCs); the data-section CRC in the
    DataEnd record before the summary, which its seeking reader does not check, and the summary CRC are
    checked here, so a change anywhere in the file is still caught. None: no /result message.
    """
    if not data:
        raise CorruptLogError(f"{name}: empty file")
    if not data.startswith(MCAP0_MAGIC):
        raise CorruptLogError(f"{name}: not an MCAP file (bad magic)")
    if not data.endswith(MCAP0_MAGIC):
        raise CorruptLogError(
            f"{name}: truncated or unfinished MCAP file ({len(data)} bytes, no closing magic)"
        )
    try:
        stream = io.BytesIO(data)
        stream.seek(-(_FOOTER_SIZE + MAGIC_SIZE), io.SEEK_END)
        footer = next(StreamReader(stream, skip_magic=True, record_size_limit=len(data)).records)
        if not isinstance(footer, Footer) or not _DATA_END_SIZE <= footer.summary_start < len(data):
            raise CorruptLogError(f"{name}: truncated or unfinished MCAP file ({len(data)} bytes, no footer)")
        _check_summary_crc(data, footer, name)
        data_end_at = footer.summary_start - _DATA_END_SIZE
        stream.seek(data_end_at)
        data_end = next(StreamReader(stream, skip_magic=True, record_size_limit=len(data)).records)
        if not isinstance(data_end, DataEnd):
            raise CorruptLogError(f"{name}: corrupt MCAP file (no data-end record before the summary)")
        if data_end.data_section_crc and zlib.crc32(data[:data_end_at]) != data_end.data_section_crc:
            raise CorruptLogError(f"{name}: corrupt MCAP file (data section CRC mismatch)")
        reader = SeekingReader(io.BytesIO(data), validate_crcs=True, record_size_limit=len(data))
        found = list(reader.iter_messages(topics=[topic]))
    except CorruptLogError:
        raise
    except Exception as exc:  # any parse failure of the bytes means a malformed file
        raise _corrupt(name, data, exc) from exc
    if not found:
        return None
    schema, channel, message = found[-1]
    return channel, (schema.name if schema is not None else ""), message


def _read_bytes(source: Path | str | IO[bytes], name: str) -> bytes:
    _reject_partial(name)
    if isinstance(source, (str, os.PathLike)):
        return Path(source).read_bytes()
    return source.read()


class _Log:
    """The schemas, channels and messages of one parsed file."""

    def __init__(self, records: list, name: str):
        self.name = name
        schemas = {r.id: r for r in records if isinstance(r, Schema)}
        self.channels: dict[int, Channel] = {r.id: r for r in records if isinstance(r, Channel)}
        self.schemas: dict[int, Schema | None] = {
            cid: schemas.get(ch.schema_id) for cid, ch in self.channels.items()
        }
        self.topics = {
            ch.topic: (s.name if (s := self.schemas[cid]) else "") for cid, ch in self.channels.items()
        }
        self.metadata = [r for r in records if isinstance(r, Metadata) and r.name == S.METADATA_NAME]
        self.messages = sorted((r for r in records if isinstance(r, Message)), key=lambda m: m.log_time)
        contacts = [ch for ch in self.channels.values() if ch.topic == S.TOPIC_CONTACTS]
        self.bodies = contacts[0].metadata.get("bodies", "").split(",") if contacts else []
        """The /contacts body names, by index (stored with the channel)."""
        self._protobuf = DecoderFactory()
        self._decoders: dict[int, Callable[[bytes], Any]] = {}
        tf = [ch for ch in self.channels.values() if ch.topic == S.TOPIC_TF]
        if tf and tf[0].message_encoding == S.MESSAGE_ENCODING:
            raise OldLogFormatError(
                f"{name}: a trial log in graspexp's older format (JSON /tf and /scene, before the Foxglove "
                "SDK): its result is still read by report, compare and resume; re-run the trial to replay it"
            )

    def decode(self, message: Message) -> tuple[str, Any]:
        """(topic, decoded message) of a message on a known topic; topic "" for other topics."""
        ch = self.channels.get(message.channel_id)
        if ch is None:
            raise CorruptLogError(
                f"{self.name}: corrupt MCAP file (message on unknown channel {message.channel_id})"
            )
        expected = S.TOPIC_SCHEMAS.get(ch.topic)
        if expected is None:
            return "", None
        encoding = S.MESSAGE_ENCODING if expected in S.SCHEMAS else S.PROTOBUF
        schema = self.schemas[ch.id]
        accepted = S.READABLE_RESULTS if expected == S.TRIAL_RESULT else (expected,)
        if ch.message_encoding != encoding or schema is None or schema.name not in accepted:
            raise CorruptLogError(
                f"{self.name}: topic {ch.topic} has encoding {ch.message_encoding!r} / schema "
                f"{self.topics[ch.topic]!r}, expected {encoding!r} / {expected!r}"
            )
        where = f"on {ch.topic} at t={message.log_time / 1e9:.6f} s"
        if encoding == S.MESSAGE_ENCODING:
            try:
                value = json.loads(message.data)
            except (UnicodeDecodeError, json.JSONDecodeError) as exc:
                raise CorruptLogError(f"{self.name}: unreadable JSON {where} ({exc})") from exc
            return ch.topic, S.restore_nan(value, S.SCHEMAS[expected])
        try:
            decoder = self._decoders.get(ch.id)
            if decoder is None:
                decoder = self._decoders[ch.id] = self._protobuf.decoder_for(encoding, schema)
            return ch.topic, decoder(message.data)
        except Exception as exc:  # protobuf's DecodeError and the decoder factory's McapError
            raise CorruptLogError(f"{self.name}: undecodable {expected} message {where} ({exc})") from exc


def _nan(v: Any) -> float:
    return math.nan if v is None else float(v)


def _xyz(v: Any) -> dict[str, float]:
    return {"x": v.x, "y": v.y, "z": v.z}


def _pose(p: Any) -> dict[str, dict[str, float]]:
    q = p.orientation
    return {"position": _xyz(p.position), "orientation": {"x": q.x, "y": q.y, "z": q.z, "w": q.w}}


def _rgba(c: Any) -> dict[str, float]:
    return {"r": c.r, "g": c.g, "b": c.b, "a": c.a}


def _entity(e: Any) -> dict:
    """A protobuf foxglove.SceneEntity as a dict in Foxglove's field layout (the cube and triangle lists)."""
    return {
        "timestamp": {"sec": e.timestamp.seconds, "nsec": e.timestamp.nanos},
        "frame_id": e.frame_id,
        "id": e.id,
        "lifetime": {"sec": e.lifetime.seconds, "nsec": e.lifetime.nanos},
        "frame_locked": e.frame_locked,
        "metadata": [{"key": kv.key, "value": kv.value} for kv in e.metadata],
        "cubes": [{"pose": _pose(c.pose), "size": _xyz(c.size), "color": _rgba(c.color)} for c in e.cubes],
        "triangles": [
            {
                "pose": _pose(t.pose),
                "points": [_xyz(p) for p in t.points],
                "color": _rgba(t.color),
                "colors": [_rgba(c) for c in t.colors],
                "indices": list(t.indices),
            }
            for t in e.triangles
        ],
    }


_CONTACT_DTYPE = np.dtype(
    {
        "names": [*S.CONTACT_FLOATS, *S.CONTACT_BODIES],
        "formats": ["<f4"] * len(S.CONTACT_FLOATS) + ["u1"] * len(S.CONTACT_BODIES),
        "itemsize": S.CONTACT_STRIDE,
    }
)


def _contacts(cloud: Any, bodies: list[str]) -> list[dict]:
    """A /contacts foxglove.PointCloud as dicts: body0, body1, position [3], normal [3], force_n [3], separation_m."""
    names = [f.name for f in cloud.fields]
    if cloud.point_stride != S.CONTACT_STRIDE or names != list(_CONTACT_DTYPE.names):
        raise ValueError(f"contact layout {names} / stride {cloud.point_stride} is not graspexp's")
    rows = np.frombuffer(cloud.data, dtype=_CONTACT_DTYPE)
    floats = np.stack([rows[n] for n in S.CONTACT_FLOATS], axis=1).astype(float).tolist()
    return [
        {
            "body0": bodies[b0],
            "body1": bodies[b1],
            "position": f[0:3],
            "normal": f[3:6],
            "force_n": f[6:9],
            "separation_m": f[9],
        }
        for f, b0, b1 in zip(floats, rows["body0"].tolist(), rows["body1"].tolist(), strict=True)
    ]


def read_trial(source: Path | str | IO[bytes], *, require_result: bool = True) -> TrialLog:
    """Read a whole trial log from a path or a binary stream (e.g. io.BytesIO).

    Raises CorruptLogError for a ``.partial``, truncated or corrupt file, an undecodable message, a
    missing ``graspexp`` metadata record, or (with ``require_result``) a missing /result message;
    OldLogFormatError (a CorruptLogError) for a log in the older JSON format.
    """
    name = _name(source)
    data = _read_bytes(source, name)
    path = (
        Path(source)
        if isinstance(source, (str, os.PathLike))
        else (Path(name) if hasattr(source, "name") else None)
    )
    parsed = _Log(_records(data, name), name)
    if not parsed.metadata:
        raise CorruptLogError(f"{name}: no '{S.METADATA_NAME}' metadata record (not a graspexp trial log)")
    log = TrialLog(
        path=path,
        metadata=dict(parsed.metadata[-1].metadata),
        result=None,
        grasp=None,
        phases=[],
        transforms={},
        contacts=[],
        topics=parsed.topics,
        message_count=len(parsed.messages),
    )
    tf: dict[str, list[list[float]]] = {}
    for m in parsed.messages:
        topic, msg = parsed.decode(m)
        t_s = m.log_time / 1e9
        try:
            if topic == S.TOPIC_TF:
                for f in msg.transforms:
                    tr, rot = f.translation, f.rotation
                    tf.setdefault(f.child_frame_id, []).append(
                        [t_s, tr.x, tr.y, tr.z, rot.w, rot.x, rot.y, rot.z]
                    )
            elif topic == S.TOPIC_CONTACTS:
                log.contacts.append((t_s, _contacts(msg, parsed.bodies)))
            elif topic == S.TOPIC_PHASE:
                log.phases.append((t_s, str(msg["name"]), msg.get("info")))
            elif topic == S.TOPIC_GRASP:
                grasp = {k: v for k, v in msg.items() if k != "timestamp"}
                grasp["pose"] = np.array([[_nan(v) for v in row] for row in grasp["pose"]], dtype=float)
                grasp["approach"] = np.array([_nan(v) for v in grasp["approach"]], dtype=float)
                grasp["t_s"] = t_s
                log.grasp = grasp
                log.grasps.append(grasp)
            elif topic == S.TOPIC_RESULT:
                if not isinstance(msg, dict) or "success" not in msg:
                    raise ValueError("result lacks 'success'")
                log.result = msg
            elif topic == S.TOPIC_ROUND:
                if not isinstance(msg, dict) or "attempts" not in msg:
                    raise ValueError("round result lacks 'attempts'")
                log.round_result = msg
            elif topic == S.TOPIC_PERCEPTION:
                log.perception = {
                    k: np.array(v, dtype=float) if k.endswith("_pose") else v
                    for k, v in msg.items()
                    if k != "timestamp"
                }
            elif topic == S.TOPIC_SCENE:
                log.scene_deletions.extend((t_s, d.id) for d in msg.deletions)
                if msg.entities:
                    log.scenes.append((t_s, [_entity(e) for e in msg.entities]))
        except (KeyError, TypeError, ValueError, IndexError, AttributeError) as exc:
            raise CorruptLogError(
                f"{name}: malformed {S.TOPIC_SCHEMAS[topic]} message on {topic} at t={t_s:.6f} s ({exc!r})"
            ) from exc
    for frame, rows in tf.items():
        arr = np.asarray(rows, dtype=float).reshape(-1, 8)
        log.transforms[frame] = (arr[:, 0].copy(), arr[:, 1:4].copy(), arr[:, 4:8].copy())
    if require_result and log.result is None and log.round_result is None:
        raise CorruptLogError(f"{name}: no /result message (the trial did not finish)")
    return log


def read_result(path: Path | str) -> dict:
    """Only the /result message (TrialResult.to_dict() with NaN restored): the fast path for reports.

    The whole file is CRC-checked as in :func:`read_trial`, but only the chunk holding /result is
    decompressed and parsed. Logs in the older JSON format are read too (their /result is unchanged).
    """
    name = str(path)
    found = _result_message(_read_bytes(path, name), name)
    if found is None:
        raise CorruptLogError(f"{name}: no /result message (the trial did not finish)")
    channel, schema_name, message = found
    if schema_name not in S.READABLE_RESULTS or channel.message_encoding != S.MESSAGE_ENCODING:
        raise CorruptLogError(f"{name}: /result has schema {schema_name!r}, expected {S.TRIAL_RESULT!r}")
    try:
        result = S.restore_nan(json.loads(message.data), S.SCHEMAS[S.TRIAL_RESULT])
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise CorruptLogError(f"{name}: unreadable JSON on /result ({exc})") from exc
    if not isinstance(result, dict) or "success" not in result:
        raise CorruptLogError(f"{name}: malformed {S.TRIAL_RESULT} message on /result")
    return result


def read_round(path: Path | str) -> dict:
    """Only the /round message of a clutter round's log (``RoundResult.to_dict()``, NaN restored), as
    :func:`read_result` reads /result."""
    name = str(path)
    found = _result_message(_read_bytes(path, name), name, S.TOPIC_ROUND)
    if found is None:
        raise CorruptLogError(f"{name}: no /round message (the round did not finish)")
    channel, schema_name, message = found
    if schema_name != S.ROUND_RESULT or channel.message_encoding != S.MESSAGE_ENCODING:
        raise CorruptLogError(f"{name}: /round has schema {schema_name!r}, expected {S.ROUND_RESULT!r}")
    try:
        result = S.restore_nan(json.loads(message.data), S.SCHEMAS[S.ROUND_RESULT])
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise CorruptLogError(f"{name}: unreadable JSON on /round ({exc})") from exc
    if not isinstance(result, dict):
        raise CorruptLogError(f"{name}: malformed {S.ROUND_RESULT} message on /round")
    return result


def read_metadata(path: Path | str) -> dict[str, str] | None:
    """A log's ``graspexp`` metadata record (config, seeds, mesh, versions), None when it has none;
    :class:`CorruptLogError` when the file's metadata cannot be read. Reads the summary's metadata index
    only: the fast path beside :func:`read_result`."""
    name = str(path)
    with open(path, "rb") as f:  # an unreadable file is an OSError
        try:
            for record in SeekingReader(f).iter_metadata():
                if record.name == S.METADATA_NAME:
                    return dict(record.metadata)
        except Exception as exc:  # any parse failure of the file (a seek before its start included)
            raise CorruptLogError(f"{name}: unreadable metadata ({type(exc).__name__}: {exc})") from exc
    return None


def read_config_yaml(path: Path | str) -> str | None:
    """The job config recorded in a log's metadata (YAML text; :func:`read_metadata`), None without one."""
    return (read_metadata(path) or {}).get("config_yaml")


def _trial_sort_key(p: Path) -> tuple:
    stem = p.stem
    return (p.parent.name, 0, int(stem), "") if stem.isdigit() else (p.parent.name, 1, 0, stem)


def iter_trial_logs(run_dir: Path | str) -> Iterator[Path]:
    """Finished logs ``<run_dir>/trials/<object>/<index>.mcap``, by object then numeric index.

    ``.partial`` files (unfinished trials) are skipped.
    """
    trials = trials_dir(run_dir)
    paths = [p for p in trials.glob("*/*.mcap") if p.is_file() and not p.name.endswith(S.PARTIAL_SUFFIX)]
    yield from sorted(paths, key=_trial_sort_key)
