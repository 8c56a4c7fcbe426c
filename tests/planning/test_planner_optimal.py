"""plan_optimal end to end on synthetic clouds: contract, determinism, failures, properties."""

import dataclasses

import numpy as np
import pytest
from helpers.planning import IN_AREA, PAPER_STEPS_ONLY, RG2, box_cloud, cylinder_cloud, request
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from graspexp.config import OptimalConfig
from graspexp.core.geometry import quat_wxyz_to_matrix
from graspexp.planning import NoFeasibleGrasp, UnknownPlanner, get_planner, plan, plan_optimal
from graspexp.planning.collision import cloud_hits, lowest_z

DETAIL_KEYS = {
    "cloud",
    "area_mask",
    "centers",
    "radii",
    "main_axis",
    "directions",
    "feasible",
    "costs",
    "best",
    "pose",
    "width",
    "mode",
    "table_z",
    "sphere_radius",
    "gripper_max_width",
}


def _upright_cylinder(seed=0, n=512, table_z=0.1):
    rng = np.random.default_rng(seed)
    pts = cylinder_cloud(rng, n, radius_m=0.03, height_m=0.12) + [0.0, 0.0, table_z]
    mask = (pts[:, 2] > table_z + 0.03) & (pts[:, 2] < table_z + 0.11)
    return pts, mask


def _check_result(res, req):
    g, det = res.grasp, res.details
    assert DETAIL_KEYS <= set(res.detail_arrays())
    k, m = det.costs.shape
    assert m == req.planner.m and det.directions.shape == (k, m, 3)
    assert det.centers.shape == (k, 3) and det.radii.shape == (k,)
    assert np.isinf(det.costs[~det.feasible]).all()
    assert np.isfinite(det.costs[det.feasible]).all()
    kb, pb = det.best
    assert (g.cluster, g.path) == (kb, pb)
    assert det.feasible[kb, pb]
    assert g.cost == det.costs[kb, pb] == det.costs.min()
    # Pose per Fig. 9.
    R = g.pose[:3, :3]
    np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-9)
    assert np.linalg.det(R) == pytest.approx(1.0, abs=1e-9)
    np.testing.assert_allclose(g.approach, det.directions[kb, pb], atol=1e-12)
    assert abs(R[:, 0] @ R[:, 2]) < 1e-9
    # Origin: c_k moved along Y to the middle of the section between the pads.
    shift = g.extras["centre_shift_m"]
    assert shift == pytest.approx(det.section_span[kb, pb].mean(), abs=1e-15)
    np.testing.assert_allclose(g.position, det.centers[kb] + shift * R[:, 1], atol=1e-12)
    lo, hi = det.section_span[kb, pb] - shift
    assert -g.width_m / 2 <= lo <= hi <= g.width_m / 2  # both pads clear the section
    np.testing.assert_array_equal(g.pose, det.pose)
    # The path starts above the support plane.
    start = det.centers[kb] - req.planner.sphere_radius_m * det.directions[kb, pb]
    assert start[2] >= req.table_z + req.planner.table_clearance_m
    # Width inside the stroke, section between the pads too.
    assert req.gripper.min_width_m <= g.width_m <= req.gripper.max_width_m
    assert g.width_m == det.width
    assert g.extras["slab_extent_m"] <= req.gripper.max_width_m
    assert g.extras["slab_extent_m"] <= g.width_m  # the open fingers clear the section they close on
    assert det.section_width[kb, pb] == g.extras["slab_extent_m"]
    assert g.planner == "optimal" and g.extras["K"] == k and g.extras["M"] == m
    assert g.n_feasible == int(det.feasible.sum())


@pytest.mark.parametrize("mode", ["collab", "bin"])
def test_plan_contract_on_an_upright_cylinder(mode):
    pts, mask = _upright_cylinder()
    req = request(pts, mask, table_z=0.1, mode=mode)
    res = plan_optimal(req)
    _check_result(res, req)
    np.testing.assert_array_equal(res.details.cloud, pts)
    np.testing.assert_array_equal(res.details.area_mask, mask)
    assert str(res.details.mode) == mode
    # The cylinder's area is 80 mm tall and 60 mm wide: its main axis is vertical and the best
    # collab path is close to orthogonal to it (Eq. 1's first factor).
    assert abs(res.details.main_axis[2]) > 0.9
    if mode == "collab":
        assert abs(res.grasp.approach @ res.details.main_axis) < 0.5


