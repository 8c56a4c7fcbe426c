"""Write one trial to MCAP: Foxglove scene and transforms, contacts, the planned grasp, phases, the result.

The file is written by the official ``foxglove-sdk`` package (its Rust MCAP writer): ``/tf``
(foxglove.FrameTransforms), ``/scene`` (foxglove.SceneUpdate), ``/grasp_pose`` (foxglove.PoseInFrame) and
``/contacts`` (foxglove.PointCloud) are protobuf messages with Foxglove's own schemas; ``/grasp``,
``/phase`` and ``/result`` are JSON with our own JSON Schemas (:mod:`graspexp.record.schemas`). log_time and publish_time are the
SIMULATION time in integer nanoseconds, so writing the same trial twice gives byte-identical files
(nothing in the file depends on the wall clock). Chunks are LZ4-compressed and carry CRCs; the data
section and the summary carry CRCs too, so the reader detects truncation and corruption.

Why the SDK: measured side by side (CPU time, 4 FrameTransforms per tick, 150 ticks, alternated), it
writes a tick in 26 us against 84 us for ``foxglove-schemas-protobuf`` + ``mcap-protobuf-support`` (pure
Python MCAP writer), 0.31x; and its WebSocket server, fed by the same channels, gives the live view
(:mod:`graspexp.record.live`).

:class:`TrialWriter` writes to any binary stream (tests use ``io.BytesIO``); :class:`TrialRecorder`
writes a file atomically: ``<path>.partial`` first, renamed to ``path`` only on a clean close.
"""

import enum
import functools
import json
import math
import os
import struct
from collections.abc import Mapping, Sequence
from contextlib import AbstractContextManager, nullcontext
from pathlib import Path
from typing import IO, TYPE_CHECKING, Any

import foxglove
import numpy as np
from foxglove.mcap import MCAPCompression, MCAPWriteOptions
from foxglove.messages import (
    CameraCalibration,
    FrameTransform,
    FrameTransforms,
    PackedElementField,
    PackedElementFieldNumericType,
    PointCloud,
    Pose,
    PoseInFrame,
    Quaternion,
    RawImage,
    SceneEntity,
    SceneEntityDeletion,
    SceneEntityDeletionType,
    SceneUpdate,
    Timestamp,
    Vector3,
)

from graspexp.core.geometry import matrix_to_quat_wxyz
from graspexp.record import schemas as S
from graspexp.record.channels import BODY_NAMES, Channels
from graspexp.record.live import live_channels

if TYPE_CHECKING:
    from graspexp.config import JobConfig

CHUNK_SIZE_BYTES = 1024 * 1024
"""Uncompressed chunk size; a typical trial fits in one chunk."""

_CONTACT = struct.Struct(S.CONTACT_FORMAT)
_CONTACT_FIELDS = [
    PackedElementField(name=n, offset=4 * i, type=PackedElementFieldNumericType.Float32)
    for i, n in enumerate(S.CONTACT_FLOATS)
] + [
    PackedElementField(name=n, offset=4 * len(S.CONTACT_FLOATS) + i, type=PackedElementFieldNumericType.Uint8)
    for i, n in enumerate(S.CONTACT_BODIES)
]
_IDENTITY = Pose(position=Vector3(), orientation=Quaternion(w=1.0))

_CLOUD_DTYPE = np.dtype([(n, "<f4") for n in S.CLOUD_FIELDS] + [("id", "<u4")])
_CLOUD_FIELDS = [
    PackedElementField(name=n, offset=_CLOUD_DTYPE.fields[n][1], type=PackedElementFieldNumericType.Float32)
    for n in S.CLOUD_FIELDS
] + [
    PackedElementField(
        name="id", offset=_CLOUD_DTYPE.fields["id"][1], type=PackedElementFieldNumericType.Uint32
    )
]

PARTIAL_SUFFIX = S.PARTIAL_SUFFIX
WORLD_FRAME = "world"


def time_ns(t_s: float) -> int:
    """Simulation time in seconds -> integer nanoseconds (``round(t_s * 1e9)``); must be finite, >= 0."""
    t = float(t_s)
    if not math.isfinite(t) or t < 0:
        raise ValueError(f"sim time t_s must be finite and >= 0, got {t_s!r}")
    return round(t * 1e9)


def stamp(t_s: float) -> dict[str, int]:
    """JSON ``time`` {sec, nsec} of our own messages for a simulation time in seconds."""
    sec, nsec = divmod(time_ns(t_s), 1_000_000_000)
    return {"sec": sec, "nsec": nsec}


