"""Schema of the ``mode`` config group: collaborative hand-over or bin picking (paper IV-A, IV-C), and
clutter removal (``pile``, ``packed``: VGN, Breyer et al. CoRL 2020; GIGA, Jiang et al. RSS 2021)."""

from dataclasses import dataclass, field, fields

from omegaconf import MISSING

from graspexp.config.constraints import BOOL, Interval, Options, Pattern, Vector


@dataclass
class ModeConfig:
    name: str = MISSING
    """``collab`` (Eq. 1; box removed after the grasp) or ``bin`` (Eq. 2-3; table, pull back): one object per
    trial; a clutter mode (:class:`ClutterModeConfig`: ``pile``, ``packed``) names its rounds' log folder
    (``trials/<name>/``)."""
    support_height_m: float = 0.10
    """Height of the support's top face above the ground plane, m (the plane z = h)."""
    support_half_size_m: list[float] = MISSING
    """Half extents [x, y] of the support top, m. The paper gives no size for its box; every one of its
    trials is a grasp of an object resting on it (IV-C), so the box must hold every dropped object. The
    collab box is 0.3 m wide, longer than the longest Table 1/2 object (LINEMOD iron 258 mm): a 0.2 m box
    let the driller (229 mm) fall off in 37 of 47 XYZ drops, 5 of its 10 trials even after 5 re-drops;
    0.3 m: 3 of 13 drops, no trial lost. The bin table is 0.8 m."""
    support_collides_with_gripper: bool = MISSING
    """False in collab mode (paper IV-A: the box is not used for gripper collisions)."""
    remove_support_after_grasp: bool = MISSING
    """True in collab mode: the box vanishes after the fingers close."""
    pull_back_m: float = 0.0
    """Bin mode: distance to retract along the approach direction after closing, m."""
    lift_m: float = 0.0
    """Bin mode: extra lift along world +Z after the pull back, m."""
    hold_s: float = 2.0
    """Time the grasp must hold at the end, s."""


@dataclass
class ClutterModeConfig(ModeConfig):
    """A clutter-removal mode (``mode=pile``, ``mode=packed``): a round of :attr:`objects_per_round` objects on
    the table, grasped one at a time (:mod:`graspexp.sim.rounds`). Its keys beside :class:`ModeConfig`'s: the
    scene type and the round's protocol."""

    scene: str = MISSING
    """How the round's objects come onto the table: the name of a registered scene type
    (:mod:`graspexp.sim.scene_types`: ``pile``, objects dropped into a box that is lifted away; ``packed``,
    objects stood upright side by side). A new scene type is a class there and a preset here."""
    objects_per_round: int = 5
    """Objects drawn from the pool (``objects``, else the dataset's list) per round, seeded
    per round; without replacement when the pool holds enough, else with. 5: VGN's and GIGA's rounds."""
    max_consecutive_failures: int = 2
    """The round ends after this many failed grasp attempts in a row (VGN's
    ``MAX_CONSECUTIVE_FAILURES = 2``, ethz-asl/vgn src/vgn/experiments/clutter_removal.py)."""
    workspace_half_size_m: list[float] = field(default_factory=lambda: [0.15, 0.15])
    """Half extents [x, y] of the square the objects are placed in, centred on the table,
    m. An object whose centre of mass is outside it (or off the table) once the scene has settled is taken
    away before the first attempt and not counted as placed. 0.3 m: VGN's workspace (``size`` 0.3 m, its
    ``remove_objects_outside_roi``)."""
    tray_half_size_m: list[float] = field(default_factory=lambda: [0.1, 0.1])
    """``pile``: inner half extents [x, y] of the box the objects are dropped into, m; it is lifted away once
    they rest, leaving a heap. 0.2 m: VGN drops into the middle third of its 0.3 m workspace inside a box;
    a box narrower than a long object (LINEMOD iron 258 mm) still holds it, tilted."""
    tray_wall_height_m: float = 0.15
    """``pile``: height of the box's walls above the table, m (higher than a heap of five YCB objects)."""
    drop_height_m: float = 0.2
    """``pile``: height of the lowest point of each object above the table at release, m (VGN: 0.2 m);
    the objects are dropped one after another, each once the earlier ones rest."""
    placement_gap_m: float = 0.01
    """``packed``: least gap between the footprints (each model's x-y bounding rectangle, turned by its yaw)
    of two objects placed upright, m: side by side, not touching."""
    object_scale: list[float] = field(default_factory=lambda: [1.0, 1.0])
    """[min, max]: each object placed in a round is scaled (its mesh, cloud and collision shape, about its
    own origin) by a factor drawn uniformly from this range, per object and round, from the round's seed.
    The protocol of VGN and GIGA scales its test objects per scene by U(0.8, 1.0) in pile scenes and
    U(0.7, 0.9) in packed scenes (ethz-asl/vgn ``src/vgn/simulation.py``; ``protocol=giga``, ``protocol=vgn``
    set it): the sets were normalised to the Panda's stroke and the scale varies them. The mass stays the
    object's, as PyBullet's ``globalScaling`` keeps a URDF's mass in their simulation. [1, 1]: every object
    at its own size and nothing drawn (the rounds of every preset, as before the key); min = max: one fixed
    factor."""
    packed_placement: str = "gap"
    """``packed``: how the objects are stood upright. ``gap``: each drawn object in turn at a random place
    of the workspace whose footprint keeps ``placement_gap_m`` from the others', up to 200 tries each
    (:func:`graspexp.sim.scene_types.packed.packed_poses`). ``vgn``: VGN's and GIGA's ``generate_packed``
    (ethz-asl/vgn ``src/vgn/simulation.py``): ``packed_attempts`` attempts in all, each stands the next
    object not yet placed upright at a random yaw with its origin uniform within ``packed_centre_half_m`` of
    the workspace centre, ``rot.drop_height_m`` above the table; an object that touches another after one
    physics step is taken away again (the others put back as they were) and waits for a later attempt, one
    that does not is left to settle."""
    packed_attempts: int = 12
    """``packed_placement=vgn``: placement attempts per round (VGN's ``max_attempts = 12``)."""
    packed_centre_half_m: float = 0.07
    """``packed_placement=vgn``: each attempt's origin is drawn uniformly within this of the workspace centre
    in x and y, m (VGN: [0.08, 0.22] m of its 0.3 m workspace)."""
    pick_order: str = "lowest_cost"
    """Which object to grasp next. ``lowest_cost``: plan every object on the table (the
    planner sees the others as obstacles) and execute the grasp of least cost (the paper's Eq. 2-3 choice
    extended over the objects: the same rule that picks a path picks the object); ``top_most``: plan the
    objects from the highest top down and execute the first grasp found (a heap is cleared from the top,
    the order a person follows, and only one plan is paid per attempt when it succeeds). Planners that plan on
    the camera (``vgn``, ``antipodal_view``) follow the same rule: each object in turn is the observation's
    ``target_id`` (vgn: the detections that hold it, cost 1 - quality)."""
    sleep_threshold: float = 0.0
    """PhysX sleep threshold of the round's objects, m^2/s^2: a body whose mass-normalised
    kinetic energy stays below it for PhysX's wake counter (0.4 s) is put to sleep, skipped by the solver
    until an awake body touches it or one it rests on is removed. 0: never, as the bodies of every trial
    (``sim`` sets 0 for all). 0.005, PhysX's default, lets the untouched objects of a heap sleep through an
    attempt and ends the settling sooner: a logged pile attempt cost about 0.65x the CPU time
    (``bench.clutter``), but a body moving slower than about 0.1 m/s for 0.4 s is frozen where it is, and the
    rounds' outcomes differ (docs/results/clutter.md, Speed); at 0.001 and below a heap's contact jitter
    keeps its objects awake (no steady gain measured). Off by default: the results are those of the full
    physics."""


