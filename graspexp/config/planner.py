"""Schemas of the ``planner`` and ``cost`` config groups (paper section III).

The cost constants are only meaningful with distances in millimetres and alpha in degrees
(beta in radians), exactly as printed in the paper's Eq. (1)-(3).
"""

from dataclasses import dataclass
from typing import Any

from omegaconf import MISSING

from graspexp.config.constraints import BOOL, TEXT, Interval, Options


@dataclass
class PlannerConfig:
    name: str = MISSING
    """Planner registry key (``optimal`` and ``optimal_literal`` are the paper's, read two ways)."""
    k: Any = "auto"
    """Number of K-means clusters: ``auto`` (rule of ``auto_k_stroke_fraction``) or a positive int. IV-D:
    "The cluster K depends on the gripper size and the size of the grasping area" (no formula given)."""
    k_max: int = 8
    """Upper bound on K when ``k: auto``."""
    m: int = 256
    """Grasping paths (Fibonacci sphere points) per cluster; IV-D: "we set the parameter M as 256"."""
    sphere_radius_m: float = 0.10
    """Radius of the Fibonacci sphere around each centre = pre-grasp standoff, m. The paper gives none;
    0.1 m clears the largest Table 1/2 object's half-extent from a cluster centre."""
    n_points: int = 2048
    """Size N of the object's surface point cloud (Eq. (1) sums over it). The paper gives none; 2048 points
    is about one per 5 mm^2 on the Table 1 objects, below the 10 mm scale of Eq. (1)'s distance term."""
    table_clearance_m: float = 0.0
    """A path is dropped when its sphere point lies below the support plane plus this, m; 0 = III-D's
    "paths that will pass through the desktop" taken at the path's start point."""
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
    of the grasping area which is produced by PCA", III-D) or ``object``. Default ``object``: on a band
    around a cylinder the area's axis can lie across the object and put the closing axis along it."""
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
    grasp_point: str = "section_middle"
    """Origin of the grasp frame: ``centre`` = c_k, as printed (the paths of Fig. 6 end at the cluster
    centre), or ``section_middle`` = c_k moved along the closing axis Y to the middle of the object's
    section between the pads: the pads of a parallel gripper close symmetrically about the TCP, so
    closing about an off-centre c_k lands one pad first and pushes the object."""
    section_fit: bool = True
    """Keep a path only if the object's section between the pads fits its opening (cheapest such path
    wins; if none fits, the cheapest whose section fits the stroke, opened to the section). Not in the
    paper (its cost is what steers paths away from the object); False = the printed argmin of the cost."""
    width_margin: float = 0.2
    """Opening = 2 r_k (1 + margin), clipped to the gripper stroke (dimensionless). The paper opens to
    "the diameter of the grasping area found by the method" (0 = as printed); 0.2 leaves clearance for
    the pads' thickness and the perception error."""

    # --- Baselines and optimal_plus (graspexp/planning/{antipodal,obb,random_grasp,optimal_plus}.py) ---
    # Optional: every field has a default, so the paper's ``optimal`` config is unchanged.
    n_candidates: int = 256
    """antipodal: first-contact points sampled; random: draws before giving up."""
    n_approach: int = 12
    """antipodal: approach directions tried about each contact pair's line (evenly spaced)."""
    friction_coef: float = 0.5
    """antipodal: friction coefficient mu of the sampling cone, half-angle atan(mu) (dimensionless)."""
    sample_area_only: bool = False
    """antipodal: draw contacts from the grasping area only (False: from the whole cloud, as GPD)."""
    approach_tilt_weight: float = 0.1
    """antipodal: cost per degree between the approach and straight down, added to the contacts' worst
    friction-cone angle (degrees), so top-down approaches win among equally antipodal pairs."""
    collision_margin_m: float = 0.002
    """Clearance the finger and palm boxes keep from cloud points and from the support plane, m."""
    width_clearance_m: float = 0.005
    """obb, antipodal, optimal_plus: opening = 2 * (largest |y| of the object between the pads) + 2 * this, m."""
    com_weight: float = 1.0
    """optimal_plus: cost factor (1 + com_weight * |c_k - centroid| / object size); 0 switches it off."""


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


PLANNER_CONSTRAINTS = {
    "name": TEXT,
    "k": [Options(("auto",)), Interval(1, 64, integer=True)],
    "k_max": [Interval(1, 64, integer=True)],
    "m": [Interval(1, 100_000, integer=True)],
    "sphere_radius_m": [Interval(0, 2, "right", "m")],
    "n_points": [Interval(16, 10_000_000, integer=True)],
    "width_margin": [Interval(0, 10)],
    "table_clearance_m": [Interval(-1, 1, unit="m")],
    "seed": [Interval(0, None, integer=True)],
    "main_axis": [Options(("object", "area"))],
    "pose_axis": [Options(("object", "area"))],
    "cluster_radius": [Options(("max", "rms"))],
    "grasp_point": [Options(("centre", "section_middle"))],
    "section_fit": BOOL,
    "auto_k_stroke_fraction": [Interval(0, 10, "right")],
    "n_candidates": [Interval(1, 1_000_000, integer=True)],
    "n_approach": [Interval(1, 3600, integer=True)],
    "friction_coef": [Interval(0, 10)],
    "sample_area_only": BOOL,
    "approach_tilt_weight": [Interval(0, 100)],
    "collision_margin_m": [Interval(0, 0.1, unit="m")],
    "width_clearance_m": [Interval(0, 0.1, unit="m")],
    "com_weight": [Interval(0, 100)],
}
"""Allowed values of every ``planner`` key (see :mod:`graspexp.config.constraints`)."""

COST_CONSTRAINTS = {
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
