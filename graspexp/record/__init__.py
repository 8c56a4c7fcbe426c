"""MCAP trial logs: one file per trial, written by :class:`TrialRecorder`, read by :func:`read_trial`.

Topics and schemas (JSON messages, JSON Schema; log_time = simulation time in ns):
``/scene`` foxglove.SceneUpdate, ``/tf`` foxglove.FrameTransform, ``/contacts`` graspexp.Contacts@1,
``/grasp`` graspexp.PlannedGrasp@1, ``/phase`` graspexp.Phase@1, ``/result`` graspexp.TrialResult@2.
"""

from graspexp.record.reader import CorruptLogError, TrialLog, iter_trial_logs, read_result, read_trial
from graspexp.record.writer import TrialRecorder, TrialWriter, box_entity, mesh_entity

__all__ = [
    "CorruptLogError",
    "TrialLog",
    "TrialRecorder",
    "TrialWriter",
    "box_entity",
    "iter_trial_logs",
    "mesh_entity",
    "read_result",
    "read_trial",
]
