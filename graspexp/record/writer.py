"""Write one trial to MCAP: Foxglove scene and transforms, contacts, the planned grasp, phases, the result.

Every message is JSON (``json`` message encoding, ``jsonschema`` schema encoding, see
:mod:`graspexp.record.schemas`); log_time and publish_time are the SIMULATION time in integer
nanoseconds, so writing the same trial twice gives byte-identical files (nothing in the file depends on
the wall clock). Chunks are LZ4-compressed (about 3x faster to finish than zstd, files about 2x larger) and carry CRCs; the data section and the summary carry CRCs
too, so the reader detects truncation and corruption.

:class:`TrialWriter` writes to any binary stream (tests use ``io.BytesIO``); :class:`TrialRecorder`
writes a file atomically: ``<path>.partial`` first, renamed to ``path`` only on a clean close.
"""

import enum
import json
import math
import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import IO, Any

import numpy as np
from mcap.writer import LIBRARY_IDENTIFIER, CompressionType, Writer

from graspexp.geometry import wxyz_to_xyzw
from graspexp.record import schemas as S

CHUNK_SIZE_BYTES = 1024 * 1024
"""Uncompressed chunk size; a typical trial fits in one or two chunks."""

SCENE_DECIMALS = 6
"""Mesh vertices in /scene messages are rounded to this many decimals of a metre (1 um)."""

CONTACT_DECIMALS = {"position": 6, "normal": 6, "force_n": 4, "separation_m": 7}
"""Decimals kept per /contacts quantity (m, unit, N, m): the bulk of a log.
/tf, /grasp and /result keep full float64 precision."""

PARTIAL_SUFFIX = ".partial"


def time_ns(t_s: float) -> int:
    """Simulation time in seconds -> integer nanoseconds (``round(t_s * 1e9)``); must be finite, >= 0."""
    t = float(t_s)
    if not math.isfinite(t) or t < 0:
        raise ValueError(f"sim time t_s must be finite and >= 0, got {t_s!r}")
    return round(t * 1e9)


def stamp(t_s: float) -> dict[str, int]:
    """Foxglove ``time`` {sec, nsec} for a simulation time in seconds."""
    sec, nsec = divmod(time_ns(t_s), 1_000_000_000)
    return {"sec": sec, "nsec": nsec}


def to_json_value(value: Any, digits: int | None = None) -> Any:
    """numpy/Python value -> plain JSON value. Non-finite floats -> None; ``digits``: significant digits."""
    if isinstance(value, np.ndarray):
        return [to_json_value(v, digits) for v in value.tolist()]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, enum.Enum):  # e.g. FailureReason: store its value
        value = value.value
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return value
    if isinstance(value, int):
        return value
    if isinstance(value, float):
        if not math.isfinite(value):
            return None
        return float(f"{value:.{digits}g}") if digits is not None else value
    if isinstance(value, Mapping):
        return {str(k): to_json_value(v, digits) for k, v in value.items()}
    if isinstance(value, Sequence):
        return [to_json_value(v, digits) for v in value]
    raise TypeError(f"cannot encode {type(value).__name__} value {value!r} as JSON")


def _vec3(values: Any, what: str) -> list[float]:
    arr = np.asarray(values, dtype=float).reshape(-1)
    if arr.shape != (3,):
        raise ValueError(f"{what} must have 3 components, got shape {np.shape(values)}")
    return [float(v) for v in arr]


def _rows(items: list[dict], key: str, what: str) -> np.ndarray:
    arr = np.asarray([c[key] for c in items], dtype=float)
    if arr.shape != (len(items), 3):
        raise ValueError(f"{what} must have 3 components, got shape {arr.shape[1:]}")
    return arr


def _rgba(color: Sequence[float]) -> dict[str, float]:
    c = np.asarray(color, dtype=float).reshape(-1)
    if c.shape != (4,):
        raise ValueError(f"color must be (r, g, b, a) in [0, 1], got {color!r}")
    return {"r": float(c[0]), "g": float(c[1]), "b": float(c[2]), "a": float(c[3])}


_IDENTITY_POSE = {
    "position": {"x": 0.0, "y": 0.0, "z": 0.0},
    "orientation": {"x": 0.0, "y": 0.0, "z": 0.0, "w": 1.0},
}


