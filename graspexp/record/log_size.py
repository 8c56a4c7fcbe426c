"""How large a log's camera images make it, and the one line that says so before a job writes logs that
large.

A trial that renders the camera (``perception.source=depth``, or a planner that reads the camera:
:func:`graspexp.perception.scene_view.wants_camera`) logs, per view, its depth image (``32FC1``: 4 bytes a
pixel) and its body-id image (``16UC1``: 2 bytes a pixel) (:meth:`graspexp.record.writer.TrialWriter.perception`):
``width_px x height_px x views x 6`` bytes an observation, before the log's LZ4 compression (which
shrinks the background's constant pixels: a 4096 x 4096 four-view trial's 403 MB of images make a 322 MB
log). A single-object trial logs one observation; a clutter round one per attempt.

Decided: a warning, not a refusal. A large log is a legitimate choice (a high-resolution study), the size
is known before the first trial (this estimate), ``record=false`` writes none, and a disk that fills is
already one line naming the log (:func:`graspexp.record.writer.is_write_error`); no hard limit is needed
as the camera's constraints bound each image (4096 x 4096 px). What must not happen is writing hundreds
of MB a trial without a word: :func:`log_size_warning` is printed once per job, before its first trial.
"""

from graspexp.config.job import JobConfig
from graspexp.perception.scene_view import wants_camera

IMAGE_BYTES_PER_PX = 4 + 2
"""Bytes a pixel of one view costs in the log: the 32FC1 depth image and the 16UC1 body-id image."""
LOG_WARN_BYTES = 100_000_000
"""A job whose camera images alone make more than this a trial (a clutter attempt) is warned, bytes
(100 MB). Why there: the D435 preset logs 0.6 MB (424 x 240, one view) and the D435's largest depth mode
in four views (1280 x 720 x 4) 22 MB, so only a camera far beyond a real sensor's reaches it, while a run of
the paper's size (a few thousand trials) at 100 MB a trial fills hundreds of GB."""


def camera_log_bytes(cfg: JobConfig) -> int:
    """Bytes of camera images one observation of ``cfg``'s camera logs (uncompressed; 0 when the trial
    renders no camera)."""
    if not wants_camera(cfg):
        return 0
    cam = cfg.perception.camera
    return int(cam.width_px) * int(cam.height_px) * len(cam.azimuths_deg) * IMAGE_BYTES_PER_PX


def log_size_warning(cfg: JobConfig) -> str:
    """'' or one line: ``cfg`` writes logs (``record=true``) whose camera images exceed
    :data:`LOG_WARN_BYTES` a trial, with the estimate and how to shrink it."""
    size = camera_log_bytes(cfg) if cfg.record else 0
    if size <= LOG_WARN_BYTES:
        return ""
    cam = cfg.perception.camera
    return (
        f"perception.camera {cam.width_px} x {cam.height_px} px x {len(cam.azimuths_deg)} view(s) logs about "
        f"{size / 1e6:.0f} MB of depth and id images per trial (per attempt in a clutter round) before "
        f"compression, above the {LOG_WARN_BYTES / 1e6:.0f} MB this warns at: lower "
        "perception.camera.width_px/height_px or the azimuths, or record=false to write no log"
    )
