"""What every planner receives; the planner contract is pure: request in, ``PlanResult`` out."""

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from graspexp.config import CostConfig, GripperConfig, PlannerConfig
from graspexp.perception.observation import Observation
from graspexp.planning.cells import CellCloud, cell_cloud
from graspexp.planning.details import PaperDetails
from graspexp.planning.grasp import Grasp


@dataclass(frozen=True)
class Neighbour:
    """Another object in the scene of a clutter round (``mode=pile``/``packed``), as the planner sees it.

    id : the object's body id in the round (its slot). name : the dataset's object name. points : (N, 3)
    its model's surface cloud at its perceived pose, world frame, m. pose : (4, 4) its perceived world pose.
    """

    id: int
    name: str
    points: np.ndarray
    pose: np.ndarray


@dataclass(frozen=True)
class PlanRequest:
    """Inputs of one planning call, all in the world frame, metres.

    points : (N, 3) object surface cloud transformed by the (perceived) object pose.
    normals : (N, 3) outward unit normals of ``points``.
    area_mask : (N,) bool, grasping area.
    object_pose : (4,4) perceived world pose of the object frame.
    table_z : height of the support plane z = h, m.
    mode : ``collab`` (Eq. 1) or ``bin`` (Eq. 2-3).
    gripper : the gripper model (stroke, finger and palm boxes), m.
    planner : the planner's own config (its plugin's schema, a :class:`PlannerConfig` subclass).
    cost : the constants of Eq. (1)-(3).
    seed : seed for anything random in the planner.
    support_blocks_gripper : whether the support is an obstacle for the fingers and palm
        (``mode.support_collides_with_gripper``: the bin's table is; the collaborative mode's box, removed
        after the grasp, is not). Paths through the support plane are dropped either way (III-D).
    observation : what the simulated depth camera saw (views, observed cloud with normals and per-point
        object ids, the target's id), when the trial rendered it (``perception.source=depth``, or a planner
        whose schema sets ``needs_observation``); None otherwise. ``points`` and ``object_pose`` are then
        the model placed at the registered pose (or the true one with ``perception.source=truth``).
    neighbours : the other objects on the support in a clutter round (empty for one object): obstacles
        for the paths and the swept gripper; a planner that ignores them still plans for the target.
    workspace_xy : (2, 2) [[x_min, y_min], [x_max, y_max]] world m, the clutter mode's workspace
        (``mode.workspace_half_size_m`` about the support's centre) in a clutter round; None for one
        object. A planner that sees the scene as one volume (``vgn``) places it there, the same for every
        target of the scene.
    """

    points: np.ndarray
    normals: np.ndarray
    area_mask: np.ndarray
    object_pose: np.ndarray
    table_z: float
    mode: str
    gripper: GripperConfig
    planner: PlannerConfig
    cost: CostConfig
    seed: int
    support_blocks_gripper: bool = True
    observation: Observation | None = None
    neighbours: tuple[Neighbour, ...] = ()
    workspace_xy: np.ndarray | None = None

    @cached_property
    def neighbour_points(self) -> np.ndarray:
        """(N, 3) every neighbour's cloud stacked, world m (empty (0, 3) without neighbours)."""
        if not self.neighbours:
            return np.zeros((0, 3))
        return np.concatenate([np.asarray(n.points, dtype=np.float64) for n in self.neighbours])

    @cached_property
    def neighbour_cells(self) -> CellCloud:
        """:attr:`neighbour_points` sorted into cubes (:func:`graspexp.planning.cells.cell_cloud`), built once
        per request for every swept test of its paths."""
        return cell_cloud(self.neighbour_points)


@dataclass(frozen=True)
class PlanResult:
    grasp: Grasp
    details: PaperDetails | dict[str, np.ndarray] = field(default_factory=dict)

    def detail_arrays(self) -> dict[str, np.ndarray]:
        """The intermediates as named arrays (what ``plan --dump`` writes)."""
        if isinstance(self.details, PaperDetails):
            return self.details.arrays()
        return {key: np.asarray(value) for key, value in self.details.items()}
