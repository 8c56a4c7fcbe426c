"""Re-run a logged trial from its MCAP metadata and compare the outcome and the logged poses."""

import numpy as np
from omegaconf import OmegaConf

from graspexp.config.registry import job_config_from_yaml
from graspexp.datasets import job_object
from graspexp.planning import plan
from graspexp.quality import fc_min_mu
from graspexp.sim.collision_shapes import collision_shape
from graspexp.sim.trial import NullRecorder, TrialContext, run_trial

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
    match within :data:`POSE_TOLERANCE`.
    """
    meta = log.metadata
    cfg = job_config_from_yaml(meta["config_yaml"])
    plain = OmegaConf.to_object(cfg)
    name, trial, seed = meta["object"], int(meta["trial"]), int(meta["trial_seed"])
    model = job_object(cfg, name)
    capture = _PoseCapture()
    result = run_trial(
        TrialContext(
            plain,
            model,
            collision_shape(model.mesh, plain.sim),
            trial,
            seed,
            capture,
            plan=plan,
            quality=fc_min_mu,
        )
    )
    logged = log.result or {}
    problems = []
    recorded = meta.get("mesh_sha256")
    if recorded is not None and recorded != model.mesh_sha256:
        problems.append(
            f"mesh differs: the log was made on {meta.get('mesh_source') or 'a procedural mesh'} (sha256 "
            f"{recorded[:12]}), this data root gives {model.source or 'a procedural mesh'} (sha256 "
            f"{model.mesh_sha256[:12]})"
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
