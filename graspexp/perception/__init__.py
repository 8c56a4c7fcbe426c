"""Perception: what a planner is told about the world (between datasets and planning; imports no later
stage). ``perception.source=truth`` hands the planner the exact pose (the paper's experiments);
``depth`` renders the scene with a simulated depth camera (:mod:`graspexp.perception.camera`, a CPU ray
caster with a published noise model, :mod:`graspexp.perception.depth_noise`) and registers the object's
model to the observed cloud (:mod:`graspexp.perception.registration`). The camera's output reaches
planners as an :class:`Observation`.

Importing this package loads numpy only: the ray caster (embreex) and Open3D load when first used.
"""

from graspexp.perception.observation import CameraView, Observation

__all__ = ["CameraView", "Observation"]
