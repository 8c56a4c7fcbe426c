"""Schema of ``optimal_plus`` (graspexp/planning/optimal_plus.py): the paper's paths and cost, then an
opening from the geometry, a swept collision check, a pad-depth test, a gravity-arm preference and a
pose-noise check. Every default below was set from the mechanism it addresses (the measurement that
shows the mechanism is named), not from the planner's score."""

from dataclasses import dataclass, field

from graspexp.config.constraints import Interval, Options, Vector, added
from graspexp.config.planner.base import AREA_CONTACT_CONSTRAINTS, AreaContactConfig
from graspexp.config.planner.optimal import PAPER_PATHS_CONSTRAINTS, PaperPathsConfig
from graspexp.config.plugins import PlannerPlugin


@dataclass
class OptimalPlusConfig(PaperPathsConfig, AreaContactConfig):
    n_points: int = 4096
    """Size N of the object's surface cloud. 4096, not 2048: the pad-contact test (``contact_band_m``)
    needs points about a band apart, and 2048 points on the iron (the largest Table 2 object) are 7 mm
    apart (a 10-trial check on the iron, collab Z: 8 of 12 contacts in its area with 2048 points, 14 of 14
    with 4096; the readings row ``plus_n2048`` measures it on every object)."""
    opening: str = "section"
    """Opening rule: ``section`` = the object's section between the pads + 2 ``width_clearance_m``;
    ``cluster`` = at least the paper's 2 r_k (1 + ``width_margin``) too. The swept collision check
    already keeps the fingers off the object, and 2 r_k of a long cluster exceeds the stroke (power drill:
    70 of its 162 paths) although its section fits."""
    cluster_length: str = "finger_width"
    """Length along the main axis each cluster gets from ``k: auto`` (K = ceil(area length / it)):
    ``finger_width`` (``gripper.finger_width_m``: the pads touch a strip that wide, so each cluster is
    one pad-wide place to grasp) or ``stroke`` (``auto_k_stroke_fraction`` of the stroke, as ``optimal``).
    Long areas then offer grasp points along their whole length, not only the middle of a stroke-long
    cluster (power drill: the housing ahead of the pistol grip)."""
    rolls_deg: list[float] = field(default_factory=lambda: [0.0, 90.0])
    """Rotations of the Fig. 9 frame about the approach tried per path, in order of preference, degrees.
    0 = the paper's closing across the main axis; 90 = along it, for a path where the object across the
    main axis exceeds the stroke."""
    depth_offsets_m: list[float] = field(default_factory=lambda: [-0.02, -0.01, 0.0, 0.01, 0.02, 0.03, 0.04])
    """Moves of the grasp point along the approach tried per path, m (+ = deeper, towards the palm
    reaching the object). From 2 cm back (the fingertips off a support just below c_k) to half the RG2
    finger length in (the paper's c_k is a mean of surface points: on a face seen from above it lies on
    the surface, 1 cm from the fingertips)."""
    min_pad_depth_m: float = 0.005
    """Smallest distance from the fingertips to the centre of either pad's contact, m: a contact centred
    closer lies on the pad's edge (``contact_band_m`` 4 mm of contact, 1 mm to spare), which the pads'
    pressure squeezes out along the approach. (0.01, the TCP's depth ``gripper.tcp_from_tip_m``, was the
    first value: it also rejects face contacts on tapered objects, e.g. every in-area grasp of the iron,
    whose body is widest at the soleplate; docs/results/ablation.md shows both.)"""
    pad_depth_target_m: float = 0.025
    """Pad depth aimed at when several depths pass, m: about a third of the RG2 finger (80 mm), deep
    enough to hold by the pad's face and short of the palm."""
    friction_coef: float = 0.75
    """Coulomb friction the contact test assumes: each pad's contact normal must lie within atan(mu)
    (36.9 deg at 0.75) of the closing axis. 0.75 is the simulated contact's sliding friction: PhysX's
    default combine mode (average) of the pad's ``gripper.pad_friction`` 1.0 and the object's
    ``sim.object_dynamic_friction`` 0.5. (The first value, 0.5, the antipodal baseline's, was stricter
    than the simulation: the cone test cost 8 points on LINEMOD in the ablations with it.)"""
    min_contacts_in_area: float = 1.0
    """Every pad contact point in the grasping area (see :class:`AreaContactConfig`)."""
    com_weight: float = 1.0
    """Cost factor ``1 + com_weight * arm / D`` (arm of gravity about the closing axis, D the object's
    box diagonal, m/m); 0 switches it off. 1: a grasp at the far end of the object costs up to twice a
    grasp through the centre of mass, within the range of Eq. (1)-(3) between neighbouring paths."""
    choose_by: str = added("edge_clearance", before="cost")
    """What picks the grasp among the robust shortlisted paths (module doc, step 6): ``edge_clearance`` = the
    path whose fingers' side and tip faces keep the most room from the object (ties, e.g. every path
    clear of it: the smallest cost); ``cost`` = the paper's Eq. (1)-(3) times the gravity-arm factor. The
    paper's cost already ranks the paths the shortlist is drawn from. Within it the failures held in
    simulation were grasps a finger's side or tip face met, not its pad (power drill, mug: one pad at
    35-40 N, the other finger's side face at 40-46 N): of 4983 shortlisted grasps simulated one by one
    on the same drops (``python -m graspexp bench.shortlist --trials 5``, every Table 1/2 object and
    setting), 1313 of 1314 with the object nowhere past a pad's plane by the finger edges were held,
    against 93 % (292 of 314) where it reached 2 mm or more past it (docs/results/experiments.md, "The choice by the finger edges (commit fb79eb6)")."""
    edge_clearance_m: float = 0.002
    """Band beside each finger's side faces and beyond its tip face that ``edge_clearance`` examines, m:
    the ``collision_margin_m`` the open fingers keep from the object, and about the 1-2 mm the object
    shifts or turns in the closing hand (the failures' logs)."""
    shortlist: int = 16
    """Paths passing the geometric checks among which ``choose_by``, the gravity arm and pose noise
    choose."""
    noise_trans_mm: float = 3.0
    """Std-dev of the pose estimator's translation error the grasp must tolerate, mm. The paper gives
    no accuracy for its estimator; 3 mm is below the 2 cm ADD(-S) threshold its cited estimators are
    scored by and about the clearance ``width_clearance_m``. 0 switches the check off."""
    noise_rot_deg: float = 2.0
    """Std-dev of the estimator's rotation error the grasp must tolerate, degrees."""
    noise_samples: int = 8
    """Pose-noise draws per shortlisted path; 0 switches the check off."""
    noise_min_pass: float = 0.75
    """Share of the draws a path must pass to compete (else the paths passing most often compete)."""


