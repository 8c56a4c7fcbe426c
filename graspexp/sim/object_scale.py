"""The per-scene object scale of a clutter round (``mode.object_scale``): VGN's and GIGA's protocol scales
every placed object by a factor drawn per object and scene (U(0.8, 1.0) in pile scenes, U(0.7, 0.9) in
packed; ethz-asl/vgn ``src/vgn/simulation.py``, PyBullet's ``globalScaling``).

A scene type scales the round's objects before it places them (:func:`scale_round_objects`), so that the
round places, renders, plans and grasps the scaled ones. A factor of exactly 1 leaves an object untouched
(the same model and shape, not a copy), and the range [1, 1] draws nothing: the rounds of every preset stay
as they were.
"""

import dataclasses
from collections.abc import MutableSequence

import numpy as np
import trimesh

from graspexp.config.mode import ClutterModeConfig
from graspexp.datasets.model import ObjectModel
from graspexp.sim.round_scene import RoundObject
from graspexp.sim.shape import CollisionShape


def draw_scales(mode: ClutterModeConfig, n: int, rng: np.random.Generator) -> np.ndarray | None:
    """The scale factors (n,) of a round's ``n`` objects by slot, uniform in ``mode.object_scale``: drawn from
    ``rng`` (n draws, before any other) only when the range is not a single value; None for [1, 1]."""
    lo, hi = (float(v) for v in mode.object_scale)
    if lo == hi:
        return None if lo == 1.0 else np.full(n, lo)
    return rng.uniform(lo, hi, size=n)


def scaled_model(model: ObjectModel, scale: float) -> ObjectModel:
    """``model`` scaled by ``scale`` about its origin: mesh and cloud (object frame, metres) times ``scale``;
    normals, grasping area, mass (PyBullet's ``globalScaling`` keeps a URDF's mass, VGN's protocol), name and
    source unchanged. ``scale`` 1: ``model`` itself."""
    if scale == 1.0:
        return model
    mesh = trimesh.Trimesh(
        np.asarray(model.mesh.vertices) * scale, np.asarray(model.mesh.faces), process=False
    )
    return dataclasses.replace(model, mesh=mesh, points=np.asarray(model.points) * scale)


def scaled_shape(shape: CollisionShape, scale: float) -> CollisionShape:
    """``shape`` scaled by ``scale`` about the object's origin: every part's vertices times ``scale`` (a convex
    hull stays one); a closed triangle mesh keeps its cooked file, which PhysX scales (``file_scale``). Its
    ``sha256`` is left empty (the cached entry it came from is unscaled). ``scale`` 1: ``shape`` itself."""
    if scale == 1.0:
        return shape
    parts = tuple((np.asarray(v * scale, dtype=np.float32), f) for v, f in shape.parts)
    file_scale = shape.file_scale if shape.convex else shape.file_scale * scale
    return dataclasses.replace(shape, parts=parts, sha256="", file_scale=file_scale)


def scale_round_objects(
    objects: MutableSequence[RoundObject], mode: ClutterModeConfig, rng: np.random.Generator
) -> list[float]:
    """Scale the round's objects in place (each slot's entry replaced by its scaled model and shape) by
    :func:`draw_scales`; the factors by slot (all 1.0 for [1, 1], nothing replaced)."""
    scales = draw_scales(mode, len(objects), rng)
    if scales is None:
        return [1.0] * len(objects)
    for slot, (obj, s) in enumerate(zip(list(objects), scales.tolist(), strict=True)):
        objects[slot] = RoundObject(scaled_model(obj.model, s), scaled_shape(obj.shape, s))
    return scales.tolist()