def to_json_value(value: Any) -> Any:
    """numpy/Python value -> plain JSON value. Non-finite floats -> None."""
    if isinstance(value, np.ndarray):
        return [to_json_value(v) for v in value.tolist()]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, enum.Enum):  # e.g. FailureReason: store its value
        value = value.value
    if isinstance(value, bool) or value is None or isinstance(value, str):
        return value
    if isinstance(value, int):
        return value
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, Mapping):
        return {str(k): to_json_value(v) for k, v in value.items()}
    if isinstance(value, Sequence):
        return [to_json_value(v) for v in value]
    raise TypeError(f"cannot encode {type(value).__name__} value {value!r} as JSON")


@functools.cache
def _body_ids(bodies: tuple[str, ...] = BODY_NAMES) -> dict[str, int]:
    return {name: i for i, name in enumerate(bodies)}


def _contact_point(c: Mapping[str, Any], bodies: tuple[str, ...] = BODY_NAMES) -> bytes:
    """One /contacts point (see :data:`graspexp.record.schemas.CONTACT_FLOATS`) from a contact mapping."""
    position = [float(v) for v in c["position"]]
    normal = [float(v) for v in c["normal"]]
    force = c["force_n"]
    force = (
        [float(v) for v in force]
        if isinstance(force, Sequence | np.ndarray)
        else [float(force) * n for n in normal]
    )
    if not len(position) == len(normal) == len(force) == 3:
        raise ValueError(f"contact position, normal and force_n must have 3 components, got {dict(c)!r}")
    try:
        ids = _body_ids(bodies)
        pair = ids[c["body0"]], ids[c["body1"]]
    except KeyError as exc:
        raise ValueError(f"contact body {exc.args[0]!r} is not one of {bodies}") from None
    return _CONTACT.pack(*position, *normal, *force, float(c.get("separation_m", 0.0)), *pair)


def _raw_image(ts: Timestamp, frame_id: str, pixels: np.ndarray, encoding: str) -> RawImage:
    """A foxglove.RawImage of a (H, W) little-endian array."""
    h, w = pixels.shape
    return RawImage(
        timestamp=ts,
        frame_id=frame_id,
        width=w,
        height=h,
        encoding=encoding,
        step=w * pixels.dtype.itemsize,
        data=np.ascontiguousarray(pixels).tobytes(),
    )


def _dumps(message: Any) -> bytes:
    return json.dumps(message, separators=(",", ":"), allow_nan=False).encode()


