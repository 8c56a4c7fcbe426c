"""Synthetic clouds and requests shared by the planner tests (pure numpy; imported by the others)."""

import numpy as np

from graspexp.config import CostConfig, GripperConfig, OptimalConfig
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


def test_synthetic_clouds_lie_on_their_surfaces():
    rng = np.random.default_rng(0)
    cyl = cylinder_cloud(rng, 200, radius_m=0.03, height_m=0.1)
    np.testing.assert_allclose(np.hypot(cyl[:, 0], cyl[:, 1]), 0.03, atol=1e-12)
    box = box_cloud(rng, 300, (0.02, 0.04, 0.06))
    on_face = np.isclose(np.abs(box[:, 0]), 0.01) | np.isclose(np.abs(box[:, 1]), 0.02)
    on_face |= np.isclose(box[:, 2], 0.0) | np.isclose(box[:, 2], 0.06)
    assert on_face.all()
