"""Schema of the ``rot`` config group: how the object is rotated before it is dropped (paper IV-D)."""

from dataclasses import dataclass

from omegaconf import MISSING

from graspexp.config.constraints import Interval, Options


@dataclass
class RotConfig:
    name: str = MISSING
    """``z``: upright model pose turned about world Z; ``xyz``: uniformly random rotation."""
    drop_height_m: float = 0.02
    """Gap between the object's lowest point and the support top at release, m."""


CONSTRAINTS = {
    "name": [Options(("z", "xyz"))],
    "drop_height_m": [Interval(0, 1, unit="m")],
}
"""Allowed values of every key (see :mod:`graspexp.config.constraints`)."""
