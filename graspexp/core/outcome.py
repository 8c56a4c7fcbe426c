"""A trial's outcome: a closed set of failure reasons and the result record written per trial."""

import dataclasses
import enum
import math
import typing
from dataclasses import asdict, dataclass, field


class FailureReason(str, enum.Enum):
    """Why a trial failed; staged checks return at the first failure."""

    NO_FEASIBLE_GRASP = "no_feasible_grasp"
    """The planner found no candidate (all paths cross the support, empty area, object too wide)."""
    COLLISION_SUPPORT = "collision_support"
    """The gripper touched the table (bin mode)."""
    NO_CONTACT = "no_contact"
    """After closing, not both fingers touch the object."""
    SLIPPED = "slipped"
    """Held, but the grasp point slid over the object by more than ``sim.slip_threshold_m`` (only when
    that stricter criterion is set)."""
    DROPPED = "dropped"
    """After the hold, not both fingers press on the object: it is no longer held (paper IV-C)."""
    SIM_UNSTABLE = "sim_unstable"
    """NaN or exploding velocities."""
    FELL_OFF_SUPPORT = "fell_off_support"
    """The object fell off the support on every drop of the re-drop budget."""
    NOT_AT_REST = "not_at_rest"
    """The object was still moving when the settle time cap (``sim.settle_max_s``) ran out: nothing is
    planned on a moving object, so the trial is neither a grasp's success nor its failure (the log's
    ``settle_timeout`` phase says how fast it still moved)."""
    REGISTRATION_FAILED = "registration_failed"
    """``perception.source=depth``: the camera saw too little of the object, or the pose registered from what
    it saw fails a check of ``perception.registration`` (``min_target_points``, ``min_inliers``,
    ``min_fitness``, ``centroid_margin_m``): nothing is planned on the prior or on the identity, so the trial
    is a perception failure, not a grasp's (``TrialResult.detail`` gives the points seen and the fitness)."""
    ERROR = "error"
    """The trial raised; the message is in ``TrialResult.error``."""


UNPLANNED = (FailureReason.NO_FEASIBLE_GRASP.value, FailureReason.REGISTRATION_FAILED.value)
"""Reasons of trials that ended at planning, without a grasp (none found; no pose to plan on): a report's
"planned grasps" leave them out."""


@dataclass
class TrialResult:
    """One row of the results table; also the ``graspexp.TrialResult@5`` MCAP message."""

    dataset: str
    object: str
    mode: str
    rot: str
    planner: str
    trial: int
    seed: int
    success: bool
    reason: str | None
    """A :class:`FailureReason` value, None on success."""
    redrops: int = 0
    error: str = ""
    grasp_cost: float = float("nan")
    grasp_width_m: float = float("nan")
    n_feasible: int = 0
    fc_min_mu: float = float("nan")
    """Smallest friction coefficient (of 0.2, 0.4, ..., 1.2) at which the planned grasp's two finger contacts
    are force-closure on the true object pose, without physics; NaN when none is (or the line misses)."""
    slip_m: float = float("nan")
    """Distance the grasp point slid over the object (object frame) from closing to the end of the hold, m."""
    finger_force_n: list[float] = field(default_factory=list)
    touched_support: bool = False
    timings_s: dict[str, float] = field(default_factory=dict)
    """Wall time per phase (build, settle, plan, quality, execute, log), s; ``physics`` is the part of settle and
    execute spent inside the physics step itself."""
    sim_time_s: float = 0.0
    steps: int = 0
    at_rest: bool = True
    """False when the settle time cap (``sim.settle_max_s``) ran out before the object came to rest: the
    trial then ends as ``not_at_rest`` (logs before that reason existed planned on the moving object)."""
    pose_trans_err_mm: float = float("nan")
    """``perception.source=depth``: distance between the registered and the true object origin, mm (NaN
    when no pose was registered)."""
    pose_rot_err_deg: float = float("nan")
    """... angle between the registered and the true orientation, degrees."""
    pose_adds_mm: float = float("nan")
    """... ADD-S: mean distance from each model point at the registered pose to the nearest model point at
    the true pose, mm (Hinterstoisser et al. 2012; symmetric objects are not penalised)."""
    registration_fitness: float = float("nan")
    """... share of the model points ICP aligned that found an observed point within
    ``perception.registration.max_correspondence_m`` (Open3D's fitness), in [0, 1]."""
    registration_cpu_s: float = float("nan")
    """... CPU time of the registration (all threads), s."""
    detail: str = ""
    """Why the trial failed, one line: the failed check's own words (for ``registration_failed`` the points
    the camera saw of the object and the registration's fitness; for ``no_feasible_grasp`` the planner's
    reason, e.g. a view-based planner's "the camera saw N points"); "" on success, for ``error`` (see
    ``error``) and in logs written before the field existed (``graspexp.TrialResult@4`` and older)."""

    def to_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict) -> "TrialResult":
        return cls(**{k: d[k] for k in cls.__dataclass_fields__ if k in d})


REQUIRED_RESULT_FIELDS = ("dataset", "object", "mode", "rot", "planner", "trial", "seed", "success", "reason")
"""Fields every /result message has had since the first log format; the others default when absent."""


def result_from_dict(d: object) -> TrialResult:
    """A :class:`TrialResult` from a /result message, checked field by field: the required fields present,
    each value of its annotated type (``success: "false"`` is not a boolean, ``trial: "abc"`` not an
    integer), ``reason`` a :class:`FailureReason` value or None, and None exactly when ``success``.
    Raises ValueError naming the field."""
    if not isinstance(d, dict):
        raise ValueError(f"a result is a mapping, got {type(d).__name__}")
    missing = [k for k in REQUIRED_RESULT_FIELDS if k not in d]
    if missing:
        raise ValueError(f"result lacks {missing}")
    hints = typing.get_type_hints(TrialResult)
    for f in dataclasses.fields(TrialResult):
        if f.name in d and not _is_instance(d[f.name], hints[f.name]):
            raise ValueError(f"result field {f.name}={d[f.name]!r} is not {hints[f.name]}")
    reasons = {r.value for r in FailureReason}
    if d["reason"] is not None and d["reason"] not in reasons:
        raise ValueError(
            f"result field reason={d['reason']!r} is not a failure reason ({', '.join(sorted(reasons))})"
        )
    if d["success"] != (d["reason"] is None):
        raise ValueError(f"result says success={d['success']} with reason={d['reason']!r}")
    if d["trial"] < 0:
        raise ValueError(f"result field trial={d['trial']} is negative")
    return TrialResult.from_dict(d)


def _is_instance(value: object, tp: object) -> bool:
    """Whether a decoded JSON value fits annotation ``tp`` (bool is not an int; an int is a float)."""
    origin, args = typing.get_origin(tp), typing.get_args(tp)
    if origin is typing.Union or type(tp).__name__ == "UnionType":
        return any(_is_instance(value, a) for a in args)
    if tp is type(None):
        return value is None
    if tp is bool:
        return isinstance(value, bool)
    if tp is int:
        return isinstance(value, int) and not isinstance(value, bool)
    if tp is float:
        return isinstance(value, int | float) and not isinstance(value, bool) and not math.isinf(value)
    if tp is str:
        return isinstance(value, str)
    if origin is list:
        return isinstance(value, list) and all(_is_instance(v, args[0]) for v in value)
    if origin is dict:
        return isinstance(value, dict) and all(
            isinstance(k, str) and _is_instance(v, args[1]) for k, v in value.items()
        )
    return True
