"""Schema of the paper's planner (``optimal``, ``optimal_literal``, ``optimal_in_area``; graspexp/planning/optimal.py).

Every place where the paper is silent is a key here; its docstring quotes the sentence it rests on.
"""

from dataclasses import dataclass
from typing import Any

from graspexp.config.constraints import BOOL, Interval, Options, added
from graspexp.config.planner.base import (
    AREA_RULE_CONSTRAINTS,
    BASE_CONSTRAINTS,
    AreaRuleConfig,
    PlannerConfig,
)
from graspexp.config.plugins import PlannerPlugin


@dataclass
class PaperPathsConfig(PlannerConfig):
    """Grasping area -> K-means -> Fibonacci paths -> cost (section III): shared by ``optimal_plus``."""

    k: Any = "auto"
    """Number of K-means clusters: ``auto`` (rule of ``auto_k_stroke_fraction``) or a positive int. IV-D:
    "The cluster K depends on the gripper size and the size of the grasping area" (no formula given)."""
    k_max: int = 8
    """Upper bound on K when ``k: auto``."""
    m: int = 256
    """Grasping paths (Fibonacci sphere points) per cluster; IV-D: "we set the parameter M as 256"."""
    table_clearance_m: float = 0.0
    """A path is dropped when its sphere point lies below the support plane plus this, m; 0 = III-D's
    "paths that will pass through the desktop" taken at the path's start point."""
    neighbour_voxel_m: float = 0.01
    """Clutter rounds (``mode=pile``/``packed``): a path passes through another object (and is dropped, as
    III-D drops "paths that will pass through the desktop") when a point sampled every half voxel along it,
    from the sphere point to the cluster radius r_k from the centre (nearer, the fingers close about the
    target: the swept check judges that part), falls in a cube of this side, m, that holds a point of
    that object's cloud. 1 cm: wider than the spacing of a sampled cloud (about 5 mm on a 10 cm object
    with 1024 points), so no path slips between the points of a surface it crosses; no effect on one object."""
    neighbour_fallback: bool = True
    """Clutter rounds: when the swept gripper of every path meets a neighbour, ``optimal`` takes the cheapest
    path clear of the target and the support, ``optimal_plus`` the grasp it plans for the target alone
    (``Grasp.touches_neighbours``), instead of finding no grasp. The protocol lets the gripper touch
    the other objects (VGN executes with ``allow_contact=True``); in a heap, a palm 15 cm wide meets a
    neighbour on nearly every path. No effect on one object."""
    seed: int = 0
    """Seed of the K-means initialisation (combined with the trial seed)."""
    main_axis: str = "object"
    """Cloud whose first principal component is the main axis of Eq. (1)'s alpha and of the K rule's
    length: ``object`` (the whole cloud; III-D: "the main axis by reducing the dimensionality of the
    object's point cloud"; the cost term is "the intersection angle between path p and the main axis of
    the object") or ``area`` (the grasping area, Fig. 7). The area's axis is ill-conditioned for bands
    around cylinders (two near-equal eigenvalues), hence the default."""
    pose_axis: str = "object"
    """Cloud whose main axis becomes the grasp frame's +X (Fig. 9): ``area`` as printed ("the main axis
    of the grasping area which is produced by PCA", III-D), ``object``, or ``area_if_elongated``: the
    area's axis where PCA defines one (the area's elongation, sqrt(l1 / l2) of its covariance, at least
    ``pose_axis_min_elongation``), else the object's. On a band around a cylinder (elongation ~1) the
    area's first component is any direction across the cylinder and can put the closing axis along it;
    on an L-shaped object (the power drill) the object's axis lies along the handle and closes the
    gripper along the housing the area marks."""
    pose_axis_min_elongation: float = 1.5
    """``pose_axis: area_if_elongated``: the area's main axis is used when the area is at least this many
    times longer along it than across it (ratio of its first two principal standard deviations, dimensionless).
    1.5 is "clearly longer than wide", fixed from the geometry before any run; the Table 1/2 areas'
    elongations (docs/results/readings.md) put the mug (1.38) and the LINEMOD can (1.37) nearest below it and the
    meat can (1.56) nearest above (its area and object axes agree)."""
    auto_k_stroke_fraction: float = 1.0
    """``k: auto``: K = clamp(ceil(L / (fraction * gripper.max_width_m)), 1, k_max), L = the area's extent
    along the main axis, m/m. III-B: clusters are "more precise areas to fit the size of the gripper",
    "a bigger gripper has fewer clusters": 1.0 makes each cluster about one stroke long."""
    cluster_radius: str = "max"
    """Definition of r_k (III-D: "the radius of the k-th cluster"), used by Eq. (1) and the opening:
    ``max`` = the largest distance of the cluster's points from c_k (the radius of the ball about c_k
    that holds the cluster: fingers opened to 2 r_k clear every point of it, and Eq. (1) then penalises
    points at the fingers' distance from the path, "to prevent the gripper from colliding") or ``rms``
    = the root-mean-square distance (ignores outlying points), m."""
    width_margin: float = 0.2
    """Opening = 2 r_k (1 + margin), clipped to the gripper stroke (dimensionless). The paper opens to
    "the diameter of the grasping area found by the method" (0 = as printed); 0.2 leaves clearance for
    the pads' thickness and the perception error."""


