"""The gripper model, as objects have theirs in :mod:`graspexp.datasets`: one geometry (finger and palm
boxes, or a URDF's convex pieces and meshes) that the planner's collision checks, the simulator, the log
and the figures all use. Built from a :class:`graspexp.config.GripperConfig`; the config stage holds the
keys and their allowed values only and reads no files.

Public API::

    GripperGeometry.of(gripper_cfg) -> GripperGeometry (boxes; ``hand`` for a URDF gripper)
    hand_of(gripper_cfg) -> HandMeshes | None (a URDF gripper's pieces, read once per file state)
    fill_gripper(job_cfg) -> None (a URDF gripper's stroke and palm size into the job config)
    load_hand(...) -> HandMeshes; UrdfError (a ValueError: a file that is not a parallel gripper)
    PALM, LEFT, RIGHT (the parts of a hand)
"""

from graspexp.grippers.fill import fill_gripper
from graspexp.grippers.geometry import Box, GripperGeometry, hand_of
from graspexp.grippers.urdf import LEFT, PALM, RIGHT, HandMeshes, UrdfError, load_hand

__all__ = [
    "LEFT",
    "PALM",
    "RIGHT",
    "Box",
    "GripperGeometry",
    "HandMeshes",
    "UrdfError",
    "fill_gripper",
    "hand_of",
    "load_hand",
]
