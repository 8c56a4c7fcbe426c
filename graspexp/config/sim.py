"""Schema of the ``sim`` config group: SAPIEN/PhysX settings and the trial protocol's tunables."""

from dataclasses import dataclass

from graspexp.config.constraints import BOOL, TEXT, Interval, Options


@dataclass
class SimConfig:
    timestep_s: float = 1.0 / 240.0
    """Physics step, s."""
    solver_position_iterations: int = 20
    solver_velocity_iterations: int = 1
    enable_tgs: bool = False
    """TGS solver; off because a flat box on a single hull slides forever with TGS on."""
    contact_offset_m: float = 0.002
    rest_offset_m: float = 0.0
    object_static_friction: float = 0.6
    object_dynamic_friction: float = 0.5
    support_friction: float = 0.6
    object_angular_damping: float = 0.5
    """Angular velocity damping of the object, 1/s: stands in for rolling resistance (PhysX has none)."""
    settle_max_s: float = 3.0
    """Time cap for the drop to come to rest, s."""
    settle_min_s: float = 0.3
    settle_linear_mps: float = 0.005
    """Object counts as settled below this linear speed, m/s."""
    settle_angular_radps: float = 0.05
    """... and below this angular speed, rad/s."""
    max_redrops: int = 5
    """Re-drops allowed when the object falls off the support."""
    approach_speed_mps: float = 0.25
    """Speed of the move from pre-grasp to grasp, m/s."""
    close_s: float = 0.6
    """Time given to the fingers to close, s."""
    retract_speed_mps: float = 0.25
    """Bin mode pull-back speed, m/s."""
    slip_threshold_m: float | None = None
    """Optional stricter success criterion, m: fail as ``slipped`` when the grasp point (TCP) moved over
    the object (object frame) by more than this between closing and the end of the hold. None (default):
    the paper's criterion (IV-C), success = the object is still held; the slip is recorded either way."""
    max_speed_mps: float = 20.0
    """Any body faster than this (or NaN) means the simulation blew up, m/s."""
    log_rate_hz: float = 30.0
    """Sim-time rate of transforms and contacts in the MCAP log, Hz."""
    coacd_threshold: float = 0.1
    coacd_preprocess_resolution: int = 30
    coacd_resolution: int = 1000
    coacd_mcts_iterations: int = 50
    coacd_max_convex_hull: int = 16
    """Upper bound on hulls per object (-1: no bound)."""
    cache_dir: str | None = None
    """Convex-decomposition cache folder; None: env GRASPEXP_CACHE, else ~/.cache/graspexp."""


CONSTRAINTS = {
    "timestep_s": [Interval(0, 0.02, "right", "s")],
    "solver_position_iterations": [Interval(1, 255, integer=True)],
    "solver_velocity_iterations": [Interval(0, 255, integer=True)],
    "enable_tgs": BOOL,
    "contact_offset_m": [Interval(0, 0.1, "right", "m")],
    "rest_offset_m": [Interval(0, 0.1, "left", "m")],
    "object_static_friction": [Interval(0, 5)],
    "object_dynamic_friction": [Interval(0, 5)],
    "support_friction": [Interval(0, 5)],
    "object_angular_damping": [Interval(0, 100, unit="1/s")],
    "settle_max_s": [Interval(0, 60, "right", "s")],
    "settle_min_s": [Interval(0, 60, unit="s")],
    "settle_linear_mps": [Interval(0, 1, "right", "m/s")],
    "settle_angular_radps": [Interval(0, 10, "right", "rad/s")],
    "max_redrops": [Interval(0, 100, integer=True)],
    "approach_speed_mps": [Interval(0, 10, "right", "m/s")],
    "close_s": [Interval(0, 60, "right", "s")],
    "retract_speed_mps": [Interval(0, 10, "right", "m/s")],
    "slip_threshold_m": [None, Interval(0, 1, "right", "m")],
    "max_speed_mps": [Interval(0, 1000, "right", "m/s")],
    "log_rate_hz": [Interval(0, 1000, "right", "Hz")],
    # CoACD's documented ranges (threshold 0.01-1, preprocess resolution 20-100, resolution 1000-10000)
    "coacd_threshold": [Interval(0.01, 1)],
    "coacd_preprocess_resolution": [Interval(20, 100, integer=True)],
    "coacd_resolution": [Interval(1000, 10_000, integer=True)],
    "coacd_mcts_iterations": [Interval(1, 2000, integer=True)],
    "coacd_max_convex_hull": [Options((-1,)), Interval(1, 1000, integer=True)],
    "cache_dir": [None, *TEXT],
}
"""Allowed values of every key (see :mod:`graspexp.config.constraints`)."""
