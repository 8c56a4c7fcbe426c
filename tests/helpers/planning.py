"""Synthetic clouds and requests shared by the planner tests."""

import copy
import functools

import numpy as np
import trimesh
from omegaconf import OmegaConf

from graspexp.config import CostConfig, GripperConfig, OptimalConfig
from graspexp.config.compose import compose_config
from graspexp.perception import Observation
from graspexp.perception.observation import given_normals
from graspexp.planning import PlanRequest

RG2 = GripperConfig(
    name="rg2",
    max_width_m=0.110,
    min_width_m=0.0,
    grip_force_n=40.0,
    finger_length_m=0.055,
    finger_width_m=0.022,
    finger_thickness_m=0.010,
    palm_size_m=[0.045, 0.150, 0.060],
)


def cylinder_cloud(
    rng: np.random.Generator, n: int = 512, radius_m: float = 0.03, height_m: float = 0.12
) -> np.ndarray:
    """(n, 3) points on the side of an upright cylinder, object frame (base at z = 0), metres."""
    theta = rng.uniform(0.0, 2.0 * np.pi, n)
    z = rng.uniform(0.0, height_m, n)
    return np.stack([radius_m * np.cos(theta), radius_m * np.sin(theta), z], axis=1)


def box_cloud(rng: np.random.Generator, n: int, size_m: tuple[float, float, float]) -> np.ndarray:
    """(n, 3) points on the surface of an axis-aligned box, base at z = 0, centred in x and y, metres."""
    sx, sy, sz = size_m
    pts = rng.uniform(-0.5, 0.5, (n, 3)) * np.array(size_m)
    face = rng.integers(0, 3, n)
    sign = rng.choice([-0.5, 0.5], n)
    pts[np.arange(n), face] = sign * np.array(size_m)[face]
    pts[:, 2] += sz / 2
    return pts


PAPER_STEPS_ONLY = {"swept_check": False, "min_contacts_in_area": 0.0}
"""``OptimalConfig`` keys that switch off the checks the paper does not print (swept gripper, area rule),
for tests of the paper's own steps."""
IN_AREA = {"pose_axis": "object", "min_contacts_in_area": 1.0}
"""``OptimalConfig`` keys of the preset ``optimal_in_area`` (every pad contact in the grasping area), for
tests of the area rule (the schema's defaults are the paper preset ``optimal``'s, without it)."""


def upright_request(model, pose: np.ndarray, mode: str, planner: OptimalConfig) -> PlanRequest:
    """A request for a loaded object (``graspexp.datasets.ObjectModel``) standing in its (4, 4)
    ``upright_pose`` on the plane z = 0.1 m, planner seed 1."""
    return PlanRequest(
        points=model.points + pose[:3, 3],
        normals=model.normals,
        area_mask=model.area_mask,
        object_pose=pose,
        table_z=UPRIGHT_SUPPORT_Z,
        mode=mode,
        gripper=RG2,
        planner=planner,
        cost=CostConfig(),
        seed=1,
    )


UPRIGHT_SUPPORT_Z = 0.1
"""Height of the support plane of :func:`upright_request`, m."""


def request(
    points: np.ndarray,
    area_mask: np.ndarray,
    *,
    table_z: float = 0.0,
    mode: str = "collab",
    seed: int = 0,
    gripper: GripperConfig = RG2,
    planner: OptimalConfig | None = None,
    cost: CostConfig | None = None,
) -> PlanRequest:
    return PlanRequest(
        points=np.asarray(points, dtype=float),
        normals=np.zeros_like(points, dtype=float),
        area_mask=np.asarray(area_mask, dtype=bool),
        object_pose=np.eye(4),
        table_z=table_z,
        mode=mode,
        gripper=gripper,
        planner=planner if planner is not None else OptimalConfig(name="optimal", m=128),
        cost=cost if cost is not None else CostConfig(),
        seed=seed,
    )


TABLE_Z = 0.1


def plain_cfg(planner: str, mode: str = "bin", *extra: str):
    """The job config of ``planner`` in ``mode`` as dataclasses (a private copy: composing with Hydra takes
    about 0.3 s, so each set of overrides is composed once per test process)."""
    return copy.deepcopy(_composed(planner, mode, *extra))


@functools.cache
def _composed(planner: str, mode: str, *extra: str):
    return OmegaConf.to_object(compose_config([f"planner={planner}", f"mode={mode}", *extra]))


def resting_cloud(mesh: trimesh.Trimesh, n: int = 768, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """Surface samples resting on the table (lowest point at TABLE_Z) and their outward normals."""
    pts, faces = trimesh.sample.sample_surface_even(mesh, n, seed=seed)
    pts = pts + np.array([0.0, 0.0, TABLE_Z - mesh.bounds[0, 2]])
    return pts, mesh.face_normals[faces]


def full_view(points: np.ndarray, normals: np.ndarray) -> Observation:
    """An observation in which the camera saw the whole cloud (no views, every point the target, id 1):
    lets the planners that read ``PlanRequest.observation`` take part in the contract tests."""
    return Observation(
        views=(),
        points=np.asarray(points, dtype=float),
        point_ids=np.ones(len(points), dtype=np.int32),
        target_id=1,
        normals_at=given_normals(normals),
    )