def test_bin_mode_prefers_steeper_paths_near_the_table():
    rng = np.random.default_rng(4)
    pts = box_cloud(rng, 800, (0.05, 0.15, 0.03))  # a flat bar lying on the table
    mask = np.ones(len(pts), dtype=bool)
    collab = plan_optimal(request(pts, mask, mode="collab"))
    bins = plan_optimal(request(pts, mask, mode="bin"))
    # Eq. (3) pulls the approach towards vertical (beta -> pi/2) when the centre is within g of the table.
    assert abs(bins.grasp.approach[2]) >= abs(collab.grasp.approach[2])
    assert abs(bins.grasp.approach[2]) > 0.9


def test_same_seed_gives_the_same_grasp_bit_for_bit():
    pts, mask = _upright_cylinder(seed=2)
    a = plan_optimal(request(pts, mask, table_z=0.1, seed=11))
    b = plan_optimal(request(pts.copy(), mask.copy(), table_z=0.1, seed=11))
    assert a.grasp.pose.tobytes() == b.grasp.pose.tobytes()
    assert (a.grasp.cost, a.grasp.width_m, a.grasp.cluster, a.grasp.path) == (
        b.grasp.cost,
        b.grasp.width_m,
        b.grasp.cluster,
        b.grasp.path,
    )
    for key in DETAIL_KEYS:
        assert a.detail_arrays()[key].tobytes() == b.detail_arrays()[key].tobytes(), key


def test_k_auto_follows_the_area_length_and_the_gripper():
    rng = np.random.default_rng(5)
    pts = cylinder_cloud(rng, 1500, radius_m=0.01, height_m=0.2)  # area length ~0.2 m along z
    mask = np.ones(len(pts), dtype=bool)
    length = np.ptp(pts[:, 2])
    expected = int(np.ceil(length / (1.0 * RG2.max_width_m)))  # clusters one stroke long (default)
    assert expected == 2
    res = plan_optimal(request(pts, mask))
    assert res.grasp.extras["K"] == expected
    half = OptimalConfig(name="optimal", auto_k_stroke_fraction=0.5)
    assert plan_optimal(request(pts, mask, planner=half)).grasp.extras["K"] == 4
    wide = dataclasses.replace(RG2, max_width_m=0.5)
    assert plan_optimal(request(pts, mask, gripper=wide)).grasp.extras["K"] == 1
    capped = OptimalConfig(name="optimal", m=64, k_max=2)
    assert plan_optimal(request(pts, mask, planner=capped)).grasp.extras["K"] == 2
    fixed = OptimalConfig(name="optimal", m=64, k=3)
    assert plan_optimal(request(pts, mask, planner=fixed)).details.centers.shape == (3, 3)


def test_empty_area_raises():
    pts, _ = _upright_cylinder()
    with pytest.raises(NoFeasibleGrasp, match="grasping area is empty"):
        plan_optimal(request(pts, np.zeros(len(pts), dtype=bool), table_z=0.1))


def test_every_path_through_the_table_raises():
    pts, mask = _upright_cylinder(table_z=0.0)
    with pytest.raises(NoFeasibleGrasp, match="below the support plane"):
        plan_optimal(request(pts, mask, table_z=0.5))  # the plane is far above the object
    clearance = OptimalConfig(name="optimal", m=64, table_clearance_m=0.3)
    with pytest.raises(NoFeasibleGrasp, match="below the support plane"):
        plan_optimal(request(pts, mask, table_z=0.0, planner=clearance))


