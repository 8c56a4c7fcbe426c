"""JSON Schema documents for every MCAP channel of a trial log, and the NaN <-> null convention.

Each schema has a versioned name constant. Two are Foxglove well-known schemas, so the log opens in
Foxglove's 3D panel; their documents follow foxglove/schemas (``schemas/jsonschema/*.json``) for the
fields graspexp writes (SceneEntity carries only the ``cubes`` and ``triangles`` primitive lists; Foxglove
recognises the type by its name). The ``graspexp.*@N`` schemas are our own: bump ``N`` whenever a field
changes meaning or is removed.

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

from graspexp.sim.outcome import TrialResult

SCHEMA_ENCODING = "jsonschema"
MESSAGE_ENCODING = "json"

FRAME_TRANSFORM = "foxglove.FrameTransform"
SCENE_UPDATE = "foxglove.SceneUpdate"
CONTACTS = "graspexp.Contacts@1"
PLANNED_GRASP = "graspexp.PlannedGrasp@1"
PHASE = "graspexp.Phase@1"
TRIAL_RESULT = "graspexp.TrialResult@2"

TOPIC_SCENE = "/scene"
TOPIC_TF = "/tf"
TOPIC_CONTACTS = "/contacts"
TOPIC_GRASP = "/grasp"
TOPIC_PHASE = "/phase"
TOPIC_RESULT = "/result"

TOPIC_SCHEMAS: dict[str, str] = {
    TOPIC_SCENE: SCENE_UPDATE,
    TOPIC_TF: FRAME_TRANSFORM,
    TOPIC_CONTACTS: CONTACTS,
    TOPIC_GRASP: PLANNED_GRASP,
    TOPIC_PHASE: PHASE,
    TOPIC_RESULT: TRIAL_RESULT,
}
"""Topic -> schema name, one channel per topic."""

PHASE_NAMES = (
    "drop",
    "settled",
    "plan",
    "pre_grasp",
    "approach",
    "close",
    "remove_support",
    "pull_back",
    "lift",
    "hold",
    "done",
    "quality",
    "failed",
)
"""The phase names the trial protocol uses (the Phase schema accepts any string)."""

METADATA_NAME = "graspexp"
"""Name of the MCAP metadata record holding the resolved config, seeds and versions."""

_NUMBER_OR_NAN = {"type": ["number", "null"], "description": "null encodes NaN"}

# ---------------------------------------------------------------------------------------------------
# Foxglove building blocks (field names and titles as in foxglove/schemas jsonschema)


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


def _duration(description: str) -> dict:
    return {
        "type": "object",
        "title": "duration",
        "properties": {
            "sec": {"type": "integer"},
            "nsec": {"type": "integer", "minimum": 0, "maximum": 999999999},
        },
        "description": description,
    }


def _xyz(title: str, description: str, what: str) -> dict:
    return {
        "title": title,
        "description": description,
        "type": "object",
        "properties": {k: {"type": "number", "description": f"{k} coordinate {what}"} for k in "xyz"},
    }


def _quaternion(description: str) -> dict:
    return {
        "title": "foxglove.Quaternion",
        "description": description,
        "type": "object",
        "properties": {k: {"type": "number", "description": f"{k} value"} for k in "xyzw"},
    }


def _color(description: str) -> dict:
    names = {"r": "Red", "g": "Green", "b": "Blue", "a": "Alpha"}
    return {
        "title": "foxglove.Color",
        "description": description,
        "type": "object",
        "properties": {
            k: {"type": "number", "description": f"{v} value between 0 and 1"} for k, v in names.items()
        },
    }


def _pose(description: str) -> dict:
    return {
        "title": "foxglove.Pose",
        "description": description,
        "type": "object",
        "properties": {
            "position": _xyz("foxglove.Vector3", "Point denoting position in 3D space", "length"),
            "orientation": _quaternion("Quaternion denoting orientation in 3D space"),
        },
    }


def _cube_primitive() -> dict:
    return {
        "title": "foxglove.CubePrimitive",
        "description": "A primitive representing a cube or rectangular prism",
        "type": "object",
        "properties": {
            "pose": _pose("Position of the center of the cube and orientation of the cube"),
            "size": _xyz("foxglove.Vector3", "Size of the cube along each axis", "length"),
            "color": _color("Color of the cube"),
        },
    }


def _triangle_list_primitive() -> dict:
    return {
        "title": "foxglove.TriangleListPrimitive",
        "description": "A primitive representing a set of triangles or a surface tiled by triangles",
        "type": "object",
        "properties": {
            "pose": _pose("Origin of triangles relative to reference frame"),
            "points": {
                "type": "array",
                "items": _xyz("foxglove.Point3", "A point representing a position in 3D space", "position"),
                "description": "Vertices to use for triangles, interpreted as a list of triples (0-1-2, 3-4-5, ...)",
            },
            "color": _color(
                "Solid color to use for the whole shape. One of `color` or `colors` must be provided."
            ),
            "colors": {
                "type": "array",
                "items": _color("A color in RGBA format"),
                "description": "Per-vertex colors (if specified, must have the same length as `points`).",
            },
            "indices": {
                "type": "array",
                "items": {"type": "integer", "minimum": 0},
                "description": "Indices into the `points` and `colors` attribute arrays (empty: no indexing).",
            },
        },
    }


def _scene_entity() -> dict:
    return {
        "title": "foxglove.SceneEntity",
        "description": "A visual element in a 3D scene. An entity may be composed of multiple primitives which "
        "all share the same frame of reference.",
        "type": "object",
        "properties": {
            "timestamp": _time("Timestamp of the entity"),
            "frame_id": {"type": "string", "description": "Frame of reference"},
            "id": {"type": "string", "description": "Identifier for the entity."},
            "lifetime": _duration(
                "Length of time (relative to `timestamp`) after which the entity should be "
                "automatically removed. Zero value: remain until replaced or deleted."
            ),
            "frame_locked": {
                "type": "boolean",
                "description": "Whether the entity should keep its location in the fixed frame (false) or "
                "follow the frame specified in `frame_id` as it moves relative to the fixed frame (true)",
            },
            "metadata": {
                "type": "array",
                "items": {
                    "title": "foxglove.KeyValuePair",
                    "description": "A key with its associated value",
                    "type": "object",
                    "properties": {
                        "key": {"type": "string", "description": "Key"},
                        "value": {"type": "string", "description": "Value"},
                    },
                },
                "description": "Additional user-provided metadata associated with the entity.",
            },
            "cubes": {"type": "array", "items": _cube_primitive(), "description": "Cube primitives"},
            "triangles": {
                "type": "array",
                "items": _triangle_list_primitive(),
                "description": "Triangle list primitives",
            },
        },
    }


def _scene_update() -> dict:
    return {
        "title": SCENE_UPDATE,
        "description": "An update to the entities displayed in a 3D scene",
        "type": "object",
        "properties": {
            "deletions": {
                "type": "array",
                "items": {
                    "title": "foxglove.SceneEntityDeletion",
                    "description": "Command to remove previously published entities",
                    "type": "object",
                    "properties": {
                        "timestamp": _time("Only matching entities earlier than this timestamp are deleted."),
                        "type": {
                            "title": "foxglove.SceneEntityDeletionType",
                            "description": "Type of deletion action to perform",
                            "oneOf": [
                                {"title": "MATCHING_ID", "const": 0, "description": "Delete the entity `id`"},
                                {
                                    "title": "ALL",
                                    "const": 1,
                                    "description": "Delete all entities on the topic",
                                },
                            ],
                        },
                        "id": {"type": "string", "description": "Identifier, if `type` is `MATCHING_ID`."},
                    },
                },
                "description": "Scene entities to delete",
            },
            "entities": {
                "type": "array",
                "items": _scene_entity(),
                "description": "Scene entities to add or replace",
            },
        },
    }


def _frame_transform() -> dict:
    return {
        "title": FRAME_TRANSFORM,
        "description": "A transform between two reference frames in 3D space",
        "type": "object",
        "properties": {
            "timestamp": _time("Timestamp of transform"),
            "parent_frame_id": {"type": "string", "description": "Name of the parent frame"},
            "child_frame_id": {"type": "string", "description": "Name of the child frame"},
            "translation": _xyz("foxglove.Vector3", "Translation component of the transform", "length"),
            "rotation": _quaternion("Rotation component of the transform"),
        },
    }


# ---------------------------------------------------------------------------------------------------
# graspexp's own schemas


def _vec3(description: str) -> dict:
    return {
        "type": "array",
        "items": _NUMBER_OR_NAN,
        "minItems": 3,
        "maxItems": 3,
        "description": description,
    }


def _contacts() -> dict:
    contact = {
        "type": "object",
        "properties": {
            "body0": {"type": "string", "description": "Name of the first body"},
            "body1": {"type": "string", "description": "Name of the second body"},
            "position": _vec3("Contact point, world frame, m"),
            "normal": _vec3("Unit contact normal, world frame, as the simulator reports it"),
            "force_n": _vec3("Contact force on body0 (simulator impulse / time step), world frame, N"),
            "separation_m": {**_NUMBER_OR_NAN, "description": "Signed distance, m (negative: penetration)"},
        },
        "required": ["body0", "body1", "position", "normal", "force_n", "separation_m"],
    }
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": CONTACTS,
        "description": "All contact points of one simulation step. Magnitude: the norm of `force_n`.",
        "type": "object",
        "properties": {
            "timestamp": _time("Simulation time of the step"),
            "contacts": {"type": "array", "items": contact},
        },
        "required": ["timestamp", "contacts"],
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


def _trial_result() -> dict:
    hints = typing.get_type_hints(TrialResult)
    fields = dataclasses.fields(TrialResult)
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "title": TRIAL_RESULT,
        "description": "graspexp.sim.outcome.TrialResult.to_dict(); NaN floats are encoded as null.",
        "type": "object",
        "properties": {f.name: _annotation_schema(hints[f.name]) for f in fields},
        "required": [f.name for f in fields],
    }


SCHEMAS: dict[str, dict] = {
    FRAME_TRANSFORM: _frame_transform(),
    SCENE_UPDATE: _scene_update(),
    CONTACTS: _contacts(),
    PLANNED_GRASP: _planned_grasp(),
    PHASE: _phase(),
    TRIAL_RESULT: _trial_result(),
}
"""Schema name -> JSON Schema document."""


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
