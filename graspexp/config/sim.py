"""Schema of the ``sim`` config group: SAPIEN/PhysX settings and the trial protocol's tunables."""

from dataclasses import dataclass


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
