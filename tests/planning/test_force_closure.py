"""Two-contact force closure on hand-made contact pairs, and contacts found on a mesh and a cloud."""

import math

import numpy as np
import pytest
import trimesh

from graspexp.planning import Grasp
from graspexp.planning.collision import frame_from_axes
from graspexp.quality import contacts_for_grasp, grasp_quality, min_friction_for_closure


def _tilt(n: np.ndarray, deg: float, about=(0.0, 0.0, 1.0)) -> np.ndarray:
    return trimesh.transformations.rotation_matrix(math.radians(deg), about)[:3, :3] @ n


P1, P2 = np.array([0.0, 0.04, 0.0]), np.array([0.0, -0.04, 0.0])
N1, N2 = np.array([0.0, 1.0, 0.0]), np.array([0.0, -1.0, 0.0])  # outward: opposed, on the line


def test_opposed_normals_need_the_smallest_mu() -> None:
    assert min_friction_for_closure(P1, N1, P2, N2) == 0.2


@pytest.mark.parametrize(
    ("deg", "mu"),
    [
        (5.0, 0.2),
        (11.0, 0.2),
        (12.0, 0.4),
        (25.0, 0.6),
        (35.0, 0.8),
        (45.0, 1.0),
        (50.0, 1.2),
        (51.0, math.inf),
    ],
)
def test_tilted_normal_needs_tan_of_the_tilt(deg: float, mu: float) -> None:
    # atan(0.2) = 11.3 deg, atan(0.4) = 21.8, atan(0.6) = 31.0, atan(0.8) = 38.7, atan(1.0) = 45, atan(1.2) = 50.2
    assert min_friction_for_closure(P1, _tilt(N1, deg), P2, N2) == mu
    assert min_friction_for_closure(P1, N1, P2, _tilt(N2, -deg, (1.0, 0.0, 0.0))) == mu


def test_the_worse_contact_decides() -> None:
    assert min_friction_for_closure(P1, _tilt(N1, 15.0), P2, _tilt(N2, 40.0)) == 1.0


def test_exact_cone_boundary_counts_as_closure() -> None:
    assert min_friction_for_closure(P1, _tilt(N1, math.degrees(math.atan(0.4))), P2, N2) == 0.4


def test_same_side_normals_are_never_closure() -> None:
    assert min_friction_for_closure(P1, N1, P2, N1) == math.inf
    assert min_friction_for_closure(P1, N1, P1, N2) == math.inf  # coincident points


def test_custom_mu_list_is_taken_in_ascending_order() -> None:
    assert min_friction_for_closure(P1, _tilt(N1, 20.0), P2, N2, mus=(1.0, 0.5, 0.1)) == 0.5


def _grasp(closing, centre=(0.0, 0.0, 0.0)) -> Grasp:
    pose = frame_from_axes(np.array([0.0, 0.0, -1.0]), np.asarray(closing, float), np.asarray(centre, float))
    return Grasp(pose=pose, width_m=0.08, cost=0.0, cluster=-1, path=-1, n_feasible=1, planner="test")


def test_contacts_on_a_mesh_are_the_first_hits_along_the_closing_line() -> None:
    box = trimesh.creation.box((0.05, 0.08, 0.1))
    p1, n1, p2, n2 = contacts_for_grasp(box, _grasp([1.0, 0.0, 0.0]))
    np.testing.assert_allclose(p1, [0.025, 0, 0], atol=1e-9)
    np.testing.assert_allclose(p2, [-0.025, 0, 0], atol=1e-9)
    np.testing.assert_allclose(n1, [1, 0, 0], atol=1e-9)
    np.testing.assert_allclose(n2, [-1, 0, 0], atol=1e-9)
    q = grasp_quality(box, _grasp([1.0, 0.0, 0.0]))
    assert q["fc_min_mu"] == 0.2 and len(q["contacts"]) == 2
    # closing at 45 degrees to the faces: the line meets each face at 45 degrees -> mu = 1.0
    assert grasp_quality(box, _grasp([1.0, 1.0, 0.0]))["fc_min_mu"] == 1.0


def test_a_line_that_misses_the_mesh_gives_inf() -> None:
    q = grasp_quality(trimesh.creation.box((0.05, 0.08, 0.1)), _grasp([1.0, 0.0, 0.0], centre=(0, 0, 0.3)))
    assert q == {"fc_min_mu": math.inf, "contacts": []}


def test_contacts_on_a_cloud_use_the_extreme_points_near_the_line() -> None:
    sphere = trimesh.creation.icosphere(subdivisions=4, radius=0.03)
    pts, faces = trimesh.sample.sample_surface_even(sphere, 4000, seed=0)
    normals = pts / np.linalg.norm(pts, axis=1, keepdims=True)
    p1, n1, p2, n2 = contacts_for_grasp(pts, _grasp([0.0, 1.0, 0.0]), normals=normals, line_radius_m=0.004)
    assert p1[1] > 0.028 and p2[1] < -0.028
    assert min_friction_for_closure(p1, n1, p2, n2) == 0.2
    with pytest.raises(ValueError, match="normals"):
        contacts_for_grasp(pts, _grasp([0.0, 1.0, 0.0]))