PAPER_PATHS_CONSTRAINTS = {
    **BASE_CONSTRAINTS,
    "k": [Options(("auto",)), Interval(1, 64, integer=True)],
    "k_max": [Interval(1, 64, integer=True)],
    "m": [Interval(1, 100_000, integer=True)],
    "table_clearance_m": [Interval(-1, 1, unit="m")],
    "neighbour_voxel_m": [Interval(0, 1, "right", unit="m")],
    "neighbour_fallback": BOOL,
    "seed": [Interval(0, None, integer=True)],
    "main_axis": [Options(("object", "area"))],
    "pose_axis": [Options(("object", "area", "area_if_elongated"))],
    "pose_axis_min_elongation": [Interval(1, None)],
    "auto_k_stroke_fraction": [Interval(0, 10, "right")],
    "cluster_radius": [Options(("max", "rms"))],
    "width_margin": [Interval(0, 10)],
}


@dataclass
class OptimalConfig(PaperPathsConfig, AreaRuleConfig):
    """The paper's planner; presets ``conf/planner/optimal.yaml``, ``optimal_literal.yaml`` and
    ``optimal_in_area.yaml``."""

    grasp_point: str = "section_middle"
    """Origin of the grasp frame: ``centre`` = c_k, as printed (the paths of Fig. 6 end at the cluster
    centre), or ``section_middle`` = c_k moved along the closing axis Y to the middle of the object's
    section between the pads: the pads of a parallel gripper close symmetrically about the TCP, so
    closing about an off-centre c_k lands one pad first and pushes the object."""
    section_fit: bool = True
    """Keep a path only if the object's section between the pads fits its opening (cheapest such path
    wins; if none fits, the cheapest whose section fits the stroke, opened to the section). Not in the
    paper (its cost is what steers paths away from the object); False = the printed argmin of the cost."""
    swept_check: bool = added(True, before=False)
    """Keep a path only if the gripper opened to its width, moving along the path from the sphere point
    to the grasp pose, keeps its fingers and palm clear of the object's cloud and, where the support
    blocks the gripper (bin picking), above the support plane (graspexp/planning/collision.py, margin 0).
    IV-D: "Because a suitable open range of the gripper can be used, collision with the other parts of
    the target object can be avoided during the grasping process"; III-D drops "paths that will pass
    through the desktop". The paper tests only the path's start point against the desktop and relies on
    the cost for the rest, so False = as printed."""
    pose_axis: str = added("area_if_elongated", before="object")
    """As :class:`PaperPathsConfig` (whose default, ``object``, ``optimal_plus`` keeps). ``area_if_elongated``:
    Fig. 9 / III-D's "main axis of the grasping area" where the area has one (the preset ``optimal``);
    ``optimal_literal`` takes ``area`` as printed, ``optimal_in_area`` ``object``."""
    min_contacts_in_area: float = 0.0
    """Share of each pad's contact points (the object points the pads meet first, within
    ``contact_band_m``) that must be grasping-area points for a path to be kept, tested with the section
    (module doc, step 7). Not in the paper: it aims its paths at the area's cluster centres, does not test
    where the 8 cm fingers land and scores success as "still held" wherever they do (IV-C), so the paper
    preset ``optimal`` has 0. ``optimal_in_area`` has 1 for the hand-over task (III-A: "the robot arm
    firstly needs to detect a proper contact area"; a person holds the rest): the report's in-area
    criterion shows what each grasps inside the area."""
    fallback_contacts_in_area: float = 1.0
    """No fallback (see :class:`AreaRuleConfig`): the paper plans from its grasping area's clusters in
    every mode and never grasps elsewhere; bin picking is one more application with a chosen area
    (III-A: an area "suitable for a specific situation, task, or application")."""


CONSTRAINTS = {
    **PAPER_PATHS_CONSTRAINTS,
    **AREA_RULE_CONSTRAINTS,
    "grasp_point": [Options(("centre", "section_middle"))],
    "section_fit": BOOL,
    "swept_check": BOOL,
}
"""Allowed values of every ``planner`` key of :class:`OptimalConfig` (see :mod:`graspexp.config.constraints`)."""

PLUGIN = PlannerPlugin(
    plan="graspexp.planning.optimal:plan_optimal", config=OptimalConfig, constraints=CONSTRAINTS
)
"""Entry point of ``optimal``, ``optimal_literal`` and ``optimal_in_area`` (one function, three presets)."""
