"""Schema of the ``cost`` config group: every constant of the paper's Eq. (1)-(3).

The constants are only meaningful with distances in millimetres and alpha in degrees (beta in radians),
exactly as printed in the paper.
"""

from dataclasses import dataclass

from graspexp.config.constraints import Interval


@dataclass
class CostConfig:
    """Every constant of Eq. (1)-(3); defaults are the paper's values."""

    angle_weight: float = 0.1
    """0.1 in (0.1 |alpha_p - 90| + 0.5) / 8, per degree."""
    angle_target_deg: float = 90.0
    """90 in |alpha_p - 90|, degrees."""
    angle_offset: float = 0.5
    """0.5 in (0.1 |alpha_p - 90| + 0.5) / 8."""
    angle_divisor: float = 8.0
    """8 in (0.1 |alpha_p - 90| + 0.5) / 8."""
    distance_numerator_mm2: float = 20.0
    """20 in min(1, 20 / ((Y_ip - r_k)^2 + 1)), mm^2."""
    distance_offset_mm2: float = 1.0
    """1 in min(1, 20 / ((Y_ip - r_k)^2 + 1)), mm^2."""
    distance_cap: float = 1.0
    """1 in min(1, ...)."""
    table_beta_target_rad: float = 1.5707963267948966
    """pi/2 in (beta_p - pi/2)^2 / 2 + 0.05, radians."""
    table_beta_divisor: float = 2.0
    """2 in (beta_p - pi/2)^2 / 2 + 0.05."""
    table_offset: float = 0.05
    """0.05 in (beta_p - pi/2)^2 / 2 + 0.05."""
    table_far: float = 1.0
    """T when d_k > g."""


CONSTRAINTS = {
    "angle_weight": [Interval(0, None, unit="per degree")],
    "angle_target_deg": [Interval(0, 90, unit="deg")],
    "angle_offset": [Interval(0, None)],
    "angle_divisor": [Interval(0, None, "neither")],
    "distance_numerator_mm2": [Interval(0, None, unit="mm^2")],
    "distance_offset_mm2": [Interval(0, None, "neither", "mm^2")],
    "distance_cap": [Interval(0, None)],
    "table_beta_target_rad": [Interval(0, 1.5707963267948966, unit="rad")],
    "table_beta_divisor": [Interval(0, None, "neither")],
    "table_offset": [Interval(0, None)],
    "table_far": [Interval(0, None)],
}
"""Allowed values of every ``cost`` key (see :mod:`graspexp.config.constraints`)."""
