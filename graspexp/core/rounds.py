"""A clutter-removal round's outcome (``mode=pile``/``packed``): one row per grasp attempt, one per round.

GSR (grasp success rate) = successful attempts / executed attempts; DR (declutter rate, VGN's "percent
cleared") = objects removed / objects placed (Breyer et al., CoRL 2020; Jiang et al., RSS 2021).
"""

import enum
from dataclasses import asdict, dataclass, field


class RoundEnd(str, enum.Enum):
    """Why a round ended (VGN's three rules, the single-object rules that apply to a heap, and an error)."""

    CLEARED = "cleared"
    """Every object placed was removed (at least one was placed)."""
    NO_GRASP = "no_grasp"
    """The planner found no grasp on any object left, or no object left could be registered from the camera
    (``perception.source=depth``): the last row's reason says which (``no_feasible_grasp`` or
    ``registration_failed``)."""
    FAILURE_LIMIT = "failure_limit"
    """``mode.max_consecutive_failures`` attempts in a row failed."""
    NOT_AT_REST = "not_at_rest"
    """The heap was still moving when the planner was to look (``sim.settle_max_s`` ran out after the placing
    or after an attempt): nothing is planned on a moving heap, so the round stops there, as a single-object
    trial does; its last row (not executed, reason ``not_at_rest``) names the object moving fastest. No
    attempt is added to GSR; the objects left count as not removed in DR."""
    NOTHING_PLACED = "nothing_placed"
    """No object came to rest inside the workspace: nothing to grasp (not ``cleared``); the round adds nothing
    to GSR or DR and is not counted among the rounds the planner ran."""
    ERROR = "error"
    """The round raised; the message is in ``RoundResult.error``."""


@dataclass
class AttemptResult:
    """One grasp attempt of a round (a row of ``attempts.csv``)."""

    round: int
    attempt: int
    target: str
    """Name of the object the attempt grasped (the dataset's object name)."""
    slot: int
    """Index of the target among the round's drawn objects (its body is ``object_<slot>``)."""
    executed: bool
    """False for the round's last row when no grasp was found (``reason`` no_feasible_grasp): not an attempt
    of GSR's denominator."""
    success: bool
    reason: str | None
    """A :class:`graspexp.core.outcome.FailureReason` value, None on success."""
    pick_order: str
    """``mode.pick_order`` that chose the target."""
    n_left: int
    """Objects on the table before the attempt."""
    n_planned: int
    """Plans made for this attempt (objects planned for)."""
    plan_s: float
    """Wall time of every plan made for the attempt (the scene's planning latency), s; NaN when none was made
    (``not_at_rest``, ``registration_failed``)."""
    plan_cpu_s: float
    """CPU time of the planning thread over the same plans, s (NaN as ``plan_s``)."""
    grasp_cost: float = float("nan")
    grasp_width_m: float = float("nan")
    n_feasible: int = 0
    slip_m: float = float("nan")
    touched_support: bool = False
    touched_neighbours: list[str] = field(default_factory=list)
    """Bodies (``object_<slot>``) other than the target that the gripper touched during the attempt (allowed)."""
    moved_neighbours: list[str] = field(default_factory=list)
    """Bodies other than the target that ended more than ``MOVED_M`` from where they were before it."""
    pose_trans_err_mm: float = float("nan")
    """``perception.source=depth``: distance between the target's registered and true origin before the
    attempt, mm (NaN when no pose was registered; as :class:`graspexp.core.outcome.TrialResult`)."""
    pose_rot_err_deg: float = float("nan")
    """... angle between the target's registered and true orientation, degrees."""
    pose_adds_mm: float = float("nan")
    """... ADD-S of the target's registered pose against the true one, mm."""
    registration_fitness: float = float("nan")
    """... Open3D's ICP fitness of the target's registration, in [0, 1]."""
    execute_s: float = 0.0
    """Wall time of the attempt's execution (approach to hold) and the settling after it, s."""
    sim_time_s: float = 0.0
    """Sim time of the round when the attempt ended, s."""

    def to_dict(self) -> dict:
        return asdict(self)


@dataclass
class RoundResult:
    """One round: what was drawn, what was placed, how it ended (a row of ``rounds.csv``; also the round
    log's ``/round`` message, ``graspexp.RoundResult@1``)."""

    dataset: str
    mode: str
    planner: str
    round: int
    seed: int
    drawn: list[str]
    """The objects drawn for the round, by slot."""
    placed: list[str]
    """Slots (``object_<slot>``) on the table inside the workspace once the scene settled."""
    removed: list[str]
    """Slots removed by a successful grasp."""
    end: str
    """A :class:`RoundEnd` value."""
    attempts: list[AttemptResult] = field(default_factory=list)
    """Every attempt of the round, in order."""
    error: str = ""
    wall_s: float = 0.0
    cpu_s: float = 0.0
    sim_time_s: float = 0.0

    @property
    def n_placed(self) -> int:
        return len(self.placed)

    @property
    def n_removed(self) -> int:
        return len(self.removed)

    def to_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, d: object) -> "RoundResult":
        """Read back a ``/round`` message (or a dict of one); ValueError naming what is wrong."""
        if not isinstance(d, dict):
            raise ValueError(f"a round result is a mapping, got {type(d).__name__}")
        missing = [k for k in ("round", "drawn", "placed", "removed", "end", "attempts") if k not in d]
        if missing:
            raise ValueError(f"round result lacks {missing}")
        if d["end"] not in {e.value for e in RoundEnd}:
            raise ValueError(f"round result end={d['end']!r} is not one of {[e.value for e in RoundEnd]}")
        known = set(cls.__dataclass_fields__)
        fields = {k: v for k, v in d.items() if k in known}
        if not isinstance(fields["attempts"], list) or not all(
            isinstance(a, dict) for a in fields["attempts"]
        ):
            raise ValueError("round result's attempts are not a list of mappings")
        try:
            fields["attempts"] = [AttemptResult(**a) for a in fields["attempts"]]
        except TypeError as exc:
            raise ValueError(f"round result has a malformed attempt ({exc})") from None
        return cls(**fields)
