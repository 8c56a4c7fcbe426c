"""The planner's output, shared by every planner."""

from dataclasses import dataclass, field

import numpy as np


@dataclass(frozen=True)
class Grasp:
    """A parallel-jaw grasp in the world frame.

    pose : (4,4) world pose of the gripper frame (paper Fig. 9): +Z approach direction (towards the
        object), +X main axis, +Y = Z x X closing axis; origin = grasp point midway between the pads.
    width_m : planned opening between the pads, m.
    cost : the planner's score, lower is better (optional: NaN).
    cluster : index k of the chosen cluster (-1 where the planner has none).
    path : index p of the chosen path in that cluster (-1 where the planner has none).
    n_feasible : number of candidate paths that survived the feasibility checks (optional: 1).
    planner : registry name of the planner that made it (optional: filled in by
        :func:`graspexp.planning.plan` from ``planner.name``).
    touches_neighbours : in a clutter scene, the grasp was planned for the target alone because none
        clears the neighbours (the fingers or palm may touch another object: allowed by the protocol,
        chosen last by the round). False for one object.
    extras : planner-specific scalars for logs (e.g. K, M).
    """

    pose: np.ndarray
    width_m: float
    cost: float = float("nan")
    cluster: int = -1
    path: int = -1
    n_feasible: int = 1
    planner: str = ""
    touches_neighbours: bool = False
    extras: dict = field(default_factory=dict)

    @property
    def position(self) -> np.ndarray:
        return self.pose[:3, 3]

    @property
    def approach(self) -> np.ndarray:
        """Unit approach direction (+Z of the gripper frame), world."""
        return self.pose[:3, 2]


class NoFeasibleGrasp(RuntimeError):
    """No candidate survived the feasibility checks (e.g. every path crosses the support)."""
