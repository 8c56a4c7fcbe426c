"""Re-run a logged trial from its MCAP metadata and compare the outcome and the logged poses."""

import os
from pathlib import Path

import numpy as np

from graspexp.config.errors import ConfigError
from graspexp.config.registry import job_config_from_yaml
from graspexp.datasets.catalog import DATA_ENV
from graspexp.run.objects import load_object, trial_context
from graspexp.sim.trial import NullRecorder, plain_config, run_trial

POSE_TOLERANCE = 1e-6
"""Largest difference allowed between a logged and a re-simulated pose component (m, or unit quaternion)."""


class _PoseCapture(NullRecorder):
    """Keeps the transforms a trial would log, in memory."""

    active = True

    def __init__(self):
        self.samples: dict[str, list[tuple[float, np.ndarray]]] = {}

    def transforms(self, t_s: float, frames: dict) -> None:
        for name, (p, q) in frames.items():
            self.samples.setdefault(name, []).append((t_s, np.concatenate([p, q]).astype(float)))


def resimulate(log) -> tuple[bool, str]:
    """Rebuild the trial in ``log`` (a :class:`graspexp.record.TrialLog`), run it, compare.

    Returns (agrees, explanation): agrees when success, failure reason and every logged frame pose
    match within :data:`POSE_TOLERANCE`. The mesh is read from the config's ``dataset.root``, else
    ``$GRASPEXP_DATA``, else the data root the log recorded (when it exists here).
    """
    meta = log.metadata
    missing = [k for k in ("config_yaml", "object", "trial", "trial_seed") if k not in meta]
    if missing or not (str(meta.get("trial", "")).isdigit() and str(meta.get("trial_seed", "")).isdigit()):
        raise ConfigError(f"the log's metadata lacks a valid {', '.join(missing) or 'trial / trial_seed'}")
    cfg = job_config_from_yaml(meta["config_yaml"])
    recorded_root = meta.get("data_root")
    if (
        cfg.dataset.root is None
        and recorded_root
        and Path(recorded_root).is_dir()
        and not os.environ.get(DATA_ENV)
    ):
        cfg.dataset.root = recorded_root  # the folder the trial read its mesh from, when no other is named
    plain = plain_config(cfg)
    name, trial, seed = meta["object"], int(meta["trial"]), int(meta["trial_seed"])
    loaded = load_object(cfg, name, plain)
    model, shape = loaded.model, loaded.hulls
    capture = _PoseCapture()
    result = run_trial(trial_context(plain, loaded, trial, capture, seed=seed))  # the seed the log recorded
    logged = log.result or {}
    problems = []
    recorded = meta.get("mesh_sha256")
    if recorded is not None and recorded != model.mesh_sha256:
        problems.append(
            f"mesh differs: the log was made on {meta.get('mesh_source') or 'a procedural mesh'} (sha256 "
            f"{recorded[:12]}), this data root gives {model.source or 'a procedural mesh'} (sha256 "
            f"{model.mesh_sha256[:12]})"
        )
    if meta.get("collision_method", shape.method) != shape.method:
        problems.append(
            f"collision method differs: {meta['collision_method']} in the log, {shape.method} now"
        )
    if bool(logged.get("success")) != result.success or logged.get("reason") != result.reason:
        problems.append(
            f"outcome differs: logged success={logged.get('success')} reason={logged.get('reason')}, "
            f"re-simulated success={result.success} reason={result.reason}"
        )
    for frame, (times, pos, quat) in log.transforms.items():
        sim = capture.samples.get(frame, [])
        if len(sim) != len(times):
            problems.append(f"frame {frame}: {len(times)} logged samples, {len(sim)} re-simulated")
            continue
        ours = np.array([s[1] for s in sim])
        err = np.abs(np.concatenate([pos, quat], axis=1) - ours).max() if len(sim) else 0.0
        if err > POSE_TOLERANCE:
            problems.append(f"frame {frame}: poses differ by up to {err:.3g}")
    if problems:
        return False, "; ".join(problems)
    n = sum(len(v[0]) for v in log.transforms.values())
    return True, f"outcome ({'success' if result.success else result.reason}) and {n} logged poses reproduced"
