"""Read trial logs back: the whole trial (:func:`read_trial`), only its result (:func:`read_result`), and
the logs of a run directory (:func:`iter_trial_logs`).

Every problem with a file (a ``.partial`` file, bad magic, truncation, a CRC mismatch, unreadable JSON, a
missing result or metadata record) raises :class:`CorruptLogError` with one message that names the file.
Before any record is parsed, the file envelope is checked: magic at both ends, the footer, the summary
CRC and the data-section CRC (the writer sets both), so a truncated or bit-flipped file is rejected up
front rather than half-read.
"""

import io
import json
import math
import os
import struct
import zlib
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any

import numpy as np
from mcap.opcode import Opcode
from mcap.reader import SeekingReader
from mcap.records import Channel, DataEnd, Footer, Message, Metadata, Schema
from mcap.stream_reader import StreamReader

from graspexp.record import schemas as S
from graspexp.record.writer import PARTIAL_SUFFIX

MAGIC = b"\x89MCAP0\r\n"
_FOOTER_SIZE = 1 + 8 + 8 + 8 + 4  # opcode, length, summary_start, summary_offset_start, summary_crc
_DATA_END_SIZE = 1 + 8 + 4  # opcode, length, data_section_crc


class CorruptLogError(ValueError):
    """A trial log that cannot be trusted: unfinished, truncated, corrupt or incomplete."""


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
    """(t_s, foxglove.SceneEntity dicts) for each /scene message."""
    scene_deletions: list[tuple[float, str]] = field(default_factory=list)
    """(t_s, entity id) of every scene entity deleted (e.g. the collab support when it is removed)."""


def _name(source: Any) -> str:
    if isinstance(source, (str, os.PathLike)):
        return str(source)
    return str(getattr(source, "name", "<stream>"))


def _check_envelope(f: IO[bytes], size: int, name: str) -> None:
    """Magic at both ends, a well-formed footer, the summary CRC and the data-section CRC."""
    f.seek(0)
    head = f.read(len(MAGIC))
    if head != MAGIC[: len(head)] or size == 0:
        raise CorruptLogError(f"{name}: not an MCAP file (bad magic)" if size else f"{name}: empty file")
    if size < 2 * len(MAGIC) + _DATA_END_SIZE + _FOOTER_SIZE:
        raise CorruptLogError(f"{name}: truncated MCAP file ({size} bytes, no footer)")
    footer_start = size - len(MAGIC) - _FOOTER_SIZE
    f.seek(footer_start)
    tail = f.read(_FOOTER_SIZE + len(MAGIC))
    if tail[_FOOTER_SIZE:] != MAGIC:
        raise CorruptLogError(f"{name}: truncated or unfinished MCAP file ({size} bytes, no closing magic)")
    opcode, length, summary_start, _, summary_crc = struct.unpack("<BQQQI", tail[:_FOOTER_SIZE])
    data_end_start = (summary_start or footer_start) - _DATA_END_SIZE
    if (
        opcode != Opcode.FOOTER
        or length != _FOOTER_SIZE - 9
        or not len(MAGIC) <= data_end_start < footer_start
    ):
        raise CorruptLogError(f"{name}: corrupt MCAP file (bad footer record)")
    if summary_crc:
        f.seek(data_end_start + _DATA_END_SIZE)
        if (
            zlib.crc32(f.read(footer_start + _FOOTER_SIZE - 4 - data_end_start - _DATA_END_SIZE))
            != summary_crc
        ):
            raise CorruptLogError(f"{name}: corrupt MCAP file (summary CRC mismatch)")
    f.seek(data_end_start)
    opcode, length, data_crc = struct.unpack("<BQI", f.read(_DATA_END_SIZE))
    if opcode != Opcode.DATA_END or length != 4:
        raise CorruptLogError(f"{name}: corrupt MCAP file (no data-end record before the summary)")
    if data_crc:
        f.seek(0)
        crc, remaining = 0, data_end_start
        while remaining:
            block = f.read(min(remaining, 1 << 20))
            crc, remaining = zlib.crc32(block, crc), remaining - len(block)
        if crc != data_crc:
            raise CorruptLogError(f"{name}: corrupt MCAP file (data section CRC mismatch)")
    f.seek(0)


