"""The planner config keys that name the paper's open choices, and the two presets built from them."""

import numpy as np
import pytest
from helpers.config import compose_cfg
from helpers.planning import PAPER_STEPS_ONLY, RG2, cylinder_cloud, request
from omegaconf import OmegaConf

from graspexp.config import OptimalConfig
from graspexp.planning import plan_optimal
from graspexp.planning.clusters import elongation, main_axis


def _can_with_band(seed: int = 3):
    """A 66 mm can on a table at z = 0.1 whose grasping area is its upper 60 mm."""
    rng = np.random.default_rng(seed)
    pts = cylinder_cloud(rng, 2048, radius_m=0.033, height_m=0.10) + [0.0, 0.0, 0.1]
    return pts, pts[:, 2] > 0.14


def _plan(**keys):
    pts, mask = _can_with_band()
    return plan_optimal(request(pts, mask, table_z=0.1, planner=OptimalConfig(name="optimal", **keys)))


def test_cluster_radius_max_is_the_farthest_member_and_sets_the_opening():
    far, rms = _plan(cluster_radius="max"), _plan(cluster_radius="rms")
    pts, mask = _can_with_band()
    area, labels = pts[mask], far.details.labels
    for j, c in enumerate(far.details.centers):
        assert far.details.radii[j] == pytest.approx(np.linalg.norm(area[labels == j] - c, axis=1).max())
    assert (far.details.radii > rms.details.radii).all()
    k = far.grasp.cluster
    if not far.grasp.extras["widened"]:
        expected = min(2 * far.details.radii[k] * 1.2, RG2.max_width_m)
        assert far.grasp.width_m == pytest.approx(expected)


def test_grasp_point_centre_keeps_c_k_and_section_middle_moves_along_y_only():
    centre, middle = _plan(grasp_point="centre"), _plan(grasp_point="section_middle")
    assert (centre.grasp.cluster, centre.grasp.path) == (middle.grasp.cluster, middle.grasp.path)
    c_k = centre.details.centers[centre.grasp.cluster]
    np.testing.assert_array_equal(centre.grasp.pose[:3, 3], c_k)
    assert centre.grasp.extras["centre_shift_m"] == 0.0
    offset = middle.grasp.pose[:3, 3] - c_k
    shift = middle.grasp.extras["centre_shift_m"]
    np.testing.assert_allclose(offset, shift * middle.grasp.pose[:3, 1], atol=1e-12)
    lo, hi = middle.details.section_span[middle.grasp.cluster, middle.grasp.path]
    assert shift == pytest.approx((lo + hi) / 2)


def test_without_the_section_fit_the_cheapest_path_wins_even_if_the_object_is_wider():
    # Opening 2 r_k with r_k the RMS radius and no margin: far too narrow for the can's 66 mm section.
    keys = {"cluster_radius": "rms", "width_margin": 0.0, "k": 3, **PAPER_STEPS_ONLY}
    fit, printed = _plan(section_fit=True, **keys), _plan(section_fit=False, **keys)
    costs = printed.details.costs
    assert printed.grasp.cost == costs.min()
    assert printed.grasp.extras["n_too_wide"] == 0 and not printed.grasp.extras["widened"]
    assert printed.grasp.n_feasible == int(np.isfinite(costs).sum())
    assert printed.grasp.extras["slab_extent_m"] > printed.grasp.width_m  # a pad lands on the object
    # With the test, the chosen path's section fits the opening it is given.
    assert fit.grasp.extras["slab_extent_m"] <= fit.grasp.width_m + 1e-12
    assert fit.grasp.cost >= printed.grasp.cost


def test_pose_axis_sets_the_grasp_x_axis_and_main_axis_the_cost_angle():
    pts, mask = _can_with_band()
    for source, cloud in (("object", pts), ("area", pts[mask])):
        res = _plan(pose_axis=source)
        x, z = res.grasp.pose[:3, 0], res.grasp.pose[:3, 2]
        a = main_axis(cloud)
        expected = a - (a @ z) * z
        np.testing.assert_allclose(x, expected / np.linalg.norm(expected), atol=1e-9)
        np.testing.assert_array_equal(res.details.pose_axis, a)
        np.testing.assert_array_equal(res.details.main_axis, main_axis(pts))  # alpha unchanged