def test_object_wider_than_the_gripper_raises():
    rng = np.random.default_rng(6)
    u = rng.normal(size=(1500, 3))
    ball = 0.1 * u / np.linalg.norm(u, axis=1, keepdims=True)  # 200 mm ball: every section > 110 mm
    one = OptimalConfig(name="optimal", m=64, k=1, **PAPER_STEPS_ONLY)  # the palm would be in the ball
    with pytest.raises(NoFeasibleGrasp, match="wider than the gripper"):
        plan_optimal(request(ball, np.ones(len(ball), dtype=bool), table_z=-1.0, planner=one))
    big = dataclasses.replace(RG2, max_width_m=0.25)
    res = plan_optimal(request(ball, np.ones(len(ball), dtype=bool), table_z=-1.0, planner=one, gripper=big))
    assert res.grasp.extras["slab_extent_m"] > 0.15


def test_paths_found_too_wide_are_skipped_for_the_next_cheapest():
    rng = np.random.default_rng(7)
    # A 200 mm x 40 mm x 40 mm bar and a 45 mm stroke: only closings across two opposite faces fit
    # (the square section's diagonal is 57 mm), so cheaper paths get rejected first.
    pts = box_cloud(rng, 2000, (0.2, 0.04, 0.04))
    mask = np.abs(pts[:, 0]) < 0.03
    narrow = dataclasses.replace(RG2, max_width_m=0.045)
    res = plan_optimal(request(pts, mask, table_z=-1.0, gripper=narrow))
    assert res.grasp.extras["n_too_wide"] > 0
    assert res.grasp.extras["slab_extent_m"] <= 0.045
    assert (~res.details.feasible).sum() == res.grasp.extras["n_too_wide"]  # no table in reach
    assert res.grasp.cost == res.details.costs.min()


def test_a_band_shorter_than_its_diameter_is_closed_across_not_along_its_height():
    # A 66 mm can whose area is a 40 mm band, main axes from the area (main_axis = pose_axis = area): PCA puts
    # the main axis horizontal, so a horizontal
    # approach would close the fingers along the can's height (100 mm section) with a ~75 mm opening.
    # That section does not fit the r_k opening; the planner goes on to a path whose section does.
    rng = np.random.default_rng(8)
    pts = cylinder_cloud(rng, 2048, radius_m=0.033, height_m=0.10) + [0.0, 0.0, 0.1]
    mask = (pts[:, 2] > 0.13) & (pts[:, 2] < 0.17)
    area_axes = OptimalConfig(
        name="optimal", main_axis="area", pose_axis="area", cluster_radius="rms", auto_k_stroke_fraction=0.5
    )
    req = request(pts, mask, table_z=0.1, planner=area_axes)
    res = plan_optimal(req)
    _check_result(res, req)
    assert abs(res.details.main_axis[2]) < 0.3
    assert abs(res.grasp.pose[2, 1]) < 0.3  # closing axis Y is (nearly) horizontal
    assert res.grasp.extras["slab_extent_m"] < 0.075
    assert res.grasp.extras["n_too_wide"] > 0 and not res.grasp.extras["widened"]


def test_object_main_axis_of_a_can_is_its_height():
    # planner.main_axis=object (default): the whole can's first principal component is its axis, even
    # when the grasping area is a short band; the fingers then close across the can.
    rng = np.random.default_rng(8)
    pts = cylinder_cloud(rng, 2048, radius_m=0.033, height_m=0.10) + [0.0, 0.0, 0.1]
    mask = (pts[:, 2] > 0.13) & (pts[:, 2] < 0.17)
    res = plan_optimal(request(pts, mask, table_z=0.1, planner=OptimalConfig(name="optimal")))
    assert abs(res.details.main_axis[2]) > 0.95
    assert abs(res.grasp.pose[2, 1]) < 0.3


def test_opening_is_widened_when_no_section_fits_the_cluster_radius():
    rng = np.random.default_rng(9)
    pts = box_cloud(rng, 3000, (0.06, 0.06, 0.06))
    mask = (
        (np.abs(pts[:, 0] - 0.03) < 1e-9) & (np.abs(pts[:, 1]) < 0.004) & (np.abs(pts[:, 2] - 0.03) < 0.004)
    )
    assert 0 < mask.sum() < 30  # a tiny patch: r_k of a few mm, opening far below any section
    req = request(pts, mask, table_z=-1.0, planner=OptimalConfig(name="optimal", m=64, **PAPER_STEPS_ONLY))
    res = plan_optimal(req)
    _check_result(res, req)
    g = res.grasp
    assert g.extras["widened"]
    assert g.width_m > 2 * res.details.radii[g.cluster] * 1.2
    assert g.width_m == pytest.approx(min(g.extras["slab_extent_m"] * 1.2, RG2.max_width_m))