def _parse_error(name: str, exc: BaseException) -> CorruptLogError:
    detail = str(exc) or type(exc).__name__
    return CorruptLogError(f"{name}: corrupt MCAP data ({type(exc).__name__}: {detail})")


def _reject_partial(name: str) -> None:
    if name.endswith(PARTIAL_SUFFIX):
        raise CorruptLogError(
            f"{name}: unfinished trial log (a {PARTIAL_SUFFIX} file: the writer did not finish)"
        )


def _decode(name: str, topic: str, schema_name: str, message: Message) -> Any:
    try:
        value = json.loads(message.data)
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise CorruptLogError(
            f"{name}: unreadable JSON on {topic} at t={message.log_time / 1e9:.6f} s ({exc})"
        ) from exc
    schema = S.SCHEMAS.get(schema_name)
    return S.restore_nan(value, schema) if schema is not None else value


def _nan(v: Any) -> float:
    return math.nan if v is None else float(v)


def read_trial(source: Path | str | IO[bytes], *, require_result: bool = True) -> TrialLog:
    """Read a whole trial log from a path or a binary stream (e.g. io.BytesIO).

    Raises CorruptLogError for a ``.partial``, truncated or corrupt file, unreadable JSON, a missing
    ``graspexp`` metadata record, or (with ``require_result``) a missing /result message.
    """
    name = _name(source)
    _reject_partial(name)
    if isinstance(source, (str, os.PathLike)):
        data = Path(source).read_bytes()
        path: Path | None = Path(source)
    else:
        data = source.read()
        path = Path(name) if hasattr(source, "name") else None
    buf = io.BytesIO(data)
    _check_envelope(buf, len(data), name)
    try:
        records = list(StreamReader(buf, validate_crcs=True, record_size_limit=len(data)).records)
    except Exception as exc:  # any parse failure of CRC-checked bytes means a malformed file
        raise _parse_error(name, exc) from exc
    if not any(isinstance(r, DataEnd) for r in records) or not isinstance(records[-1], Footer):
        raise CorruptLogError(f"{name}: corrupt MCAP file (no data-end or footer record)")

    schemas = {r.id: r for r in records if isinstance(r, Schema)}
    channels = {r.id: r for r in records if isinstance(r, Channel)}
    meta = [r for r in records if isinstance(r, Metadata) and r.name == S.METADATA_NAME]
    if not meta:
        raise CorruptLogError(f"{name}: no '{S.METADATA_NAME}' metadata record (not a graspexp trial log)")
    messages = sorted((r for r in records if isinstance(r, Message)), key=lambda m: m.log_time)

    topics: dict[str, str] = {}
    for ch in channels.values():
        topics[ch.topic] = schemas[ch.schema_id].name if ch.schema_id in schemas else ""
    log = TrialLog(
        path=path,
        metadata=dict(meta[-1].metadata),
        result=None,
        grasp=None,
        phases=[],
        transforms={},
        contacts=[],
        topics=topics,
        message_count=len(messages),
    )
    tf: dict[str, list[list[float]]] = {}
    for m in messages:
        ch = channels.get(m.channel_id)
        if ch is None:
            raise CorruptLogError(f"{name}: corrupt MCAP file (message on unknown channel {m.channel_id})")
        schema_name = topics[ch.topic]
        if ch.topic not in S.TOPIC_SCHEMAS:
            continue
        if ch.message_encoding != S.MESSAGE_ENCODING or schema_name != S.TOPIC_SCHEMAS[ch.topic]:
            raise CorruptLogError(
                f"{name}: topic {ch.topic} has encoding {ch.message_encoding!r} / schema {schema_name!r}, "
                f"expected {S.MESSAGE_ENCODING!r} / {S.TOPIC_SCHEMAS[ch.topic]!r}"
            )
        t_s = m.log_time / 1e9
        msg = _decode(name, ch.topic, schema_name, m)
        try:
            if ch.topic == S.TOPIC_TF:
                tr, rot = msg["translation"], msg["rotation"]
                row = [t_s, tr["x"], tr["y"], tr["z"], rot["w"], rot["x"], rot["y"], rot["z"]]
                tf.setdefault(msg["child_frame_id"], []).append([_nan(v) for v in row])
            elif ch.topic == S.TOPIC_CONTACTS:
                log.contacts.append((t_s, list(msg["contacts"])))
            elif ch.topic == S.TOPIC_PHASE:
                log.phases.append((t_s, str(msg["name"]), msg.get("info")))
            elif ch.topic == S.TOPIC_GRASP:
                grasp = {k: v for k, v in msg.items() if k != "timestamp"}
                grasp["pose"] = np.array([[_nan(v) for v in row] for row in grasp["pose"]], dtype=float)
                grasp["approach"] = np.array([_nan(v) for v in grasp["approach"]], dtype=float)
                grasp["t_s"] = t_s
                log.grasp = grasp
            elif ch.topic == S.TOPIC_RESULT:
                if not isinstance(msg, dict) or "success" not in msg:
                    raise ValueError("result lacks 'success'")
                log.result = msg
            elif ch.topic == S.TOPIC_SCENE:
                log.scenes.append((t_s, list(msg["entities"])))
                log.scene_deletions.extend((t_s, str(d["id"])) for d in msg.get("deletions", []))
        except (KeyError, TypeError, ValueError, IndexError) as exc:
            raise CorruptLogError(
                f"{name}: malformed {schema_name} message on {ch.topic} at t={t_s:.6f} s ({exc!r})"
            ) from exc
    for frame, rows in tf.items():
        arr = np.asarray(rows, dtype=float).reshape(-1, 8)
        log.transforms[frame] = (arr[:, 0].copy(), arr[:, 1:4].copy(), arr[:, 4:8].copy())
    if require_result and log.result is None:
        raise CorruptLogError(f"{name}: no /result message (the trial did not finish)")
    return log


