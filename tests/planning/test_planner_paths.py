"""Fibonacci sphere, path geometry and the support-plane test; main axis and the K rule."""

import math

import numpy as np
import pytest
from sklearn.neighbors import KDTree

from graspexp.planning.clusters import choose_k, main_axis, max_radii_m, segment
from graspexp.planning.paths import above_support, approach_directions, fibonacci_sphere, sphere_points


@pytest.mark.parametrize("m", [1, 2, 16, 256, 1000])
def test_fibonacci_points_are_unit(m):
    u = fibonacci_sphere(m)
    assert u.shape == (m, 3)
    np.testing.assert_allclose(np.linalg.norm(u, axis=1), 1.0, atol=1e-12)


@pytest.mark.parametrize("m", [64, 256, 1024])
def test_fibonacci_points_are_evenly_spread(m):
    u = fibonacci_sphere(m)
    assert np.linalg.norm(u.mean(axis=0)) < 2.0 / m
    nn, _ = KDTree(u).query(u, k=2)
    nn = nn[:, 1]
    assert nn.max() / nn.min() < 1.6
    # An ideal packing gives about sqrt(4 pi / m) between neighbours.
    assert nn.mean() == pytest.approx(math.sqrt(4 * math.pi / m), rel=0.2)
    # Equal-area bands: each hemisphere holds half the points.
    assert abs((u[:, 2] > 0).sum() - m / 2) <= 1


def test_fibonacci_rejects_zero():
    with pytest.raises(ValueError, match="m=0"):
        fibonacci_sphere(0)


def test_paths_run_from_the_sphere_to_the_centre():
    centers = np.array([[0.0, 0.0, 0.1], [0.2, -0.1, 0.3]])
    d = approach_directions(centers, 32)
    assert d.shape == (2, 32, 3)
    np.testing.assert_array_equal(d[0], -fibonacci_sphere(32))
    np.testing.assert_array_equal(d[0], d[1])
    start = sphere_points(centers, d, 0.1)
    np.testing.assert_allclose(np.linalg.norm(start - centers[:, None], axis=2), 0.1, atol=1e-12)
    # Moving R along the approach direction from the start reaches the centre.
    np.testing.assert_allclose(start + 0.1 * d, np.broadcast_to(centers[:, None], start.shape), atol=1e-12)


def test_paths_through_the_table_are_removed():
    centers = np.array([[0.0, 0.0, 0.05], [0.0, 0.0, 0.5]])  # 5 cm and 50 cm above z = 0
    d = approach_directions(centers, 256)
    ok = above_support(centers, d, 0.1, 0.0, 0.0)
    start_z = sphere_points(centers, d, 0.1)[..., 2]
    np.testing.assert_array_equal(ok, start_z >= 0.0)
    assert ok[1].all()  # the sphere around the high centre never reaches the table
    assert not ok[0].all() and ok[0].any()
    # Sphere point below z = 0 exactly when u_z < -0.5 for the low centre.
    np.testing.assert_array_equal(ok[0], -d[0, :, 2] >= -0.5)
    # A clearance removes more.
    assert above_support(centers, d, 0.1, 0.0, 0.02).sum() < ok.sum()


def test_main_axis_is_the_long_direction_with_a_fixed_sign():
    rng = np.random.default_rng(0)
    pts = rng.normal(size=(500, 3)) * [0.01, 0.05, 0.002]
    a = main_axis(pts)
    assert abs(a[1]) > 0.99 and a[1] > 0
    assert np.array_equal(main_axis(pts), main_axis(-pts))  # sign is fixed, not inherited
    np.testing.assert_allclose(np.linalg.norm(a), 1.0, atol=1e-12)


def test_auto_k_rule():
    axis = np.array([0.0, 0.0, 1.0])
    line = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.12], [0.01, 0.0, 0.05]])  # L = 0.12 m along the axis
    assert choose_k("auto", 8, line, axis, 0.100, 0.5) == 3  # ceil(0.12 / 0.05)
    assert choose_k("auto", 8, line, axis, 0.100, 1.0) == 2  # ceil(0.12 / 0.1): clusters one stroke long
    assert choose_k("auto", 8, line, axis, 0.300, 0.5) == 1  # bigger gripper, fewer clusters
    assert choose_k("auto", 2, line, axis, 0.010, 0.5) == 2  # clamped to k_max
    assert choose_k("auto", 8, line[:2], axis, 0.010, 0.5) == 2  # never more than the area points
    assert choose_k(5, 8, line, axis, 0.1, 0.5) == 3  # explicit K, capped at n_area
    assert choose_k(2, 8, line, axis, 0.1, 0.5) == 2
    with pytest.raises(ValueError, match="planner.k=0"):
        choose_k(0, 8, line, axis, 0.1, 0.5)


def test_segment_radii_are_rms_distances_to_the_means():
    rng = np.random.default_rng(1)
    blobs = np.concatenate([rng.normal(size=(100, 3)) * 0.01 + [0.0, 0.0, z] for z in (0.0, 0.2, 0.4)])
    c = segment(blobs, 3, random_state=7)
    assert c.centers_m.shape == (3, 3) and c.radii_m.shape == (3,)
    for j in range(3):
        members = blobs[c.labels == j]
        np.testing.assert_allclose(c.centers_m[j], members.mean(axis=0), atol=1e-12)
        rms = np.sqrt(np.mean(np.sum((members - c.centers_m[j]) ** 2, axis=1)))
        assert c.radii_m[j] == pytest.approx(rms, rel=1e-12)
    assert sorted(np.round(c.centers_m[:, 2], 1)) == [0.0, 0.2, 0.4]
    far = max_radii_m(blobs, c)
    for j in range(3):
        members = blobs[c.labels == j]
        assert far[j] == pytest.approx(np.linalg.norm(members - c.centers_m[j], axis=1).max(), rel=1e-12)
        assert far[j] > c.radii_m[j]


def test_segment_with_too_few_distinct_points_drops_empty_clusters():
    pts = np.array([[0.0, 0.0, 0.0]] * 5 + [[0.0, 0.0, 0.1]] * 5)
    c = segment(pts, 3, random_state=0)
    assert len(c.centers_m) == 2
    assert np.isfinite(c.centers_m).all() and np.isfinite(c.radii_m).all()
