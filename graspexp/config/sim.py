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
    slip_threshold_m: float = 0.02
    """Slip = how far the grasp point (TCP) moved over the object, in the object frame, between closing
    and the end of the hold; above this the grasp slipped, m."""
    max_speed_mps: float = 20.0
    """Any body faster than this (or NaN) means the simulation blew up, m/s."""
    log_rate_hz: float = 30.0
    """Sim-time rate of transforms and contacts in the MCAP log, Hz."""
    collision_method: str = "mesh"
    """Object collision geometry: ``mesh`` (each sizeable part of the mesh repaired to a closed surface,
    decimated, checked, and collided as a PhysX SDF triangle mesh), ``coacd`` or ``vhacd`` (convex
    decompositions). ``mesh`` is the one within 1 mm of every staged object: 90th percentile of the
    collision surface outside the mesh <= 0.26 mm on all 32, against 3.7-5.5 mm for CoACD at the
    settings below (``python -m graspexp.bench.collision_shapes``)."""
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
