"""A trial's outcome: a closed set of failure reasons and the result record written per trial."""

import enum
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
    ERROR = "error"
    """The trial raised; the message is in ``TrialResult.error``."""


@dataclass
class TrialResult:
    """One row of the results table; also the ``graspexp.TrialResult@2`` MCAP message."""

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

    def to_dict(self) -> dict:
        return asdict(self)

    @classmethod
    def from_dict(cls, d: dict) -> "TrialResult":
        return cls(**{k: d[k] for k in cls.__dataclass_fields__ if k in d})