def test_registry_dispatches_and_lists_names():
    assert get_planner("optimal_literal") is plan_optimal  # the same function under a second preset
    assert get_planner("optimal") is plan_optimal
    with pytest.raises(UnknownPlanner, match="planner.name='nope' is unknown: expected one of .*optimal"):
        get_planner("nope")
    pts, mask = _upright_cylinder()
    req = request(pts, mask, table_z=0.1)
    assert plan(req).grasp.pose.tobytes() == plan_optimal(req).grasp.pose.tobytes()
    other = dataclasses.replace(req, planner=OptimalConfig(name="missing"))
    with pytest.raises(UnknownPlanner, match="missing"):
        plan(other)


def test_bad_inputs_are_rejected():
    pts, mask = _upright_cylinder()
    with pytest.raises(ValueError, match="area_mask has shape"):
        plan_optimal(request(pts, mask[:-1], table_z=0.1))
    with pytest.raises(ValueError, match="mode='pick'"):
        plan_optimal(request(pts, mask, table_z=0.1, mode="pick"))


unit_quat = st.tuples(*[st.floats(-1.0, 1.0) for _ in range(4)]).filter(
    lambda q: sum(v * v for v in q) > 0.05
)


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    shape=st.sampled_from(["cylinder", "box"]),
    dims=st.tuples(st.floats(0.01, 0.04), st.floats(0.02, 0.06), st.floats(0.02, 0.06)),
    n=st.integers(60, 400),
    quat=unit_quat,
    table_z=st.floats(-0.5, 0.5),
    xy=st.tuples(st.floats(-0.3, 0.3), st.floats(-0.3, 0.3)),
    mode=st.sampled_from(["collab", "bin"]),
    band=st.tuples(st.floats(0.0, 0.6), st.floats(0.3, 1.0)),
    seed=st.integers(0, 2**31 - 1),
)
def test_property_valid_grasp_for_random_clouds_and_poses(
    shape, dims, n, quat, table_z, xy, mode, band, seed
):
    """The paper's steps alone always give a grasp; with the swept check and the area rule (the defaults)
    a grasp, when there is one, is clear of the cloud and the support and has its pads in the area."""
    rng = np.random.default_rng(seed)
    if shape == "cylinder":
        obj = cylinder_cloud(rng, n, radius_m=dims[0], height_m=2 * dims[1])
    else:
        obj = box_cloud(rng, n, dims)
    R = quat_wxyz_to_matrix(np.array(quat))
    world = obj @ R.T
    world += [xy[0], xy[1], table_z - world[:, 2].min()]  # resting on the plane z = table_z
    # Grasping area: a band of the object along a random object-frame direction.
    direction = rng.normal(size=3)
    proj = obj @ (direction / np.linalg.norm(direction))
    lo, hi = np.quantile(proj, [min(band), max(band)])
    mask = (proj >= lo) & (proj <= hi)
    mask[int(np.argmin(np.abs(proj - (lo + hi) / 2)))] = True
    req = request(
        world,
        mask,
        table_z=table_z,
        mode=mode,
        seed=seed % 1000,
        planner=OptimalConfig(name="optimal", m=64, **PAPER_STEPS_ONLY),
    )
    res = plan_optimal(req)
    _check_result(res, req)
    checked = dataclasses.replace(req, planner=OptimalConfig(name="optimal", m=64, **IN_AREA))
    try:
        res = plan_optimal(checked)
    except NoFeasibleGrasp as e:
        assert "planner.swept_check" in str(e) or "grasping area" in str(e)
        return
    _check_result(res, checked)
    g = res.grasp
    assert cloud_hits(world, g.pose[None], RG2, g.width_m, sweep_m=0.1, margin_m=0.0)[0] == 0
    assert lowest_z(g.pose[None], RG2, g.width_m, 0.1)[0] >= table_z
    assert res.details.contact_share[g.cluster, g.path] == 1.0
