"""MCAP trial logs: one file per trial, written by :class:`TrialRecorder`, read by :func:`read_trial`.

Topics (log_time = simulation time in ns): ``/tf`` foxglove.FrameTransform, ``/scene``
foxglove.SceneUpdate and ``/grasp_pose`` foxglove.PoseInFrame (protobuf, Foxglove's schemas, written by
``foxglove-sdk``); ``/contacts`` graspexp.Contacts@1, ``/grasp`` graspexp.PlannedGrasp@1, ``/phase``
graspexp.Phase@1, ``/result`` graspexp.TrialResult@2 (JSON, our own JSON Schemas).
"""

from graspexp.record.reader import (
    CorruptLogError,
    OldLogFormatError,
    TrialLog,
    iter_trial_logs,
    read_result,
    read_trial,
)
from graspexp.record.scene import ObjectScene, box_entity, mesh_entity, object_scene
from graspexp.record.writer import TrialRecorder, TrialWriter, trial_recorder

__all__ = [
    "CorruptLogError",
    "ObjectScene",
    "OldLogFormatError",
    "TrialLog",
    "TrialRecorder",
    "TrialWriter",
    "box_entity",
    "iter_trial_logs",
    "mesh_entity",
    "object_scene",
    "read_result",
    "read_trial",
    "trial_recorder",
]
