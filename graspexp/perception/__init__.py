"""Perception: what a planner is told about the world, all of it in this stage (between datasets and
planning; imports no later stage). :mod:`graspexp.perception.scene_view` is what the simulator asks at
planning time: the planner's view of a trial (:func:`~graspexp.perception.scene_view.perceive`) or of a
clutter scene (:func:`~graspexp.perception.scene_view.perceive_scene`). ``perception.source=truth`` hands the
planner the exact pose (the paper's experiments); ``depth`` renders the scene with a simulated depth camera
(:mod:`graspexp.perception.camera`, a CPU ray caster, with the noise model its preset carries,
:mod:`graspexp.perception.depth_noise`) and registers the object's model to the observed cloud
(:mod:`graspexp.perception.registration`). The camera's output reaches planners as an :class:`Observation`;
volumetric planners fuse its views into a TSDF (:mod:`graspexp.perception.tsdf`).

Importing this package loads numpy only: the ray caster (embreex) and Open3D load when first used.
"""

from graspexp.perception.observation import CameraView, Observation

__all__ = ["CameraView", "Observation"]
