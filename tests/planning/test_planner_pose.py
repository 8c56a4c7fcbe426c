"""Grasp frame (Fig. 9), opening width and the wider-than-gripper slab."""

import dataclasses

import numpy as np
import pytest
from helpers.planning import RG2

from graspexp.planning.paths import fibonacci_sphere
from graspexp.planning.pose import (
    grasp_pose,
    grasp_rotation,
    grasp_rotations,
    opening_widths_m,
    slab_spans_m,
)


def _assert_frame(R, approach, axis):
    np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-12)
    assert np.linalg.det(R) == pytest.approx(1.0, abs=1e-12)
    np.testing.assert_allclose(R[:, 2], approach / np.linalg.norm(approach), atol=1e-12)
    assert abs(R[:, 0] @ R[:, 2]) < 1e-12
    np.testing.assert_allclose(R[:, 1], np.cross(R[:, 2], R[:, 0]), atol=1e-12)


def test_frame_axes_follow_fig9():
    axis = np.array([0.0, 0.0, 1.0])
    approach = np.array([-1.0, 0.0, 0.0])  # horizontal approach along -x onto a vertical axis
    R = grasp_rotation(approach, axis)
    _assert_frame(R, approach, axis)
    np.testing.assert_allclose(R[:, 0], axis, atol=1e-12)  # X = main axis when already orthogonal
    np.testing.assert_allclose(R[:, 1], [0.0, 1.0, 0.0], atol=1e-12)  # Y = Z x X = (-x) x z = +y


def test_frame_is_valid_for_every_sphere_direction_and_x_leans_to_the_axis():
    axis = np.array([0.3, -0.4, 0.866])
    axis /= np.linalg.norm(axis)
    dirs = -fibonacci_sphere(256)
    Rs = grasp_rotations(dirs, axis)
    for d, R in zip(dirs, Rs, strict=True):
        _assert_frame(R, d, axis)
        assert R[:, 0] @ axis >= -1e-12  # Gram-Schmidt keeps X on the main axis's side


def test_frame_falls_back_deterministically_when_axis_is_parallel_to_approach():
    axis = np.array([0.0, 0.0, 1.0])
    cases = [  # (approach, the world axis least aligned with it; ties go to the lower index)
        ([0.0, 0.0, -1.0], [1.0, 0.0, 0.0]),
        ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0]),
        ([1e-9, 0.0, -1.0], [0.0, 1.0, 0.0]),
    ]
    for approach, seed in cases:
        approach = np.array(approach)
        R = grasp_rotation(approach, axis)
        _assert_frame(R, approach, axis)
        np.testing.assert_allclose(R[:, 0], seed, atol=1e-8)
        np.testing.assert_array_equal(R, grasp_rotation(approach, axis))


def test_pose_origin_is_the_centre():
    c = np.array([0.1, 0.2, 0.3])
    T = grasp_pose(c, np.array([0.0, 1.0, -1.0]), np.array([1.0, 0.0, 0.0]))
    np.testing.assert_array_equal(T[:3, 3], c)
    np.testing.assert_array_equal(T[3], [0.0, 0.0, 0.0, 1.0])


def test_width_is_twice_the_radius_with_margin_clipped_to_the_stroke():
    assert opening_widths_m(np.array([0.02]), 0.2, RG2)[0] == pytest.approx(0.048)
    assert opening_widths_m(np.array([0.2]), 0.2, RG2)[0] == RG2.max_width_m
    tight = dataclasses.replace(RG2, min_width_m=0.01)
    assert opening_widths_m(np.array([0.001]), 0.2, tight)[0] == 0.01
    w = opening_widths_m(np.linspace(0.0, 0.3, 31), 0.2, tight)
    assert np.all((tight.min_width_m <= w) & (w <= tight.max_width_m))


def test_slab_span_is_the_section_between_the_pads():
    # A thin bar along world y from -40 mm to +100 mm through the grasp point, plus a far point.
    bar = np.stack([np.zeros(141), np.linspace(-0.04, 0.1, 141), np.zeros(141)], axis=1)
    pts = np.vstack([bar, [[0.0, 0.5, 0.2]]])  # z = 0.2 m: beyond the pads, ignored
    close_on_bar = grasp_rotation(np.array([0.0, 0.0, -1.0]), np.array([1.0, 0.0, 0.0]))  # Y = -world y
    along_bar = grasp_rotation(np.array([0.0, 0.0, -1.0]), np.array([0.0, 1.0, 0.0]))  # X = world y
    np.testing.assert_allclose(close_on_bar[:, 1], [0.0, -1.0, 0.0], atol=1e-12)
    spans = slab_spans_m(pts, np.zeros(3), np.stack([close_on_bar, along_bar]), RG2)
    np.testing.assert_allclose(spans[0], [-0.1, 0.04], atol=1e-12)  # in grasp-frame y = -world y
    np.testing.assert_allclose(spans[1], [0.0, 0.0], atol=1e-12)  # only the bar's centre is in |x| <= 11 mm
    empty = slab_spans_m(pts + [1.0, 0.0, 0.0], np.zeros(3), close_on_bar[None], RG2)
    np.testing.assert_array_equal(empty[0], [0.0, 0.0])