CONSTRAINTS = {
    **PAPER_PATHS_CONSTRAINTS,
    **AREA_CONTACT_CONSTRAINTS,
    "opening": [Options(("section", "cluster"))],
    "cluster_length": [Options(("finger_width", "stroke"))],
    "rolls_deg": [Vector(None, Interval(-180, 180, unit="deg"))],
    "depth_offsets_m": [Vector(None, Interval(-0.5, 0.5, unit="m"))],
    "min_pad_depth_m": [Interval(-0.5, 0.5, unit="m")],
    "pad_depth_target_m": [Interval(0, 0.5, unit="m")],
    "friction_coef": [Interval(0, 10, "right")],
    "com_weight": [Interval(0, 100)],
    "choose_by": [Options(("edge_clearance", "cost"))],
    "edge_clearance_m": [Interval(0, 0.05, unit="m")],
    "shortlist": [Interval(1, 100_000, integer=True)],
    "noise_trans_mm": [Interval(0, 100, unit="mm")],
    "noise_rot_deg": [Interval(0, 90, unit="deg")],
    "noise_samples": [Interval(0, 1000, integer=True)],
    "noise_min_pass": [Interval(0, 1)],
}
"""Allowed values of every key of :class:`OptimalPlusConfig` (see :mod:`graspexp.config.constraints`)."""

PLUGIN = PlannerPlugin(
    plan="graspexp.planning.optimal_plus:plan_optimal_plus", config=OptimalPlusConfig, constraints=CONSTRAINTS
)
"""Entry point of the built-in planner (graspexp's ``pyproject.toml``)."""