class TrialWriter:
    """Writes one trial's MCAP to a binary stream. Call :meth:`finish` once; the stream stays open.

    metadata : str -> str, stored as the MCAP metadata record named ``graspexp``. ``channels``: the
    channels of a live server (:func:`graspexp.record.live.live_channels`) that also get every message;
    None: the file only. ``stream=None`` with live channels streams without writing a file. ``bodies``: the
    /contacts body names (a clutter round's: :func:`graspexp.record.scene.round_bodies`).
    """

    active = True
    """Every message is kept (:class:`graspexp.sim.trial.LogSink`)."""

    def __init__(
        self,
        stream: IO[bytes] | None,
        metadata: Mapping[str, str],
        channels: Channels | None = None,
        bodies: tuple[str, ...] = BODY_NAMES,
    ):
        bad = [k for k, v in metadata.items() if not isinstance(k, str) or not isinstance(v, str)]
        if bad:
            raise TypeError(f"metadata must map str to str; offending keys: {bad}")
        self._ch = channels if channels is not None else Channels(foxglove.Context(), bodies)
        self._ch.use_bodies(bodies)
        self._bodies = bodies
        self._mcap = None
        if stream is not None:
            options = MCAPWriteOptions(
                compression=MCAPCompression.Lz4, profile="", chunk_size=CHUNK_SIZE_BYTES
            )
            self._mcap = foxglove.open_mcap(stream, context=self._ch.context, writer_options=options)
            self._mcap.write_metadata(S.METADATA_NAME, dict(metadata))
        self._has_result = False
        self._finished = False

    @property
    def has_result(self) -> bool:
        """Whether :meth:`result` was called."""
        return self._has_result

    def _ns(self, t_s: float) -> int:
        if self._finished:
            raise RuntimeError("trial log already finished")
        return time_ns(t_s)

    def _json(self, topic: str, t_s: float, message: dict) -> None:
        self._ch.json[topic].log(_dumps(message), log_time=self._ns(t_s))

    # -- Foxglove topics (protobuf) ----------------------------------------------------------------

    def scene(self, t_s: float, entities: Sequence[SceneEntity]) -> None:
        """/scene, foxglove.SceneUpdate adding ``entities`` (from :mod:`graspexp.record.scene`)."""
        self._ch.scene.log(SceneUpdate(entities=list(entities)), log_time=self._ns(t_s))

    def delete_entities(self, t_s: float, ids: Sequence[str]) -> None:
        """/scene, foxglove.SceneUpdate deleting the entities ``ids`` (e.g. the support when it is removed)."""
        ns = self._ns(t_s)
        ts = Timestamp(*divmod(ns, 1_000_000_000))
        deletions = [
            SceneEntityDeletion(timestamp=ts, type=SceneEntityDeletionType.MatchingId, id=str(i)) for i in ids
        ]
        self._ch.scene.log(SceneUpdate(deletions=deletions), log_time=ns)

    def transforms(self, t_s: float, frames: Mapping[str, tuple[Sequence[float], Sequence[float]]]) -> None:
        """/tf, one foxglove.FrameTransforms message: a FrameTransform per child frame, parent ``world``.

        frames : child frame -> (position (3,) world frame m, quaternion (4,) SAPIEN order w, x, y, z).
        The rotation is written in Foxglove order (x, y, z, w). The hot path of a trial log: plain floats.
        """
        ns = self._ns(t_s)
        ts = Timestamp(*divmod(ns, 1_000_000_000))
        out = []
        for child, (pos, quat_wxyz) in frames.items():
            x, y, z = pos.tolist() if isinstance(pos, np.ndarray) else map(float, pos)
            qw, qx, qy, qz = (
                quat_wxyz.tolist() if isinstance(quat_wxyz, np.ndarray) else map(float, quat_wxyz)
            )
            out.append(
                FrameTransform(
                    timestamp=ts,
                    parent_frame_id=WORLD_FRAME,
                    child_frame_id=child,
                    translation=Vector3(x=x, y=y, z=z),
                    rotation=Quaternion(x=qx, y=qy, z=qz, w=qw),
                )
            )
        self._ch.tf.log(FrameTransforms(transforms=out), log_time=ns)

    def contacts(self, t_s: float, contacts: Sequence[Mapping[str, Any]]) -> None:
        """/contacts, foxglove.PointCloud in ``world``: one point per contact (drawn in Foxglove's 3D panel).

        Each mapping: body0, body1 (names from :data:`BODY_NAMES`), position (3,)
        world m, normal (3,) world, force_n: (3,) world-frame force on body0 in N, or a scalar magnitude
        along ``normal``; separation_m (float, default 0). Stored as float32, as PhysX reports contacts.
        """
        ns = self._ns(t_s)
        cloud = PointCloud(
            timestamp=Timestamp(*divmod(ns, 1_000_000_000)),
            frame_id=WORLD_FRAME,
            pose=_IDENTITY,
            point_stride=S.CONTACT_STRIDE,
            fields=_CONTACT_FIELDS,
            data=b"".join(_contact_point(c, self._bodies) for c in contacts),
        )
        self._ch.contacts.log(cloud, log_time=ns)

    # -- our own topics (JSON) ----------------------------------------------------------------------

    def grasp(self, t_s: float, grasp: Mapping[str, Any]) -> None:
        """/grasp, graspexp.PlannedGrasp@1, and the same pose on /grasp_pose (foxglove.PoseInFrame, ``world``).

        Keys: pose (4, 4) world-frame homogeneous matrix (stored row-major as 4 rows), approach (3,) unit
        world direction, width_m, cost, cluster, path, planner, K, M, n_feasible. Extra keys are kept.
        """
        pose = np.asarray(grasp["pose"], dtype=float)
        if pose.shape != (4, 4):
            raise ValueError(f"grasp pose must be (4, 4), got shape {pose.shape}")
        approach = np.asarray(grasp["approach"], dtype=float).reshape(-1)
        if approach.shape != (3,):
            raise ValueError(f"grasp approach must have 3 components, got {grasp['approach']!r}")
        msg: dict[str, Any] = {"timestamp": stamp(t_s)}
        msg.update(grasp)
        msg["pose"] = pose.tolist()
        msg["approach"] = approach.tolist()
        for key in ("cluster", "path", "K", "M"):
            msg.setdefault(key, None)
        self._json(S.TOPIC_GRASP, t_s, to_json_value(msg))
        if np.isfinite(pose).all():
            ns = time_ns(t_s)
            qw, qx, qy, qz = (float(v) for v in matrix_to_quat_wxyz(pose[:3, :3]))
            x, y, z = (float(v) for v in pose[:3, 3])
            self._ch.grasp_pose.log(
                PoseInFrame(
                    timestamp=Timestamp(*divmod(ns, 1_000_000_000)),
                    frame_id=WORLD_FRAME,
                    pose=Pose(
                        position=Vector3(x=x, y=y, z=z), orientation=Quaternion(x=qx, y=qy, z=qz, w=qw)
                    ),
                ),
                log_time=ns,
            )

    def phase(self, t_s: float, name: str, info: Mapping[str, Any] | None = None) -> None:
        """/phase, graspexp.Phase@1: the protocol enters phase ``name`` (see schemas.PHASE_NAMES)."""
        msg = {"timestamp": stamp(t_s), "name": str(name), "info": None if info is None else dict(info)}
        self._json(S.TOPIC_PHASE, t_s, to_json_value(msg))

    def result(self, t_s: float, result: Mapping[str, Any] | Any) -> None:
        """/result, graspexp.TrialResult@5: ``TrialResult.to_dict()`` (a TrialResult is accepted too).

        NaN floats are written as null and read back as NaN.
        """
        d = result.to_dict() if hasattr(result, "to_dict") else dict(result)
        missing = [k for k in S.SCHEMAS[S.TRIAL_RESULT]["required"] if k not in d]
        if missing:
            raise ValueError(f"trial result lacks fields {missing}")
        if self._mcap is not None:
            self._mcap.flush()  # the result gets a chunk of its own: read_result decompresses only that
        self._json(S.TOPIC_RESULT, t_s, to_json_value(d))
        self._has_result = True

    def round_result(self, t_s: float, result: Mapping[str, Any] | Any) -> None:
        """/round, graspexp.RoundResult@1: a clutter round's ``RoundResult.to_dict()``, its attempts included
        (the round log's last message, in place of /result)."""
        d = result.to_dict() if hasattr(result, "to_dict") else dict(result)
        missing = [k for k in S.SCHEMAS[S.ROUND_RESULT]["required"] if k not in d]
        if missing:
            raise ValueError(f"round result lacks fields {missing}")
        if self._mcap is not None:
            self._mcap.flush()
        channel = self._ch.lazy_json(S.TOPIC_ROUND)
        channel.log(_dumps(to_json_value(d)), log_time=self._ns(t_s))
        self._has_result = True

    def perception(
        self, t_s: float, observation: Any, poses: Mapping[str, np.ndarray], info: Mapping[str, Any]
    ) -> None:
        """What the camera saw at planning time: per view (a :class:`graspexp.perception.CameraView` of
        ``observation``) /camera/depth, /camera/ids and /camera/calibration in the view's frame (the trial
        puts the views' and the object's frames on /tf); the observed cloud on /camera/cloud; ``poses``
        (``object_true``, ``object_prior``, ``object_estimated``: (4, 4) world) and ``info`` (source,
        errors, fitness, ...) on /perception (graspexp.Perception@1)."""
        ns = self._ns(t_s)
        ts = Timestamp(*divmod(ns, 1_000_000_000))
        ch = self._ch.camera
        for v in observation.views:
            h, w = v.depth.shape
            ch.depth.log(_raw_image(ts, v.name, v.depth.astype("<f4"), "32FC1"), log_time=ns)
            ids = np.clip(v.ids, 0, 65535).astype("<u2")
            ch.ids.log(_raw_image(ts, v.name, ids, "16UC1"), log_time=ns)
            K = [float(x) for x in np.asarray(v.K, dtype=float).ravel()]
            P = [K[0], K[1], K[2], 0.0, K[3], K[4], K[5], 0.0, K[6], K[7], K[8], 0.0]
            ch.calibration.log(
                CameraCalibration(
                    timestamp=ts,
                    frame_id=v.name,
                    width=w,
                    height=h,
                    distortion_model="plumb_bob",
                    D=[0.0] * 5,
                    K=K,
                    R=[1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0],
                    P=P,
                ),
                log_time=ns,
            )
        packed = np.zeros(len(observation.points), dtype=_CLOUD_DTYPE)
        for i, name in enumerate(S.CLOUD_FIELDS):
            packed[name] = (observation.points if i < 3 else observation.normals)[:, i % 3]
        packed["id"] = observation.point_ids
        ch.cloud.log(
            PointCloud(
                timestamp=ts,
                frame_id=WORLD_FRAME,
                pose=_IDENTITY,
                point_stride=_CLOUD_DTYPE.itemsize,
                fields=_CLOUD_FIELDS,
                data=packed.tobytes(),
            ),
            log_time=ns,
        )
        target = int((observation.point_ids == observation.target_id).sum())
        msg = {
            "timestamp": stamp(t_s),
            **{k: v for k, v in info.items() if k != "estimated_pose"},
            "true_pose": np.asarray(poses["object_true"]),
            "prior_pose": np.asarray(poses["object_prior"]),
            "n_points": len(observation.points),
            "n_target_points": target,
        }
        if "estimated_pose" in info:
            msg["estimated_pose"] = np.asarray(info["estimated_pose"])
        ch.perception.log(_dumps(to_json_value(msg)), log_time=ns)

    def finish(self) -> None:
        """Write the summary and footer. The stream is flushed, not closed."""
        if not self._finished:
            if self._mcap is not None:
                self._mcap.close()
            self._finished = True

    def __enter__(self) -> "TrialWriter":
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        self.finish()


