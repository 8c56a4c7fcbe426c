"""Eq. (1)-(3) against values computed by hand (mm, degrees, radians spelled out)."""

import math

import numpy as np
import pytest

from graspexp.config import CostConfig
from graspexp.planning.cost import (
    all_path_costs,
    distance_term,
    path_main_axis_angles_deg,
    path_table_angles_rad,
    table_term,
)

COST = CostConfig()
G_M = 0.110


def cluster_costs(points_m, center_m, r_k_m, directions, axis, mode, table_z_m, gripper_max_width_m, cost):
    """Eq. (1) or (2) for the paths ``directions`` (M, 3) of one cluster: (M,) costs."""
    d = np.asarray(directions, dtype=np.float64)[None]
    feasible = np.ones(d.shape[:2], dtype=bool)
    return all_path_costs(
        points_m, center_m, [r_k_m], d, feasible, axis, mode, table_z_m, gripper_max_width_m, cost
    )[0]


# Collab case: path line = x axis through the centre (0, 0, 0); main axis 60 degrees from it.
PATH_X = np.array([[1.0, 0.0, 0.0]])
AXIS_60 = np.array([math.cos(math.radians(60.0)), 0.0, math.sin(math.radians(60.0))])
# Y_i (distance to the x axis) = 10 mm, 3 mm, 40 mm.
POINTS_MM = np.array([[5.0, 10.0, 0.0], [0.0, 0.0, 3.0], [-7.0, 0.0, 40.0]])
R_K_MM = 10.0


def _hand_eq1() -> float:
    angle = (0.1 * abs(60.0 - 90.0) + 0.5) / 8.0  # alpha = 60 deg -> 3.5 / 8
    s = min(1.0, 20.0 / ((10.0 - 10.0) ** 2 + 1.0))  # = 1 (capped from 20)
    s += min(1.0, 20.0 / ((3.0 - 10.0) ** 2 + 1.0))  # = 20 / 50 = 0.4
    s += min(1.0, 20.0 / ((40.0 - 10.0) ** 2 + 1.0))  # = 20 / 901
    return angle * s


def test_eq1_by_hand_on_three_points():
    assert _hand_eq1() == pytest.approx(3.5 / 8.0 * (1.0 + 0.4 + 20.0 / 901.0), rel=1e-15)
    got = cluster_costs(
        POINTS_MM / 1000.0, np.zeros(3), R_K_MM / 1000.0, PATH_X, AXIS_60, "collab", -1.0, G_M, COST
    )
    assert got.shape == (1,)
    assert got[0] == pytest.approx(_hand_eq1(), rel=1e-6)


def test_eq1_distance_sum_float32_and_float64_agree_with_hand_value():
    hand = 1.0 + 0.4 + 20.0 / 901.0
    for dtype in (np.float32, np.float64):
        got = distance_term(POINTS_MM, PATH_X, R_K_MM, COST, dtype=dtype)
        assert got[0] == pytest.approx(hand, rel=1e-6)


def test_eq1_is_the_same_for_a_path_and_its_reverse():
    both = np.array([[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]])
    got = cluster_costs(
        POINTS_MM / 1000.0, np.zeros(3), R_K_MM / 1000.0, both, AXIS_60, "collab", -1.0, G_M, COST
    )
    assert got[0] == pytest.approx(got[1], rel=1e-12)


def test_eq2_eq3_by_hand_near_and_far_from_the_table():
    beta = math.radians(30.0)  # path 30 degrees below horizontal
    d = np.array([math.cos(beta), 0.0, -math.sin(beta)])
    n1 = np.array([0.0, 1.0, 0.0])  # both orthogonal to d
    n2 = np.array([math.sin(beta), 0.0, math.cos(beta)])
    points_mm = np.stack([20.0 * d + 10.0 * n1, -5.0 * d + 4.0 * n2])  # Y = 10 mm and 4 mm
    axis = np.array([0.0, 1.0, 0.0])  # alpha = 90 deg
    angle = (0.1 * abs(90.0 - 90.0) + 0.5) / 8.0  # 0.0625
    dist = min(1.0, 20.0 / ((10.0 - 10.0) ** 2 + 1.0)) + min(
        1.0, 20.0 / ((4.0 - 10.0) ** 2 + 1.0)
    )  # 1 + 20/37
    t_near = (math.pi / 6.0 - math.pi / 2.0) ** 2 / 2.0 + 0.05  # d_k = 50 mm <= g = 110 mm
    t_far = 1.0  # d_k = 200 mm > g

    near = cluster_costs(points_mm / 1000.0, np.zeros(3), 0.010, d[None], axis, "bin", -0.050, G_M, COST)
    far = cluster_costs(points_mm / 1000.0, np.zeros(3), 0.010, d[None], axis, "bin", -0.200, G_M, COST)
    collab = cluster_costs(points_mm / 1000.0, np.zeros(3), 0.010, d[None], axis, "collab", -0.050, G_M, COST)
    assert near[0] == pytest.approx(angle * dist * t_near, rel=1e-6)
    assert far[0] == pytest.approx(angle * dist * t_far, rel=1e-6)
    assert collab[0] == pytest.approx(angle * dist, rel=1e-6)


def test_eq3_switches_exactly_at_the_gripper_stroke():
    beta = np.array([0.0, math.pi / 4, math.pi / 2])
    at = table_term(110.0, beta, 110.0, COST)
    np.testing.assert_allclose(at, (beta - math.pi / 2) ** 2 / 2.0 + 0.05, rtol=1e-15)
    np.testing.assert_array_equal(table_term(110.001, beta, 110.0, COST), [1.0, 1.0, 1.0])
    assert at[2] == pytest.approx(0.05)  # a vertical path costs only the offset


def test_angles_are_line_angles_in_their_ranges():
    axis = np.array([0.0, 0.0, 1.0])
    dirs = np.array(
        [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, math.sqrt(0.5), -math.sqrt(0.5)]]
    )
    np.testing.assert_allclose(path_main_axis_angles_deg(dirs, axis), [0.0, 0.0, 90.0, 45.0], atol=1e-6)
    np.testing.assert_allclose(
        path_table_angles_rad(dirs), [math.pi / 2, math.pi / 2, 0.0, math.pi / 4], atol=1e-12
    )


def test_cost_constants_come_from_the_config():
    doubled = CostConfig(distance_numerator_mm2=40.0, distance_cap=5.0, angle_divisor=4.0)
    got = cluster_costs(
        POINTS_MM / 1000.0, np.zeros(3), R_K_MM / 1000.0, PATH_X, AXIS_60, "collab", -1.0, G_M, doubled
    )
    hand = (0.1 * 30.0 + 0.5) / 4.0 * (min(5.0, 40.0) + min(5.0, 40.0 / 50.0) + min(5.0, 40.0 / 901.0))
    assert got[0] == pytest.approx(hand, rel=1e-6)


def test_unknown_mode_is_rejected():
    with pytest.raises(ValueError, match="mode='pick'"):
        cluster_costs(POINTS_MM / 1000.0, np.zeros(3), 0.01, PATH_X, AXIS_60, "pick", 0.0, G_M, COST)