PICK_ORDERS = ("lowest_cost", "top_most")
"""The values of ``mode.pick_order``."""
PACKED_PLACEMENTS = ("gap", "vgn")
"""The values of ``mode.packed_placement``."""
NAME = [Pattern(r"[A-Za-z0-9][A-Za-z0-9_.-]*", "a name of letters, digits, '_', '.' and '-'")]
"""A clutter mode's name: its rounds' log folder ``trials/<name>/``."""


CONSTRAINTS = {
    "name": [Options(("collab", "bin"))],
    "support_height_m": [Interval(0, 2, "right", "m")],
    "support_half_size_m": [Vector(2, Interval(0, 5, "right", "m"))],
    "support_collides_with_gripper": BOOL,
    "remove_support_after_grasp": BOOL,
    "pull_back_m": [Interval(0, 2, unit="m")],
    "lift_m": [Interval(0, 2, unit="m")],
    "hold_s": [Interval(0, 60, "right", "s")],
}
"""Allowed values of every key of :class:`ModeConfig` (see :mod:`graspexp.config.constraints`)."""
CLUTTER_CONSTRAINTS = {
    **CONSTRAINTS,
    "name": NAME,
    "scene": NAME,
    "objects_per_round": [Interval(1, 50, integer=True)],
    "max_consecutive_failures": [Interval(1, 100, integer=True)],
    "workspace_half_size_m": [Vector(2, Interval(0, 5, "right", "m"))],
    "tray_half_size_m": [Vector(2, Interval(0, 5, "right", "m"))],
    "tray_wall_height_m": [Interval(0, 2, "right", "m")],
    "drop_height_m": [Interval(0, 2, unit="m")],
    "placement_gap_m": [Interval(0, 1, unit="m")],
    "object_scale": [Vector(2, Interval(0, 10, "neither"))],
    "packed_placement": [Options(PACKED_PLACEMENTS)],
    "packed_attempts": [Interval(1, 10_000, integer=True)],
    "packed_centre_half_m": [Interval(0, 5, unit="m")],
    "pick_order": [Options(PICK_ORDERS)],
    "sleep_threshold": [Interval(0, 1, unit="m^2/s^2")],
}
"""Allowed values of every key of :class:`ClutterModeConfig`; ``scene`` names a registered scene type, checked
when the job starts (:func:`graspexp.sim.scene_types.scene_type`)."""


CLUTTER_KEYS = frozenset(f.name for f in fields(ClutterModeConfig)) - {f.name for f in fields(ModeConfig)}
"""The keys only a clutter mode has (every mode had them before :class:`ClutterModeConfig` existed)."""
LEGACY_SCENES = ("pile", "packed")
"""The clutter modes of logs written before ``mode.scene``: each named after its scene type."""


def is_clutter(mode: object) -> bool:
    """Whether a mode config (a composed node or its dataclass) is a clutter-removal mode: its schema is
    :class:`ClutterModeConfig` (it has a ``scene``)."""
    return getattr(mode, "scene", None) is not None
