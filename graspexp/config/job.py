"""Schema of the top-level job config that composes every group."""

from dataclasses import dataclass, field
from typing import Any

from omegaconf import MISSING

from graspexp.config.constraints import BOOL, Interval, Names, Options
from graspexp.config.cost import CostConfig
from graspexp.config.dataset import DatasetConfig
from graspexp.config.gripper import GripperConfig
from graspexp.config.mode import ModeConfig
from graspexp.config.perception import PerceptionConfig
from graspexp.config.rot import RotConfig
from graspexp.config.sim import SimConfig

OBJECTIVES = ("success", "worst_object")
"""The values of ``objective`` (what a job returns to a sweeper)."""


@dataclass
class JobConfig:
    defaults: list[Any] = field(default_factory=list)
    dataset: DatasetConfig = MISSING
    mode: ModeConfig = MISSING
    rot: RotConfig = MISSING
    gripper: GripperConfig = MISSING
    planner: Any = MISSING
    """The selected planner's own schema (a :class:`graspexp.config.PlannerConfig` subclass, from its plugin)."""
    cost: CostConfig = MISSING
    sim: SimConfig = MISSING
    perception: PerceptionConfig = field(default_factory=PerceptionConfig)
    trials: int = 10
    """Trials per object."""
    seed: int = 0
    """Global seed; each trial's seed derives from (seed, object, trial index)."""
    objects: list[str] | None = None
    """Subset of the dataset's objects; None: all of them."""
    record: bool = True
    """Write one MCAP log per trial."""
    live: bool = False
    """Stream the running trials to the Foxglove app over a WebSocket server on 127.0.0.1 (live view)."""
    live_port: int = 8765
    """Port of the live-view server (0: any free port)."""
    progress: bool = True
    """Show a progress bar."""
    objective: str = "success"
    """What the job returns to a sweeper (``hydra/sweeper=study`` maximises it), a fraction in [0, 1]:
    ``success``: the mean over objects of each object's success rate (with equal trials per object, as a
    job runs them, this equals the mean over all trials); ``worst_object``: the lowest object's success
    rate (tunes for the hardest object). A job that cannot run returns None (the study marks it FAIL)."""


JOB_CONSTRAINTS = {
    "trials": [Interval(1, 100_000, integer=True)],
    "seed": [Interval(0, 2**63 - 1, integer=True)],
    "objects": [None, Names()],
    "record": BOOL,
    "live": BOOL,
    "live_port": [Interval(0, 65535, integer=True)],
    "progress": BOOL,
    "objective": [Options(OBJECTIVES)],
}
"""Allowed values of the top-level keys; the groups have their own (see :mod:`graspexp.config.constraints`)."""