def is_write_error(exc: BaseException) -> bool:
    """Whether ``exc`` is a failure to write a log file: an OSError, or the Foxglove SDK's RuntimeError
    for an I/O error of its MCAP sink (a full disk, a file-size limit)."""
    text = str(exc)
    return isinstance(exc, OSError) or (
        isinstance(exc, RuntimeError)
        and "FoxgloveError" in text
        and ("I/O error" in text or "write method failed" in text)
    )


class TrialRecorder(TrialWriter):
    """Atomic trial log file; use as a context manager.

    Writes ``<path>.partial`` in the same folder and renames it to ``path`` on a clean exit. The recorder
    owns ``path``: an older file there is removed when recording starts, so a failed re-run never
    leaves a previous log looking like its result. If the ``with`` body raises, or no :meth:`result`
    was written, the partial file is deleted and nothing is left at ``path`` (the latter raises
    RuntimeError from :meth:`close`).
    """

    def __init__(
        self,
        path: Path | str,
        metadata: Mapping[str, str],
        channels: Channels | None = None,
        bodies: tuple[str, ...] = BODY_NAMES,
    ):
        self.path = Path(path)
        self.partial_path = self.path.with_name(self.path.name + PARTIAL_SUFFIX)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self.path.unlink(missing_ok=True)  # a link there is removed, never written through
        self.partial_path.unlink(missing_ok=True)
        flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW  # a link planted meanwhile: refused
        self._file = os.fdopen(os.open(self.partial_path, flags, 0o644), "wb")  # closed by close() or abort()
        try:
            super().__init__(self._file, metadata, channels, bodies)
        except BaseException:
            self.abort()
            raise

    def close(self) -> None:
        """Finish the file and rename it to ``path``. Without a result message: abort and raise."""
        if self._file.closed:
            return
        if not self.has_result:
            self.abort()
            raise RuntimeError(
                f"{self.path}: trial log closed without a /result (or /round) message; log discarded"
            )
        try:
            self.finish()
            self._file.close()
            os.replace(self.partial_path, self.path)
        except BaseException:
            self.abort()
            raise

    def abort(self) -> None:
        """Discard the log: close and delete the partial file; nothing is left at ``path``."""
        mcap, self._mcap, self._finished = getattr(self, "_mcap", None), None, True
        try:
            if mcap is not None:
                mcap.close()  # detaches the file from the channels (a live server's stay in use)
        except Exception as exc:  # a sink that failed to write (disk full) fails to close too
            if not is_write_error(exc):
                raise
        finally:
            try:
                self._file.close()  # flushes: fails again on a full disk
            except OSError:
                pass  # the partial file is discarded below either way
            self.partial_path.unlink(missing_ok=True)

    def __enter__(self) -> "TrialRecorder":
        return self

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None:
            self.close()
        else:
            self.abort()


def trial_recorder(
    path: Path | str | None,
    metadata: Mapping[str, str],
    cfg: "JobConfig",
    bodies: tuple[str, ...] = BODY_NAMES,
) -> AbstractContextManager:
    """The recorder of one trial under job config ``cfg`` (its ``live`` and ``live_port`` keys).

    A :class:`TrialRecorder` for ``path``; None: no file. With ``cfg.live`` the messages also stream to
    the live server (:mod:`graspexp.record.live`); with neither, a no-op recorder.
    """
    channels = None
    if cfg.live:
        channels = live_channels(int(cfg.live_port))
    if path is not None:
        return TrialRecorder(path, metadata, channels, bodies)
    if channels is not None:
        return TrialWriter(None, metadata, channels, bodies)
    from graspexp.sim.trial import NullRecorder

    return nullcontext(NullRecorder())
