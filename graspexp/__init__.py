"""graspexp: reproduce and extend an analytic parallel-gripper grasp planner in SAPIEN physics."""

__version__ = "0.1.0"
