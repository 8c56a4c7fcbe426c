"""MCAP trial logs: one file per trial, written by :class:`TrialRecorder`, read by :func:`read_trial`.

Topics (log_time = simulation time in ns): ``/tf`` foxglove.FrameTransforms, ``/scene``
foxglove.SceneUpdate, ``/contacts`` foxglove.PointCloud and ``/grasp_pose`` foxglove.PoseInFrame (protobuf,
Foxglove's schemas, written by ``foxglove-sdk``); ``/grasp`` graspexp.PlannedGrasp@1, ``/phase``
graspexp.Phase@1, ``/result`` graspexp.TrialResult@5 (JSON, our own JSON Schemas). The scene entities are
built by :mod:`graspexp.record.scene` (imported on its own: it needs the simulator's geometry).
"""

from graspexp.record.reader import (
    CorruptLogError,
    OldLogFormatError,
    TrialLog,
    iter_trial_logs,
    read_result,
    read_round,
    read_trial,
)
from graspexp.record.writer import TrialRecorder, TrialWriter, trial_recorder

__all__ = [
    "CorruptLogError",
    "OldLogFormatError",
    "TrialLog",
    "TrialRecorder",
    "TrialWriter",
    "iter_trial_logs",
    "read_result",
    "read_round",
    "read_trial",
    "trial_recorder",
]
