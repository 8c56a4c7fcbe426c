"""Learned grasp planners that run published checkpoints on CPU (the optional extra ``learned``:
``pip install -e '.[learned]'``). Nothing here is imported by :mod:`graspexp.planning` itself: torch and
Open3D load only when such a planner runs."""