def _entity(id: str, frame_id: str, *, cubes: list[dict], triangles: list[dict]) -> dict:
    """A foxglove.SceneEntity that never expires and follows ``frame_id`` (frame_locked)."""
    return {
        "frame_id": frame_id,
        "id": id,
        "lifetime": {"sec": 0, "nsec": 0},
        "frame_locked": True,
        "metadata": [],
        "cubes": cubes,
        "triangles": triangles,
    }


def mesh_entity(
    id: str, frame_id: str, vertices: np.ndarray, faces: np.ndarray, color: Sequence[float]
) -> dict:
    """A foxglove.SceneEntity with one TriangleListPrimitive (identity pose in ``frame_id``).

    vertices : (V, 3) float, ``frame_id`` frame, m. faces : (F, 3) int indices into vertices.
    color : (r, g, b, a) in [0, 1], one colour for the whole mesh. The vertices are stored once
    (rounded to SCENE_DECIMALS decimals, i.e. 1 um) with an index array of 3F entries; frame_locked is
    true so the mesh follows ``frame_id``. The entity is plain JSON data, ready for :meth:`TrialWriter.scene`.
    """
    v = np.asarray(vertices, dtype=float)
    f = np.asarray(faces)
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"vertices must be (V, 3), got shape {v.shape}")
    if f.ndim != 2 or f.shape[1] != 3 or not np.issubdtype(f.dtype, np.integer):
        raise ValueError(f"faces must be (F, 3) integers, got shape {f.shape} dtype {f.dtype}")
    if f.size and (f.min() < 0 or f.max() >= len(v)):
        raise ValueError(f"faces index outside 0..{len(v) - 1}")
    pts = np.round(v, SCENE_DECIMALS).tolist()
    return _entity(
        id,
        frame_id,
        cubes=[],
        triangles=[
            {
                "pose": _IDENTITY_POSE,
                "points": [{"x": p[0], "y": p[1], "z": p[2]} for p in pts],
                "color": _rgba(color),
                "colors": [],
                "indices": f.reshape(-1).astype(int).tolist(),
            }
        ],
    )


def box_entity(
    id: str,
    frame_id: str,
    center: Sequence[float],
    size: Sequence[float],
    color: Sequence[float],
    quat_xyzw: Sequence[float] = (0.0, 0.0, 0.0, 1.0),
) -> dict:
    """A foxglove.SceneEntity with one CubePrimitive.

    center : (3,) m and quat_xyzw : (4,) Foxglove order (x, y, z, w), both in ``frame_id``;
    size : (3,) full edge lengths, m; color : (r, g, b, a) in [0, 1].
    """
    c, s = _vec3(center, "center"), _vec3(size, "size")
    q = np.asarray(quat_xyzw, dtype=float).reshape(-1)
    if q.shape != (4,):
        raise ValueError(f"quat_xyzw must have 4 components, got {quat_xyzw!r}")
    cube = {
        "pose": {
            "position": dict(zip("xyz", c, strict=True)),
            "orientation": dict(zip("xyzw", q.tolist(), strict=True)),
        },
        "size": dict(zip("xyz", s, strict=True)),
        "color": _rgba(color),
    }
    return _entity(id, frame_id, cubes=[cube], triangles=[])