def read_result(path: Path | str) -> dict:
    """Only the /result message (TrialResult.to_dict() with NaN restored): the fast path for reports.

    The envelope and CRCs are checked as in :func:`read_trial`; only the chunk holding the result is
    decompressed and decoded.
    """
    name = str(path)
    _reject_partial(name)
    with open(path, "rb") as f:
        size = os.fstat(f.fileno()).st_size
        _check_envelope(f, size, name)
        try:
            found = list(
                SeekingReader(f, validate_crcs=True, record_size_limit=size).iter_messages(
                    topics=[S.TOPIC_RESULT]
                )
            )
        except Exception as exc:  # any parse failure of CRC-checked bytes means a malformed file
            raise _parse_error(name, exc) from exc
    if not found:
        raise CorruptLogError(f"{name}: no /result message (the trial did not finish)")
    schema, channel, message = found[-1]
    schema_name = schema.name if schema is not None else ""
    if schema_name != S.TRIAL_RESULT or channel.message_encoding != S.MESSAGE_ENCODING:
        raise CorruptLogError(f"{name}: /result has schema {schema_name!r}, expected {S.TRIAL_RESULT!r}")
    result = _decode(name, S.TOPIC_RESULT, schema_name, message)
    if not isinstance(result, dict) or "success" not in result:
        raise CorruptLogError(f"{name}: malformed {S.TRIAL_RESULT} message on /result")
    return result


def _trial_sort_key(p: Path) -> tuple:
    stem = p.stem
    return (p.parent.name, 0, int(stem), "") if stem.isdigit() else (p.parent.name, 1, 0, stem)


def iter_trial_logs(run_dir: Path | str) -> Iterator[Path]:
    """Finished logs ``<run_dir>/trials/<object>/<index>.mcap``, by object then numeric index.

    ``.partial`` files (unfinished trials) are skipped.
    """
    trials = Path(run_dir) / "trials"
    paths = [p for p in trials.glob("*/*.mcap") if p.is_file() and not p.name.endswith(PARTIAL_SUFFIX)]
    yield from sorted(paths, key=_trial_sort_key)
