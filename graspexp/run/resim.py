"""Re-run a logged trial from its MCAP metadata and compare the outcome and the logged poses."""

import os
from pathlib import Path

import numpy as np

from graspexp.config.errors import ConfigError
from graspexp.config.registry import job_config_from_yaml
from graspexp.datasets.catalog import DATA_ENV
from graspexp.run.objects import load_sim_object, round_context, trial_context
from graspexp.run.provenance import recorded_pool
from graspexp.sim.rounds import run_round
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
    if log.round_result is not None:
        return _resimulate_round(log, cfg, plain)
    name, trial, seed = meta["object"], int(meta["trial"]), int(meta["trial_seed"])
    loaded = load_sim_object(cfg, name, plain)
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
    problems += _pose_differences(log, capture)
    if problems:
        return False, "; ".join(problems)
    n = sum(len(v[0]) for v in log.transforms.values())
    return True, f"outcome ({'success' if result.success else result.reason}) and {n} logged poses reproduced"


def _pose_differences(log, capture: _PoseCapture) -> list[str]:
    """One line per logged frame whose re-simulated poses differ (count, or beyond :data:`POSE_TOLERANCE`)."""
    problems = []
    for frame, (times, pos, quat) in log.transforms.items():
        sim = capture.samples.get(frame, [])
        if len(sim) != len(times):
            problems.append(f"frame {frame}: {len(times)} logged samples, {len(sim)} re-simulated")
            continue
        ours = np.array([s[1] for s in sim])
        err = np.abs(np.concatenate([pos, quat], axis=1) - ours).max() if len(sim) else 0.0
        if err > POSE_TOLERANCE:
            problems.append(f"frame {frame}: poses differ by up to {err:.3g}")
    return problems


def _resimulate_round(log, cfg, plain) -> tuple[bool, str]:
    """:func:`resimulate` for a clutter round's log: the drawn objects (``round_objects``) placed again from
    the round's seed; every attempt's target and outcome, the round's end and every logged pose compared."""
    meta = log.metadata
    names = str(meta.get("round_objects", "")).split()
    if not names:
        raise ConfigError("the round log's metadata lacks round_objects (the objects drawn for the round)")
    loaded = [load_sim_object(cfg, name, plain) for name in names]
    capture = _PoseCapture()
    ctx = round_context(plain, loaded, int(meta["trial"]), int(meta["trial_seed"]), capture)
    result = run_round(ctx)
    logged = log.round_result
    problems = _pool_mesh_differences(meta, loaded)
    if (logged["end"], logged["removed"]) != (result.end, result.removed):
        problems.append(
            f"round differs: logged end={logged['end']} removed={logged['removed']}, re-simulated "
            f"end={result.end} removed={result.removed}"
        )
    key = ("attempt", "target", "slot", "success", "reason")
    ours = [tuple(getattr(a, k) for k in key) for a in result.attempts]
    theirs = [tuple(a[k] for k in key) for a in logged["attempts"]]
    if ours != theirs:
        problems.append(f"attempts differ: logged {theirs}, re-simulated {ours}")
    problems += _pose_differences(log, capture)
    if problems:
        return False, "; ".join(problems)
    n = sum(len(v[0]) for v in log.transforms.values())
    return (
        True,
        f"round ({result.end}, {len(result.removed)}/{len(result.placed)} removed, {len(ours)} attempts) and {n} logged poses reproduced",
    )


def _pool_mesh_differences(meta: dict, loaded: list) -> list[str]:
    """One "mesh differs" line per drawn object whose mesh the round log's pool (``round_pool``) records with
    another SHA-256 than this data root gives (a round logged before pools were recorded: none)."""
    try:
        pool = {e["name"]: e for e in recorded_pool(meta) or []}
    except (ValueError, RecursionError) as exc:
        raise ConfigError(f"the round log's metadata: {exc}") from None
    problems = []
    for o in {o.model.name: o for o in loaded}.values():
        recorded = pool.get(o.model.name, {}).get("mesh_sha256")
        if recorded and recorded != o.model.mesh_sha256:
            was = pool[o.model.name].get("mesh_source") or "a procedural mesh"
            problems.append(
                f"mesh differs: {o.model.name}: the log was made on {was} (sha256 {recorded[:12]}), this data "
                f"root gives {o.model.source or 'a procedural mesh'} (sha256 {o.model.mesh_sha256[:12]})"
            )
    return problems