class TrialWriter:
    """Writes one trial's MCAP to a binary stream. Call :meth:`finish` once; the stream stays open.

    metadata : str -> str, stored as the MCAP metadata record named ``graspexp``.
    """

    def __init__(self, stream: IO[bytes], metadata: Mapping[str, str]):
        bad = [k for k, v in metadata.items() if not isinstance(k, str) or not isinstance(v, str)]
        if bad:
            raise TypeError(f"metadata must map str to str; offending keys: {bad}")
        self._mcap = Writer(
            stream,
            chunk_size=CHUNK_SIZE_BYTES,
            compression=CompressionType.LZ4,
            enable_crcs=True,
            enable_data_crcs=True,
        )
        self._mcap.start(profile="", library=f"graspexp; {LIBRARY_IDENTIFIER}")
        self._mcap.add_metadata(S.METADATA_NAME, dict(metadata))
        self._schema_ids: dict[str, int] = {}
        self._channel_ids: dict[str, int] = {}
        self._sequence: dict[str, int] = {}
        self._has_result = False
        self._finished = False

    @property
    def has_result(self) -> bool:
        """Whether :meth:`result` was called."""
        return self._has_result

    # -- low level ----------------------------------------------------------------------------------

    def _channel(self, topic: str) -> int:
        if topic not in self._channel_ids:
            name = S.TOPIC_SCHEMAS[topic]
            if name not in self._schema_ids:
                self._schema_ids[name] = self._mcap.register_schema(
                    name=name, encoding=S.SCHEMA_ENCODING, data=S.schema_bytes(name)
                )
            self._channel_ids[topic] = self._mcap.register_channel(
                topic=topic, message_encoding=S.MESSAGE_ENCODING, schema_id=self._schema_ids[name]
            )
            self._sequence[topic] = 0
        return self._channel_ids[topic]

    def _write(self, topic: str, t_s: float, message: dict) -> None:
        if self._finished:
            raise RuntimeError("trial log already finished")
        ns = time_ns(t_s)
        channel = self._channel(topic)
        data = json.dumps(message, separators=(",", ":"), allow_nan=False).encode()
        self._mcap.add_message(
            channel_id=channel, log_time=ns, publish_time=ns, data=data, sequence=self._sequence[topic]
        )
        self._sequence[topic] += 1

    # -- topics -------------------------------------------------------------------------------------

    def scene(self, t_s: float, entities: list[dict]) -> None:
        """/scene, foxglove.SceneUpdate: entities from :func:`mesh_entity` / :func:`box_entity`.

        Each entity gets ``timestamp`` = t_s. The entities are plain JSON data already (the constructors
        round and convert once), so a scene sent with every trial costs no per-float work here.
        """
        ts = stamp(t_s)
        ents = [{"timestamp": ts, **e} for e in entities]
        self._write(S.TOPIC_SCENE, t_s, {"deletions": [], "entities": ents})

    def transforms(self, t_s: float, frames: Mapping[str, tuple[Sequence[float], Sequence[float]]]) -> None:
        """/tf, one foxglove.FrameTransform per child frame, parent ``world``.

        frames : child frame -> (position (3,) world frame m, quaternion (4,) SAPIEN order w, x, y, z).
        The rotation is written in Foxglove order {x, y, z, w}. This is the hot path of a trial log, so
        messages are built from plain floats without the generic :func:`to_json_value` walk.
        """
        ts = stamp(t_s)
        for child, (pos, quat_wxyz) in frames.items():
            p = [float(v) for v in pos]
            x, y, z, w = wxyz_to_xyzw(quat_wxyz)
            if len(p) != 3 or not all(map(math.isfinite, (*p, x, y, z, w))):
                raise ValueError(f"frame {child!r}: need a finite position (3,) and quaternion (w, x, y, z)")
            msg = {
                "timestamp": ts,
                "parent_frame_id": "world",
                "child_frame_id": child,
                "translation": {"x": p[0], "y": p[1], "z": p[2]},
                "rotation": {"x": x, "y": y, "z": z, "w": w},
            }
            self._write(S.TOPIC_TF, t_s, msg)

    def contacts(self, t_s: float, contacts: list[dict]) -> None:
        """/contacts, graspexp.Contacts@1: one message with every contact point of the step.

        Each dict: body0, body1 (names), position (3,) world m, normal (3,) world, force_n: (3,) world-frame
        force on body0 in N, or a scalar magnitude along ``normal``; separation_m (float, default 0).
        Numbers are rounded (vectorised) to CONTACT_DECIMALS decimals per quantity: 1 um positions,
        1e-6 normals, 0.1 mN forces, 0.1 um separations.
        """
        out = []
        if contacts:
            pos = _rows(contacts, "position", "contact position")
            normal = _rows(contacts, "normal", "contact normal")
            force = np.array(
                [
                    np.asarray(c["force_n"], dtype=float) * (normal[i] if np.ndim(c["force_n"]) == 0 else 1.0)
                    for i, c in enumerate(contacts)
                ],
                dtype=float,
            ).reshape(-1, 3)
            sep = np.array([float(c.get("separation_m", 0.0)) for c in contacts])
            d = CONTACT_DECIMALS
            cols = (
                np.round(pos, d["position"]).tolist(),
                np.round(normal, d["normal"]).tolist(),
                np.round(force, d["force_n"]).tolist(),
                np.round(sep, d["separation_m"]).tolist(),
            )
            for c, p, n, f, sp in zip(contacts, *cols, strict=True):
                out.append(
                    {
                        "body0": str(c["body0"]),
                        "body1": str(c["body1"]),
                        "position": p,
                        "normal": n,
                        "force_n": f,
                        "separation_m": sp,
                    }
                )
        msg = {"timestamp": stamp(t_s), "contacts": out}  # plain rounded floats already
        self._write(S.TOPIC_CONTACTS, t_s, msg)

    def grasp(self, t_s: float, grasp: Mapping[str, Any]) -> None:
        """/grasp, graspexp.PlannedGrasp@1.

        Keys: pose (4, 4) world-frame homogeneous matrix (stored row-major as 4 rows), approach (3,) unit
        world direction, width_m, cost, cluster, path, planner, K, M, n_feasible. Extra keys are kept.
        """
        pose = np.asarray(grasp["pose"], dtype=float)
        if pose.shape != (4, 4):
            raise ValueError(f"grasp pose must be (4, 4), got shape {pose.shape}")
        msg: dict[str, Any] = {"timestamp": stamp(t_s)}
        msg.update(grasp)
        msg["pose"] = pose.tolist()
        msg["approach"] = _vec3(grasp["approach"], "grasp approach")
        for key in ("cluster", "path", "K", "M"):
            msg.setdefault(key, None)
        self._write(S.TOPIC_GRASP, t_s, to_json_value(msg))

    def phase(self, t_s: float, name: str, info: Mapping[str, Any] | None = None) -> None:
        """/phase, graspexp.Phase@1: the protocol enters phase ``name`` (see schemas.PHASE_NAMES)."""
        msg = {"timestamp": stamp(t_s), "name": str(name), "info": None if info is None else dict(info)}
        self._write(S.TOPIC_PHASE, t_s, to_json_value(msg))

    def result(self, t_s: float, result: Mapping[str, Any] | Any) -> None:
        """/result, graspexp.TrialResult@2: ``TrialResult.to_dict()`` (a TrialResult is accepted too).

        NaN floats are written as null and read back as NaN. The result is written in its own chunk so
        :func:`graspexp.record.reader.read_result` decompresses only that.
        """
        d = result.to_dict() if hasattr(result, "to_dict") else dict(result)
        missing = [k for k in S.SCHEMAS[S.TRIAL_RESULT]["required"] if k not in d]
        if missing:
            raise ValueError(f"trial result lacks fields {missing}")
        self._mcap.flush()
        self._write(S.TOPIC_RESULT, t_s, to_json_value(d))
        self._has_result = True

    def finish(self) -> None:
        """Write the summary and footer. The stream is flushed, not closed."""
        if not self._finished:
            self._mcap.finish()
            self._finished = True


