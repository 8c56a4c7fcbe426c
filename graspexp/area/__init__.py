"""``python -m graspexp.area``: the alias of ``python -m graspexp area``, the grasping-area tool
(:mod:`graspexp.tools.area`)."""
