"""optimal_plus's added terms, each on its own: the stability measures (pad contacts, gravity arm, centre of
mass, pose noise) on synthetic clouds, and each planner key changing the grasp the way its docstring says."""

import dataclasses

import numpy as np
import pytest
import trimesh
from helpers.planning import TABLE_Z, plain_cfg, resting_cloud

from graspexp.core.geometry import make_pose, random_rotation
from graspexp.grippers import GripperGeometry
from graspexp.planning import NoFeasibleGrasp, PlanRequest, plan
from graspexp.planning.stability import (
    gravity_arm_m,
    pad_contacts,
    pad_edge_excess_m,
    pose_perturbations,
    volume_centroid_m,
)


def _request(pts, normals, area=None, seed: int = 3, mode: str = "bin", **planner) -> PlanRequest:
    cfg = plain_cfg("optimal_plus")
    pl = dataclasses.replace(cfg.planner, **planner)
    mask = np.ones(len(pts), bool) if area is None else area
    return PlanRequest(pts, normals, mask, np.eye(4), TABLE_Z, mode, cfg.gripper, pl, cfg.cost, seed)


def _geometry() -> GripperGeometry:
    return GripperGeometry.of(plain_cfg("optimal_plus").gripper)


def test_volume_centroid_is_the_solid_centroid_not_the_surface_mean() -> None:
    cone = trimesh.creation.cone(radius=0.05, height=0.12, sections=64)
    pts, _ = trimesh.sample.sample_surface_even(cone, 4000, seed=1)
    assert volume_centroid_m(pts)[2] == pytest.approx(0.12 / 4, abs=1e-3)  # a solid cone: h/4 above its base
    flat = np.c_[np.random.default_rng(0).random((50, 2)), np.zeros(50)]  # no 3-D hull: the point mean
    np.testing.assert_allclose(volume_centroid_m(flat), flat.mean(axis=0))


def test_gravity_arm_is_the_horizontal_distance_across_the_closing_axis() -> None:
    pose = np.eye(4)
    pose[:3, :3] = [[0, 1, 0], [1, 0, 0], [0, 0, -1]]  # approach straight down, closing axis along world x
    assert gravity_arm_m(pose[None], [0.0, 0.05, 0.0])[0] == pytest.approx(0.05)  # beside the closing line
    assert gravity_arm_m(pose[None], [0.05, 0.0, 0.0])[0] == pytest.approx(0.0)  # on it
    assert gravity_arm_m(pose[None], [0.0, 0.0, -0.05])[0] == pytest.approx(0.0)  # straight below it


def test_pad_contacts_depth_and_cone_angle() -> None:
    geo = _geometry()
    frame = np.eye(4)[None]
    box = trimesh.creation.box((0.02, 0.04, 0.03))
    box.apply_translation([0.0, 0.0, -0.03])  # faces at y = +-0.02, z from -0.045 to -0.015
    pts, faces = trimesh.sample.sample_surface_even(box, 3000, seed=2)
    normals = box.face_normals[faces]
    depth, angle, _ = pad_contacts(pts, normals, frame, geo, 0.002)
    assert depth[0] == pytest.approx(geo.tip_z_m + 0.03, abs=2e-3)  # the faces' middle, 3 cm behind the TCP
    assert angle[0] < np.radians(
        3
    )  # flat faces across the closing axis (the band takes in a few edge points)
    shifted = pts + [
        0.0,
        0.0,
        geo.tip_z_m + 0.041,
    ]  # the faces now span z from tip - 4 mm to past the tips: an edge grasp
    depth_tip, _, _ = pad_contacts(shifted, normals, frame, geo, 0.002)
    assert depth_tip[0] == pytest.approx(0.002, abs=0.0015)
    ball = trimesh.creation.icosphere(subdivisions=4, radius=0.1)
    pts, faces = trimesh.sample.sample_surface_even(ball, 20000, seed=3)
    cap = pts + [0.0, 0.0, geo.tip_z_m + 0.1 - 0.008]  # the pads reach 8 mm into a 0.2 m ball: its cap
    _, cap_angle, _ = pad_contacts(cap, ball.face_normals[faces], frame, geo, 0.002)
    assert np.degrees(cap_angle[0]) > 45  # the pads would press on the cap's slope, outside any cone
    nothing, no_angle, _ = pad_contacts(pts + [1.0, 0, 0], normals, frame, geo, 0.002)
    assert nothing[0] == -np.inf and no_angle[0] == pytest.approx(np.pi)