class TrialRecorder(TrialWriter):
    """Atomic trial log file; use as a context manager.

    Writes ``<path>.partial`` in the same folder and renames it to ``path`` on a clean exit. The recorder
    owns ``path``: an older file there is removed when recording starts, so a failed re-run never
    leaves a previous log looking like its result. If the ``with`` body raises, or no :meth:`result`
    was written, the partial file is deleted and nothing is left at ``path`` (the latter raises
    RuntimeError from :meth:`close`).
    """

    def __init__(self, path: Path | str, metadata: Mapping[str, str]):
        self.path = Path(path)
        self.partial_path = self.path.with_name(self.path.name + PARTIAL_SUFFIX)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.path.unlink(missing_ok=True)
        self._file = open(self.partial_path, "wb")  # closed by close() or abort()
        try:
            super().__init__(self._file, metadata)
        except BaseException:
            self.abort()
            raise

    def close(self) -> None:
        """Finish the file and rename it to ``path``. Without a result message: abort and raise."""
        if self._file.closed:
            return
        if not self.has_result:
            self.abort()
            raise RuntimeError(f"{self.path}: trial log closed without a /result message; log discarded")
        try:
            self.finish()
            self._file.close()
            os.replace(self.partial_path, self.path)
        except BaseException:
            self.abort()
            raise

    def abort(self) -> None:
        """Discard the log: close and delete the partial file; nothing is left at ``path``."""
        if not self._file.closed:
            self._file.close()
        self.partial_path.unlink(missing_ok=True)

    def __enter__(self) -> "TrialRecorder":
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None:
            self.close()
        else:
            self.abort()