def test_presets_differ_only_in_the_documented_reading_keys():
    ours, literal = compose_cfg("planner=optimal").planner, compose_cfg("planner=optimal_literal").planner
    differ = {k for k in ours if ours[k] != literal[k]}
    assert differ == {"name", "pose_axis", "grasp_point", "section_fit", "width_margin", "swept_check"}
    assert (literal.pose_axis, literal.grasp_point, literal.section_fit, literal.width_margin) == (
        "area",
        "centre",
        False,
        0.0,
    )
    assert (literal.swept_check, literal.min_contacts_in_area) == (False, 0.0)


def test_the_paper_preset_has_no_area_rule_and_optimal_in_area_adds_only_that_and_the_object_axis():
    """``optimal`` rejects no path for where its pads land (the paper scores "still held", IV-C);
    ``optimal_in_area`` is the earlier default: the area rule on the pads and the object's axis as X."""
    ours, in_area = compose_cfg("planner=optimal").planner, compose_cfg("planner=optimal_in_area").planner
    assert ours.min_contacts_in_area == 0.0 and ours.pose_axis == "area_if_elongated"
    differ = {k for k in ours if ours[k] != in_area[k]}
    assert differ == {"name", "min_contacts_in_area", "pose_axis"}
    assert (in_area.min_contacts_in_area, in_area.pose_axis) == (1.0, "object")


def _l_shape(seed: int = 5):
    """An L of two 20 mm bars on a table at z = 0.1: a 160 mm housing along X (the grasping area) and a
    120 mm handle along -Y below one end; the whole L's main axis lies between them."""
    rng = np.random.default_rng(seed)
    housing = rng.uniform([-0.08, -0.01, 0.1], [0.08, 0.01, 0.12], (1500, 3))
    handle = rng.uniform([-0.08, -0.13, 0.1], [-0.06, -0.01, 0.12], (1500, 3))
    pts = np.vstack([housing, handle])
    return pts, np.arange(len(pts)) < len(housing)


def test_area_if_elongated_takes_the_area_axis_of_a_long_area_and_the_object_axis_of_a_ring():
    # A long area (elongation ~8): the area's axis, unlike the L's own.
    pts, mask = _l_shape()
    assert elongation(pts[mask]) > 4
    pl = OptimalConfig(
        name="optimal", pose_axis="area_if_elongated", min_contacts_in_area=0.0, swept_check=False
    )
    res = plan_optimal(request(pts, mask, table_z=0.1, planner=pl))
    np.testing.assert_array_equal(res.details.pose_axis, main_axis(pts[mask]))
    assert abs(main_axis(pts) @ main_axis(pts[mask])) < 0.95
    # A band around a can (elongation ~1: any direction across it is a first component): the object's.
    can, band = _can_with_band()
    assert elongation(can[band]) < 1.5
    res = plan_optimal(request(can, band, table_z=0.1, planner=pl))
    np.testing.assert_array_equal(res.details.pose_axis, main_axis(can))
    # The threshold decides: above the area's elongation, the object's axis is used there too.
    high = OptimalConfig(**{**pl.__dict__, "pose_axis_min_elongation": elongation(pts[mask]) + 1})
    res = plan_optimal(request(pts, mask, table_z=0.1, planner=high))
    np.testing.assert_array_equal(res.details.pose_axis, main_axis(pts))


def test_elongation_is_the_ratio_of_the_principal_standard_deviations():
    rng = np.random.default_rng(0)
    box = rng.uniform(-1, 1, (20_000, 3)) * [3.0, 1.0, 0.5]
    assert elongation(box) == pytest.approx(3.0, rel=0.03)
    assert elongation(np.zeros((1, 3))) == 1.0


def test_literal_preset_plans_the_printed_argmin_at_c_k():
    pts, mask = _can_with_band()
    cfg = compose_cfg("planner=optimal_literal")
    pl = OmegaConf.to_object(cfg.planner)
    res = plan_optimal(request(pts, mask, table_z=0.1, planner=pl))
    assert res.grasp.planner == "optimal_literal"
    assert res.grasp.cost == res.details.costs.min()
    np.testing.assert_array_equal(res.grasp.pose[:3, 3], res.details.centers[res.grasp.cluster])
    expected = min(2 * res.details.radii[res.grasp.cluster], RG2.max_width_m)
    assert res.grasp.width_m == pytest.approx(expected)
