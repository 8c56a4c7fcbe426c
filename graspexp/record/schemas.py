"""Topics of a trial log, and the JSON Schemas of graspexp's own messages with the NaN <-> null convention.

The Foxglove topics (``/tf``, ``/scene``, ``/grasp_pose``, ``/contacts``) carry Foxglove's own protobuf schemas, written
by the ``foxglove-sdk`` package (see :mod:`graspexp.record.writer`); nothing here copies them. The
``graspexp.*@N`` schemas are our own JSON Schemas for what no Foxglove schema covers: bump ``N`` whenever a
field changes meaning or is removed.

NaN and infinities: JSON has no NaN, so the writer encodes every non-finite float as ``null``. In our own
schemas a float that may be NaN is declared ``{"type": ["number", "null"]}``; :func:`restore_nan` walks a
decoded message together with its schema and turns ``null`` back into ``float("nan")`` exactly there
(``+-inf`` therefore reads back as NaN). A ``null`` where the schema says ``string`` (e.g. a successful
trial's ``reason``) stays ``None``.
"""

import dataclasses
import json
import math
import types
import typing

from graspexp.core.outcome import TrialResult
from graspexp.core.phases import Phase
from graspexp.core.rounds import AttemptResult, RoundResult

SCHEMA_ENCODING = "jsonschema"
MESSAGE_ENCODING = "json"
"""Schema and message encodings of our own topics."""
PROTOBUF = "protobuf"
"""Schema and message encoding of the Foxglove topics."""

FRAME_TRANSFORMS = "foxglove.FrameTransforms"
SCENE_UPDATE = "foxglove.SceneUpdate"
POSE_IN_FRAME = "foxglove.PoseInFrame"
POINT_CLOUD = "foxglove.PointCloud"
RAW_IMAGE = "foxglove.RawImage"
CAMERA_CALIBRATION = "foxglove.CameraCalibration"
PERCEPTION = "graspexp.Perception@1"
PLANNED_GRASP = "graspexp.PlannedGrasp@1"
PHASE = "graspexp.Phase@1"
TRIAL_RESULT = "graspexp.TrialResult@5"
ROUND_RESULT = "graspexp.RoundResult@1"
READABLE_RESULTS = (
    TRIAL_RESULT,
    "graspexp.TrialResult@4",
    "graspexp.TrialResult@3",
    "graspexp.TrialResult@2",
)
"""/result schemas the readers accept: @4 is @5 without ``detail`` (then "": no reason's words were kept),
@3 is @4 without the pose-registration fields (then NaN: no pose was registered), @2 is @3 without
``at_rest`` (then True: the cap was not checked)."""

TOPIC_SCENE = "/scene"
TOPIC_TF = "/tf"
TOPIC_GRASP_POSE = "/grasp_pose"
TOPIC_CONTACTS = "/contacts"
TOPIC_GRASP = "/grasp"
TOPIC_PHASE = "/phase"
TOPIC_RESULT = "/result"
TOPIC_DEPTH = "/camera/depth"
TOPIC_IDS = "/camera/ids"
TOPIC_CALIBRATION = "/camera/calibration"
TOPIC_CLOUD = "/camera/cloud"
TOPIC_PERCEPTION = "/perception"
TOPIC_ROUND = "/round"
"""A clutter round's log (``mode=pile``/``packed``): its :class:`graspexp.core.rounds.RoundResult` with every
attempt, in place of ``/result`` (created on first use: a trial's log has none)."""
LAZY_TOPICS = (TOPIC_ROUND,)
CAMERA_TOPICS = (TOPIC_DEPTH, TOPIC_IDS, TOPIC_CALIBRATION, TOPIC_CLOUD, TOPIC_PERCEPTION)
"""Topics of a trial that rendered the depth camera (created on first use: other logs lack them).
``/camera/depth`` (32FC1, m, 0 = no return) and ``/camera/ids`` (16UC1 object ids) are one
foxglove.RawImage per view, in the view's frame (``view0``, ...: /tf, OpenCV axes);
``/camera/calibration`` its pinhole intrinsics; ``/camera/cloud`` the observed cloud in ``world``
(:data:`CLOUD_FIELDS`); ``/perception`` the registered pose, its errors and the registration's fitness."""
CLOUD_FIELDS = ("x", "y", "z", "normal_x", "normal_y", "normal_z")
"""float32 fields of a /camera/cloud point (world m, unit normal), then ``id`` (uint32, object id)."""

