"""The intermediates of the paper's planners (``optimal``, ``optimal_plus``): typed records that figures,
benches and ``plan --dump`` read by attribute. World frame, metres; K clusters, M paths per cluster, N
cloud points, S shortlisted paths."""

import dataclasses
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np


@dataclass(frozen=True)
class PaperDetails:
    """What the paper's steps computed (shared by ``optimal`` and ``optimal_plus``)."""

    cloud: np.ndarray
    """(N, 3) the object cloud the planner saw, m."""
    area_mask: np.ndarray
    """(N,) bool: the grasping area."""
    labels: np.ndarray
    """(N_area,) int: the K-means cluster of each area point."""
    centers: np.ndarray
    """(K, 3) cluster centres c_k, m."""
    radii: np.ndarray
    """(K,) cluster radii r_k, m."""
    main_axis: np.ndarray
    """(3,) unit main axis of the cloud (PCA)."""
    pose_axis: np.ndarray
    """(3,) unit axis the grasp poses are built about (``planner.pose_axis``)."""
    directions: np.ndarray
    """(K, M, 3) unit approach directions of the paths."""
    feasible: np.ndarray
    """(K, M) bool: paths still feasible after every test."""
    costs: np.ndarray
    """(K, M) path costs (Eq. 1-3; inf where infeasible)."""
    best: np.ndarray
    """(2,) int: (k, p) of the chosen path."""
    pose: np.ndarray
    """(4, 4) the chosen grasp pose."""
    width: float
    """Opening width of the chosen grasp, m."""
    mode: str
    """``collab`` or ``bin``."""
    table_z: float
    """Height of the support plane, m."""
    sphere_radius: float
    """Radius of the sphere the paths start on, m."""
    gripper_max_width: float
    """The gripper's stroke, m."""

    def arrays(self) -> dict[str, np.ndarray]:
        """Every field as an array, flat keys (the ``plan --dump`` file; a nested record's fields as
        ``<record>_<field>``)."""
        out = {}
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if dataclasses.is_dataclass(value) or isinstance(value, tuple):
                fields = value._asdict() if isinstance(value, tuple) else dataclasses.asdict(value)
                out.update({f"{f.name}_{k}": np.asarray(v) for k, v in fields.items()})
            else:
                out[f.name] = np.asarray(value)
        return out


@dataclass(frozen=True)
class OptimalDetails(PaperDetails):
    """``optimal``: the paper's record plus the tests of step 7 (nan where a path was not examined)."""

    section_width: np.ndarray
    """(K, M) the object's width across the pads at each examined path, m."""
    section_span: np.ndarray
    """(K, M, 2) [y_lo, y_hi] of that section about c_k, m."""
    contact_share: np.ndarray
    """(K, M) the smaller pad's in-area share of contact (nan where the rule is off)."""


class Candidate(NamedTuple):
    """One path of ``optimal_plus`` that passed checks 1-3 (its first passing roll, then depth)."""

    cluster: int
    """k of the path."""
    path: int
    """p of the path."""
    pose: np.ndarray
    """(4, 4) the grasp pose placed on it."""
    width_m: float
    """Opening width, m."""
    pad_depth_m: float
    """Depth of the shallower pad's contact, m."""
    depth_offset_m: float
    """The move along the approach from the paper's depth, m."""
    roll_deg: float
    """Roll about the approach, degrees."""


@dataclass(frozen=True)
class Shortlist:
    """The S shortlisted paths of ``optimal_plus`` (steps 4-6), in search order."""

    poses: np.ndarray
    """(S, 4, 4) grasp poses."""
    widths: np.ndarray
    """(S,) opening widths, m."""
    costs: np.ndarray
    """(S,) costs with the centre-of-mass factor."""
    robust: np.ndarray
    """(S,) bool: passes the noise test."""
    edge_excess_m: np.ndarray
    """(S,) how far a pad reaches past the object's edge beyond the clearance, m."""
    pad_depth_m: np.ndarray
    """(S,) pad contact depths, m."""


@dataclass(frozen=True)
class OptimalPlusDetails(PaperDetails):
    """``optimal_plus``: the paper's record plus the centre of mass and the shortlist."""

    com: np.ndarray
    """(3,) the cloud's volume centroid, m."""
    shortlist: Shortlist
