"""Schema of the ``sim`` config group: SAPIEN/PhysX settings and the trial protocol's tunables."""

from dataclasses import dataclass

from graspexp.config.constraints import BOOL, TEXT, Interval, Options, added


@dataclass
class SimConfig:
    timestep_s: float = 1.0 / 240.0
    """Physics step, s."""
    solver_position_iterations: int = 20
    """PhysX solver position iterations per step (every body; ``sapien.physx.set_body_config``)."""
    solver_velocity_iterations: int = 1
    """PhysX solver velocity iterations per step (every body)."""
    enable_tgs: bool = False
    """TGS solver; off because a flat box on a single hull slides forever with TGS on."""
    contact_offset_m: float = 0.002
    """PhysX contact offset of every shape: contacts are generated within this distance, m (above
    ``rest_offset_m``)."""
    rest_offset_m: float = 0.0
    """PhysX rest offset of every shape: the separation at which touching shapes come to rest, m."""
    object_static_friction: float = 0.6
    """Static friction coefficient of the object (an object's sidecar ``friction`` overrides it), 1."""
    object_dynamic_friction: float = 0.5
    """Dynamic friction coefficient of the object (an object's sidecar ``friction`` overrides it), 1."""
    support_friction: float = 0.6
    """Static and dynamic friction coefficient of the support (box or table), 1."""
    object_angular_damping: float = 0.5
    """Angular velocity damping of the object, 1/s: stands in for rolling resistance (PhysX has none)."""
    settle_max_s: float = 3.0
    """Time cap for the drop to come to rest, s; an object still moving then ends its trial as
    ``not_at_rest`` (nothing is planned on a moving object)."""
    settle_min_s: float = 0.3
    """The drop is not taken as settled before this time has passed, s (at most ``settle_max_s``)."""
    settle_linear_mps: float = 0.005
    """Object counts as settled below this linear speed, m/s."""
    settle_angular_radps: float = 0.05
    """... and below this angular speed, rad/s."""
    settle_hold_s: float = added(0.1, before=0.0)
    """... for this long without a break, s (0: one step). A rocking object passes both speeds at each
    turn for a step or two: with one step, a bleach cleanser lying on its side counted as settled at
    such a turn and rolled back 4 cm into the closing fingers (YCB bin XYZ trial 6)."""
    max_redrops: int = 5
    """Re-drops allowed when the object falls off the support."""
    approach_speed_mps: float = 0.25
    """Speed of the move from pre-grasp to grasp, m/s."""
    approach_settle_s: float = added(0.2, before=0.0)
    """Time the arm holds the grasp pose after the approach before the fingers close, s. The arm's drive
    lags its moving target by damping x speed / stiffness (``gripper.arm_damping_ns_per_m`` x
    ``approach_speed_mps`` / ``gripper.arm_stiffness_n_per_m`` = 5 mm for the RG2), so with 0 the fingers
    started closing with the gripper still 4-5 mm short of the grasp pose and moving, met the object a few
    mm short of the planned pad depth and pushed it 1-2 mm along the approach as the arm caught up (logs
    of optimal_plus's mug and power-drill failures). A robot's controller reaches its goal before the
    gripper is commanded; 0.2 s is 10 time constants of the drive (damping / stiffness = 0.02 s)."""
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
    max_angular_speed_radps: float = 1.0e6
    """An object spinning faster than this (or NaN) means the simulation blew up, rad/s."""
    fell_below_m: float = 0.05
    """While settling, an object whose origin is this far below the support plane has fallen off it, m."""
    on_support_tolerance_m: float = 0.01
    """A settled object rests on the support when its lowest point is less than this below the support
    top (and its centre of mass is over the support), m."""
    min_finger_force_n: float = 0.5
    """A finger holds the object when it presses with at least this force, N."""
    log_rate_hz: float = 30.0
    """Sim-time rate of transforms and contacts in the MCAP log, Hz."""
    collision_method: str = "mesh"
    """Object collision geometry: ``mesh`` (each sizeable part of the mesh repaired to a closed surface,
    decimated, checked, and collided as a PhysX SDF triangle mesh), ``coacd`` or ``vhacd`` (convex
    decompositions). ``mesh`` is the one within 1 mm of every staged object: 90th percentile of the
    collision surface outside the mesh <= 0.26 mm on all 32, against 3.7-5.5 mm for CoACD at the
    settings below (``python -m graspexp bench.collision_shapes``)."""
    mesh_max_faces: int = 4000
    """``mesh``: first face budget for the quadric decimation of the repaired mesh. 4000 keeps every
    staged object but the bowl within 0.26 mm (p90) of the scan; 16k (no decimation) costs 1.5x per step
    in trials, and 1500 pinches the mug's wall (10 mm)."""
    mesh_tolerance_m: float = 0.0005
    """``mesh``: the repaired, decimated surface is measured against the scan (90th percentile of either
    lying outside the other); over this the face budget doubles, up to no decimation, m. Half the 1 mm
    target: decimation can collapse a thin wall (the bowl's, at 4000 faces: 8 mm)."""
    mesh_min_part_area: float = 0.01
    """``mesh``: connected parts with less than this fraction of the mesh's surface area are dropped as
    scan debris (google_16k scans carry a few specks); larger parts (a modelled mug's handle) are kept."""
    sdf_spacing_m: float = 0.005
    """``mesh``: PhysX SDF grid spacing, m. PhysX simulates a dynamic triangle mesh only with an SDF but
    computes its contacts with boxes and convex shapes (support, floor, fingers, palm) on the triangles,
    so the spacing sets only the once-per-process cooking time (mug, 16k faces: 0.3 s at 4 mm, 7 s at
    1 mm), not the contacts (tests/test_collision_shapes.py: the same landing, bit for bit)."""
    coacd_threshold: float = 0.1
    """``coacd``: concavity threshold (CoACD's unit: a fraction of the bounding-box diagonal)."""
    coacd_preprocess_resolution: int = 30
    """``coacd``: voxel resolution of CoACD's manifold pre-pass (coarse: its error alone is millimetres)."""
    coacd_resolution: int = 1000
    """``coacd``: surface samples per hull for the concavity measure."""
    coacd_mcts_iterations: int = 50
    """``coacd``: Monte-Carlo tree search iterations per cut."""
    coacd_max_convex_hull: int = 16
    """``coacd``: upper bound on hulls per object (-1: no bound)."""
    vhacd_max_hulls: int = 64
    """``vhacd``: upper bound on hulls per object."""
    vhacd_resolution: int = 100000
    """``vhacd``: voxels in the object's bounding box (V-HACD's accuracy knob; time grows with it)."""
    vhacd_min_volume_error_pct: float = 0.1
    """``vhacd``: a hull is split while it exceeds its part's volume by more than this, %."""
    vhacd_shrinkwrap: bool = True
    """``vhacd``: project hull vertices onto the mesh surface (undoes part of the voxel error)."""
    prepare_workers: int = 2
    """Processes that prepare collision shapes in parallel on a cold cache (one object per process)."""
    cache_dir: str | None = None
    """Collision-shape cache folder; None: env GRASPEXP_CACHE, else ~/.cache/graspexp."""


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
    "settle_hold_s": [Interval(0, 10, unit="s")],
    "max_redrops": [Interval(0, 100, integer=True)],
    "approach_speed_mps": [Interval(0, 10, "right", "m/s")],
    "approach_settle_s": [Interval(0, 60, unit="s")],
    "close_s": [Interval(0, 60, "right", "s")],
    "retract_speed_mps": [Interval(0, 10, "right", "m/s")],
    "slip_threshold_m": [None, Interval(0, 1, "right", "m")],
    "max_speed_mps": [Interval(0, 1000, "right", "m/s")],
    "max_angular_speed_radps": [Interval(0, 1e9, "right", "rad/s")],
    "fell_below_m": [Interval(0, 10, "right", "m")],
    "on_support_tolerance_m": [Interval(0, 1, "right", "m")],
    "min_finger_force_n": [Interval(0, 1000, "right", "N")],
    "log_rate_hz": [Interval(0, 1000, "right", "Hz")],
    "collision_method": [Options(("mesh", "coacd", "vhacd"))],
    "mesh_max_faces": [Interval(64, None, integer=True)],
    "mesh_tolerance_m": [Interval(0, 0.01, "right", "m")],
    "mesh_min_part_area": [Interval(0, 1, "left")],
    # cooking time grows as spacing^-3 (mug: 7 s at 1 mm); PhysX's own default is 1 cm
    "sdf_spacing_m": [Interval(0.0005, 0.05, unit="m")],
    # CoACD's documented ranges (threshold 0.01-1, preprocess resolution 20-100, resolution 1000-10000)
    "coacd_threshold": [Interval(0.01, 1)],
    "coacd_preprocess_resolution": [Interval(20, 100, integer=True)],
    "coacd_resolution": [Interval(1000, 10_000, integer=True)],
    "coacd_mcts_iterations": [Interval(1, 2000, integer=True)],
    "coacd_max_convex_hull": [Options((-1,)), Interval(1, 1000, integer=True)],
    "vhacd_max_hulls": [Interval(1, 1024, integer=True)],
    "vhacd_resolution": [Interval(10_000, 64_000_000, integer=True)],  # V-HACD's documented range
    "vhacd_min_volume_error_pct": [Interval(0, 100, "right", "%")],
    "vhacd_shrinkwrap": BOOL,
    "prepare_workers": [Interval(1, 64, integer=True)],
    "cache_dir": [None, *TEXT],
}
"""Allowed values of every key (see :mod:`graspexp.config.constraints`)."""