TOPIC_SCHEMAS: dict[str, str] = {
    TOPIC_SCENE: SCENE_UPDATE,
    TOPIC_TF: FRAME_TRANSFORMS,
    TOPIC_GRASP_POSE: POSE_IN_FRAME,
    TOPIC_CONTACTS: POINT_CLOUD,
    TOPIC_GRASP: PLANNED_GRASP,
    TOPIC_PHASE: PHASE,
    TOPIC_RESULT: TRIAL_RESULT,
    TOPIC_DEPTH: RAW_IMAGE,
    TOPIC_IDS: RAW_IMAGE,
    TOPIC_CALIBRATION: CAMERA_CALIBRATION,
    TOPIC_CLOUD: POINT_CLOUD,
    TOPIC_PERCEPTION: PERCEPTION,
    TOPIC_ROUND: ROUND_RESULT,
}
"""Topic -> schema name, one channel per topic."""

PHASE_NAMES = tuple(p.value for p in Phase)
"""The phase names the trial and round protocols use (:class:`graspexp.core.phases.Phase`; the Phase schema
accepts any string)."""

METADATA_NAME = "graspexp"
"""Name of the MCAP metadata record holding the resolved config, seeds and versions."""

CONTACT_FLOATS = (
    "x",
    "y",
    "z",
    "normal_x",
    "normal_y",
    "normal_z",
    "force_x",
    "force_y",
    "force_z",
    "separation",
)
"""/contacts is a foxglove.PointCloud in the world frame, one point per touching body pair: these float32
fields (position m, unit normal, force on body0 N, signed separation m), then ``body0`` and ``body1`` as
uint8 indices into the body names stored as the channel's metadata ``bodies`` (comma-separated; see
:data:`graspexp.record.channels.BODY_NAMES`), padded to :data:`CONTACT_STRIDE` bytes."""
CONTACT_BODIES = ("body0", "body1")
CONTACT_STRIDE = 4 * len(CONTACT_FLOATS) + 4
CONTACT_FORMAT = f"<{len(CONTACT_FLOATS)}f2B2x"
"""struct format of one /contacts point (little-endian)."""
PARTIAL_SUFFIX = ".partial"
"""A log being written (or abandoned) has this suffix after ``.mcap``."""

_NUMBER_OR_NAN = {"type": ["number", "null"], "description": "null encodes NaN"}


def _time(description: str) -> dict:
    return {
        "type": "object",
        "title": "time",
        "properties": {
            "sec": {"type": "integer", "minimum": 0},
            "nsec": {"type": "integer", "minimum": 0, "maximum": 999999999},
        },
        "description": description,
    }


def _vec3(description: str) -> dict:
    return {
        "type": "array",
        "items": _NUMBER_OR_NAN,
        "minItems": 3,
        "maxItems": 3,
        "description": description,
    }


def _planned_grasp() -> dict:
    integer_or_null = {"type": ["integer", "null"]}
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": PLANNED_GRASP,
        "description": "The grasp chosen by the planner, with the search statistics behind it.",
        "type": "object",
        "properties": {
            "timestamp": _time("Simulation time at which the grasp was planned"),
            "pose": {
                "type": "array",
                "items": {"type": "array", "items": _NUMBER_OR_NAN, "minItems": 4, "maxItems": 4},
                "minItems": 4,
                "maxItems": 4,
                "description": "Gripper pose in the world frame: 4x4 homogeneous matrix, row-major, m",
            },
            "approach": _vec3("Unit approach direction of the gripper, world frame"),
            "width_m": {**_NUMBER_OR_NAN, "description": "Opening width at the contacts, m"},
            "cost": {**_NUMBER_OR_NAN, "description": "Planner cost of the chosen grasp (lower is better)"},
            "cluster": {**integer_or_null, "description": "Index of the chosen cluster"},
            "path": {**integer_or_null, "description": "Index of the chosen approach path"},
            "planner": {"type": "string", "description": "Registered planner name"},
            "K": {**integer_or_null, "description": "Number of clusters"},
            "M": {**integer_or_null, "description": "Number of approach paths per cluster"},
            "n_feasible": {"type": "integer", "minimum": 0, "description": "Number of feasible paths"},
            "touches_neighbours": {
                "type": "boolean",
                "description": "Planned for the target alone: the gripper may touch a neighbour (clutter)",
            },
        },
        "required": ["timestamp", "pose", "approach", "width_m", "cost", "planner", "n_feasible"],
    }


def _phase() -> dict:
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": PHASE,
        "description": "Start of a protocol phase (" + ", ".join(PHASE_NAMES) + ").",
        "type": "object",
        "properties": {
            "timestamp": _time("Simulation time at which the phase starts"),
            "name": {"type": "string", "description": "Phase name"},
            "info": {
                "type": ["object", "null"],
                "description": "Free-form details (non-finite floats: null)",
            },
        },
        "required": ["timestamp", "name"],
    }