def test_pose_perturbations_rotate_about_the_object_origin() -> None:
    rng = np.random.default_rng(0)
    origin = np.array([0.3, -0.2, 0.5])
    still = pose_perturbations(rng, 4, 0.0, 0.0, origin)
    np.testing.assert_allclose(still, np.tile(np.eye(4), (4, 1, 1)), atol=1e-12)
    turned = pose_perturbations(rng, 64, 0.0, 5.0, origin)
    np.testing.assert_allclose(
        turned[:, :3, :3] @ origin + turned[:, :3, 3], np.tile(origin, (64, 1)), atol=1e-12
    )
    moved = pose_perturbations(rng, 2000, 3.0, 0.0, origin)[:, :3, 3]
    assert moved.std(axis=0) == pytest.approx([0.003] * 3, rel=0.1)


def _tee() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A T lying flat: a 0.06 m wide stem along y and a 0.2 x 0.04 m bar across its end; the area is the
    bar. Across the object's main axis (y) the bar is 0.2 m, wider than the stroke; across the bar it is
    0.04 m, but where the stem joins it the stem lies between the pads as well."""
    stem = trimesh.creation.box((0.06, 0.16, 0.04))
    stem.apply_translation([0.0, -0.1, 0.0])  # y from -0.18 to -0.02, where the bar starts
    bar = trimesh.creation.box((0.2, 0.04, 0.04))
    tee = trimesh.util.concatenate([stem, bar])  # touching, not overlapping: no boolean engine needed
    pts, normals = resting_cloud(tee, n=3000)
    area = pts[:, 1] > -0.021
    return pts, normals, area


def test_rolls_let_a_path_close_along_the_main_axis() -> None:
    pts, normals, area = _tee()
    with pytest.raises(NoFeasibleGrasp, match="too wide"):
        plan(_request(pts, normals, area, rolls_deg=[0.0]))
    g = plan(_request(pts, normals, area)).grasp
    assert g.extras["roll_deg"] == 90.0
    assert abs(g.pose[:3, 1][1]) > 0.9  # closing across the bar, along world y
    assert abs(g.position[0]) > 0.03 + 0.011  # beside the stem: a pad's half-width clear of it


def test_finger_width_clusters_reach_the_ends_of_a_long_area() -> None:
    pts, normals, area = _tee()
    with pytest.raises(NoFeasibleGrasp):
        plan(_request(pts, normals, area, cluster_length="stroke", rolls_deg=[90.0]))
    g = plan(_request(pts, normals, area, cluster_length="finger_width", rolls_deg=[90.0])).grasp
    assert g.extras["K"] > 1  # the area is 0.04 m long along the object's main axis: one stroke, two pads


def test_min_pad_depth_rejects_fingertip_grasps() -> None:
    flat = trimesh.creation.box((0.09, 0.06, 0.03))  # 3 cm high on the table: the pads reach 2.8 cm of it
    pts, normals = resting_cloud(flat, n=2000)
    g = plan(_request(pts, normals)).grasp
    assert g.extras["pad_depth_m"] >= 0.005
    with pytest.raises(NoFeasibleGrasp, match="pad contact shallower than 0.09 m"):
        plan(_request(pts, normals, min_pad_depth_m=0.09))  # deeper than the 8 cm fingers reach


def test_depth_offsets_move_the_grasp_towards_the_target_depth() -> None:
    box = trimesh.creation.box((0.05, 0.05, 0.1))
    pts, normals = resting_cloud(box, n=2000)
    depth = {
        t: plan(_request(pts, normals, pad_depth_target_m=t, choose_by="cost")).grasp.extras["pad_depth_m"]
        for t in (0.012, 0.045)
    }
    assert depth[0.045] > 0.035  # the table stops the fingertips short of the target
    assert depth[0.012] < depth[0.045] - 0.005  # reached without moving: the smallest move wins
    only = plan(
        _request(pts, normals, depth_offsets_m=[0.0], pad_depth_target_m=0.045, choose_by="cost")
    ).grasp
    assert only.extras["depth_offset_m"] == 0.0


def test_com_weight_prefers_grasps_near_the_centre_of_mass() -> None:
    """A hammer-like bar: a heavy head at one end, the area the whole handle (the factor scales the
    paper's cost: ``choose_by=cost``; with ``edge_clearance`` it breaks ties)."""
    handle = trimesh.creation.box((0.24, 0.03, 0.03))
    head = trimesh.creation.box((0.04, 0.09, 0.06))
    head.apply_translation([0.14, 0.0, 0.015])  # x from 0.12, where the handle ends
    hammer = trimesh.util.concatenate([handle, head])
    pts, normals = resting_cloud(hammer, n=3000)
    area = pts[:, 0] < 0.11
    arms = {
        w: plan(_request(pts, normals, area, com_weight=w, choose_by="cost")).grasp.extras["gravity_arm_m"]
        for w in (0.0, 20.0)
    }
    assert arms[20.0] < arms[0.0] - 0.01


def _slab(lo, hi) -> trimesh.Trimesh:
    """An axis-aligned box from corner ``lo`` to corner ``hi`` (3,), m."""
    box = trimesh.creation.box(np.subtract(hi, lo))
    box.apply_translation(np.add(lo, hi) / 2)
    return box


def test_pad_edge_excess_is_how_far_the_object_reaches_past_a_pad_beside_the_finger() -> None:
    geo = _geometry()
    frame = np.eye(4)[None]
    half = geo.finger_width_m / 2
    body = _slab((-0.05, -0.02, -0.06), (0.05, 0.02, 0.0))  # faces at y = +-0.02 across the pads
    pts = trimesh.sample.sample_surface_even(body, 8000, seed=1)[0]

    def excess(*parts) -> float:
        extra = [trimesh.sample.sample_surface_even(p, 2000, seed=2)[0] for p in parts]
        return float(pad_edge_excess_m(np.vstack([pts, *extra]), frame, geo, 0.002)[0])

    assert excess() == pytest.approx(0.0, abs=1e-9)  # a flat face running on past the pad
    beside = _slab((half + 0.0005, 0.02, -0.06), (half + 0.0035, 0.023, 0.0))  # a 3 mm rib beside the pad
    assert excess(beside) == pytest.approx(0.003, abs=1e-6)
    away = _slab((half + 0.005, 0.02, -0.06), (half + 0.008, 0.023, 0.0))  # 5 mm away: outside the band
    assert excess(away) == pytest.approx(0.0, abs=1e-9)
    ledge = _slab((-0.05, 0.02, geo.tip_z_m + 0.0005), (0.05, 0.024, geo.tip_z_m + 0.0015))  # past the tips
    assert excess(ledge) == pytest.approx(0.004, abs=1e-6)
    assert pad_edge_excess_m(pts + [1.0, 0.0, 0.0], frame, geo, 0.002)[0] == -np.inf  # nothing in reach


def test_choose_by_edge_clearance_takes_the_grasp_whose_pads_not_edges_meet_the_object() -> None:
    """A cone in random poses: among the same shortlist, ``cost`` takes grasps with the cone's surface
    rising past a pad beside its finger; ``edge_clearance`` takes one clear of it where one exists."""
    cone = trimesh.creation.cone(radius=0.04, height=0.1, sections=48)
    rng = np.random.default_rng(0)
    by_cost, by_edges = [], []
    for _ in range(5):
        turned = cone.copy()
        turned.apply_transform(make_pose(random_rotation(rng), np.zeros(3)))
        pts, normals = resting_cloud(turned, n=3000)
        by_cost.append(plan(_request(pts, normals, choose_by="cost")).grasp.extras["edge_excess_m"])
        by_edges.append(plan(_request(pts, normals)).grasp.extras["edge_excess_m"])
    assert all(e <= max(c, 0.0) + 1e-12 for c, e in zip(by_cost, by_edges, strict=True))
    assert sum(c > 0.0005 for c in by_cost) >= 3  # the cheapest path often has a pad edge on the cone
    assert sum(e <= 0.0 for e in by_edges) >= 4


def test_opening_cluster_is_at_least_the_papers_opening() -> None:
    pts, normals = resting_cloud(trimesh.creation.cylinder(radius=0.02, height=0.1), n=2000)
    section = plan(_request(pts, normals)).grasp
    cluster = plan(_request(pts, normals, opening="cluster")).grasp
    assert section.width_m == pytest.approx(0.04 + 2 * 0.005, abs=0.004)
    assert cluster.width_m > section.width_m


def test_noise_check_prefers_grasps_that_survive_the_pose_error() -> None:
    pts, normals = resting_cloud(trimesh.creation.box((0.05, 0.08, 0.1)), n=2000)
    off = plan(_request(pts, normals, noise_samples=0)).grasp
    assert off.extras["noise_pass"] == 1.0
    tight = plan(_request(pts, normals, width_clearance_m=0.0025, noise_trans_mm=4.0, noise_samples=16)).grasp
    loose = plan(_request(pts, normals, noise_trans_mm=4.0, noise_samples=16)).grasp
    assert tight.extras["noise_pass"] < loose.extras["noise_pass"]  # 2.5 mm of clearance absorbs less of 4 mm


@pytest.mark.parametrize("key", ["depth_offsets_m", "rolls_deg"])
def test_empty_lists_are_one_clear_error(key: str) -> None:
    pts, normals = resting_cloud(trimesh.creation.box((0.05, 0.05, 0.05)), n=500)
    with pytest.raises(ValueError, match=f"planner.{key} is empty: give at least one value"):
        plan(_request(pts, normals, **{key: []}))


def test_area_fallback_takes_the_grasp_touching_the_area_most() -> None:
    """A band of the box narrower than a pad is its area: no pad lies wholly in it, so only the fallback
    plans, and it requires the best share any try reached."""
    box = trimesh.creation.box((0.09, 0.06, 0.04))
    pts, normals = resting_cloud(box, n=3000)
    area = np.abs(pts[:, 0]) < 0.004
    with pytest.raises(NoFeasibleGrasp, match="in the grasping area") as strict:
        plan(_request(pts, normals, area, fallback_contacts_in_area=1.0))
    best = float(str(strict.value).split("best passing try: ")[1].split(";")[0])
    assert 0.0 < best < 1.0
    g = plan(_request(pts, normals, area, fallback_contacts_in_area=0.0)).grasp
    assert g.extras["in_area_required"] == pytest.approx(best, abs=0.005)
    assert abs(g.position[0]) < 0.01  # the pads straddle the band
    with pytest.raises(NoFeasibleGrasp, match="fallback_contacts_in_area 0.9"):
        plan(_request(pts, normals, area, fallback_contacts_in_area=0.9))  # above the best share
    with pytest.raises(NoFeasibleGrasp, match=r"in the modes \['bin'\], this is collab"):
        plan(_request(pts, normals, area, mode="collab"))  # a person holds the rest: no fallback
    whole = plan(_request(pts, normals, fallback_contacts_in_area=0.0)).grasp  # the whole box is area
    assert whole.extras["in_area_required"] == 1.0
