"""``mode.scene=packed``: the objects stood upright (their own +Z up, random yaw) at random places in the
workspace that keep a gap between their footprints (VGN's and GIGA's ``generate_packed``, ethz-asl/vgn
``src/vgn/simulation.py``); an object that finds no place in :data:`PLACE_TRIES` tries is left out."""

from collections.abc import Sequence

import numpy as np

from graspexp.config import JobConfig
from graspexp.config.mode import ClutterModeConfig
from graspexp.core.bodies import clutter_body
from graspexp.core.geometry import make_pose, yaw_rotation
from graspexp.datasets.model import ObjectModel
from graspexp.sim.round_scene import ClutterScene, RoundObject, add_clutter_object
from graspexp.sim.round_sim import RoundSim
from graspexp.sim.scene_types import register

PLACE_TRIES = 200
"""Random places tried per object of a packed scene before it is left out of the round."""


@register("packed")
class Packed:
    """Side by side, upright, not touching (:func:`packed_poses`); no fixture."""

    def fixtures(self, ts: ClutterScene, cfg: JobConfig) -> None:
        pass

    def place(self, sim: RoundSim, objects: Sequence[RoundObject], rng: np.random.Generator) -> None:
        cfg = sim.cfg
        poses = packed_poses([o.model for o in objects], cfg.mode, float(cfg.rot.drop_height_m), rng)
        for slot, (obj, pose) in enumerate(zip(objects, poses, strict=True)):
            if pose is not None:
                add_clutter_object(sim.ts, clutter_body(slot), obj.model, obj.shape, pose, cfg)


def packed_poses(
    models: list[ObjectModel], mode: ClutterModeConfig, gap_m: float, rng: np.random.Generator
) -> list[np.ndarray | None]:
    """Upright (the model's own +Z up, random yaw) places in the workspace whose footprints keep
    ``mode.placement_gap_m`` apart: each footprint is the model's x-y bounding rectangle turned by the yaw
    (separating-axis test), lying wholly inside ``mode.workspace_half_size_m``; the lowest point ``gap_m``
    above the table. Placed in slot order; None for an object that found no place in :data:`PLACE_TRIES`
    tries (left out: a round of large objects places fewer)."""
    ws = np.asarray(mode.workspace_half_size_m, dtype=float)
    placed: list[
        tuple[np.ndarray, np.ndarray, np.ndarray]
    ] = []  # (centre (2,), axes (2, 2) columns, half (2,))
    out: list[np.ndarray | None] = [None] * len(models)
    bounds = [(m.mesh.vertices.min(axis=0), m.mesh.vertices.max(axis=0)) for m in models]
    for i in range(len(models)):
        lo, hi = bounds[i]
        mid, half = (lo + hi)[:2] / 2, (hi - lo)[:2] / 2
        for _ in range(PLACE_TRIES):
            R = yaw_rotation(rng.uniform(0.0, 2.0 * np.pi))
            axes = R[:2, :2]
            reach = np.abs(axes) @ half  # (2,) half extents of the turned rectangle's bounding box
            room = ws - reach
            if np.any(room < 0):
                continue
            centre = rng.uniform(-room, room)
            if all(_apart(centre, axes, half, *other, mode.placement_gap_m) for other in placed):
                placed.append((centre, axes, half))
                t = np.zeros(3)
                t[:2] = centre - axes @ mid
                t[2] = float(mode.support_height_m) + gap_m - lo[2]
                out[i] = make_pose(R, t)
                break
    return out


def _apart(
    c1: np.ndarray,
    a1: np.ndarray,
    h1: np.ndarray,
    c2: np.ndarray,
    a2: np.ndarray,
    h2: np.ndarray,
    gap_m: float,
) -> bool:
    """Whether two turned rectangles (centre (2,), unit axes as columns (2, 2), half sizes (2,)) are at least
    ``gap_m`` apart along some axis of either (separating-axis test)."""
    d = c2 - c1
    for axis in (*a1.T, *a2.T):
        r1 = np.abs(a1.T @ axis) @ h1
        r2 = np.abs(a2.T @ axis) @ h2
        if abs(d @ axis) >= r1 + r2 + gap_m:
            return True
    return False