def _perception() -> dict:
    matrix = {
        "type": "array",
        "items": {"type": "array", "items": _NUMBER_OR_NAN, "minItems": 4, "maxItems": 4},
        "minItems": 4,
        "maxItems": 4,
    }
    number = dict(_NUMBER_OR_NAN)
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": PERCEPTION,
        "description": "What the planner was told about the object at planning time (perception.*).",
        "type": "object",
        "properties": {
            "timestamp": _time("Simulation time of the camera frame"),
            "source": {"type": "string", "description": "perception.source: truth or depth"},
            "true_pose": {**matrix, "description": "True object pose, world, 4x4 row-major, m"},
            "prior_pose": {**matrix, "description": "Noisy true pose (the registration's prior), m"},
            "estimated_pose": {**matrix, "description": "Registered pose (source depth), m"},
            "method": {"type": "string", "description": "icp or global+icp"},
            "trans_mm": {**number, "description": "Translation error of the registered pose, mm"},
            "rot_deg": {**number, "description": "Rotation error of the registered pose, degrees"},
            "adds_mm": {**number, "description": "ADD-S of the registered pose, mm"},
            "fitness": {**number, "description": "Share of model points with a correspondence"},
            "rmse_m": {**number, "description": "RMS distance of the correspondences, m"},
            "n_points": {"type": "integer", "minimum": 0, "description": "Observed cloud size"},
            "n_target_points": {"type": "integer", "minimum": 0, "description": "Points on the target"},
        },
        "required": ["timestamp", "source", "true_pose", "prior_pose", "n_points", "n_target_points"],
    }


def _annotation_schema(tp: object) -> dict:
    """JSON Schema for one TrialResult field annotation."""
    if tp is bool:
        return {"type": "boolean"}
    if tp is int:
        return {"type": "integer"}
    if tp is float:
        return dict(_NUMBER_OR_NAN)
    if tp is str:
        return {"type": "string"}
    origin, args = typing.get_origin(tp), typing.get_args(tp)
    if origin in (types.UnionType, typing.Union) and len(args) == 2 and type(None) in args:
        (inner,) = [a for a in args if a is not type(None)]
        schema = _annotation_schema(inner)
        kinds = schema["type"] if isinstance(schema["type"], list) else [schema["type"]]
        return {**schema, "type": sorted(set(kinds) | {"null"})}
    if origin is list and len(args) == 1:
        return {"type": "array", "items": _annotation_schema(args[0])}
    if origin is dict and len(args) == 2 and args[0] is str:
        return {"type": "object", "additionalProperties": _annotation_schema(args[1])}
    raise TypeError(f"TrialResult field type {tp!r} has no JSON Schema mapping in graspexp.record.schemas")


def _dataclass_schema(cls: type, title: str | None = None, given: dict | None = None) -> dict:
    """JSON Schema of a result dataclass's ``to_dict()`` (every field required); ``given``: field -> schema
    for the fields whose annotation says too little."""
    hints = typing.get_type_hints(cls)
    fields = dataclasses.fields(cls)
    given = given or {}
    out = {
        "type": "object",
        "properties": {f.name: given.get(f.name) or _annotation_schema(hints[f.name]) for f in fields},
        "required": [f.name for f in fields],
    }
    if title is None:
        return out
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": title,
        "description": f"{cls.__module__}.{cls.__name__}.to_dict(); NaN floats are encoded as null.",
        **out,
    }


def _trial_result() -> dict:
    return _dataclass_schema(TrialResult, TRIAL_RESULT)


def _round_result() -> dict:
    attempts = {"type": "array", "items": _dataclass_schema(AttemptResult)}
    return _dataclass_schema(RoundResult, ROUND_RESULT, {"attempts": attempts})


SCHEMAS: dict[str, dict] = {
    PLANNED_GRASP: _planned_grasp(),
    PHASE: _phase(),
    TRIAL_RESULT: _trial_result(),
    PERCEPTION: _perception(),
    ROUND_RESULT: _round_result(),
}
"""Our own schema name -> JSON Schema document (the Foxglove topics carry protobuf schemas from the SDK)."""


def schema_bytes(name: str) -> bytes:
    """The schema document as stored in the MCAP Schema record (compact, deterministic JSON)."""
    return json.dumps(SCHEMAS[name], separators=(",", ":")).encode()


def restore_nan(value: object, schema: dict) -> object:
    """Turn ``null`` back into NaN wherever ``schema`` allows a number; recurse into objects and arrays."""
    kinds = schema.get("type")
    kinds = kinds if isinstance(kinds, list) else [kinds]
    if value is None:
        return math.nan if "number" in kinds else None
    if isinstance(value, dict):
        props = schema.get("properties", {})
        extra = schema.get("additionalProperties")
        out = {}
        for k, v in value.items():
            sub = props.get(k, extra if isinstance(extra, dict) else None)
            out[k] = restore_nan(v, sub) if sub is not None else v
        return out
    if isinstance(value, list) and isinstance(schema.get("items"), dict):
        return [restore_nan(v, schema["items"]) for v in value]
    return value
