"""The cubed neighbour cloud of a clutter round (:mod:`graspexp.planning.cells`) and the compiled neighbour
tests built on it give exactly the booleans of a scan of every point."""

import numpy as np
import pytest
from helpers.planning import plain_cfg

import graspexp.planning.paths as paths
from graspexp.grippers import GripperGeometry
from graspexp.planning.cells import cell_cloud
from graspexp.planning.collision import cloud_hits, neighbour_hits
from graspexp.planning.paths import approach_directions, clear_of


def _scene(seed: int, n_points: int = 3000, n_poses: int = 400):
    """Random blobs of points and random grasp frames among them, world m."""
    rng = np.random.default_rng(seed)
    blobs = rng.uniform(-0.12, 0.12, (6, 3))
    points = blobs[rng.integers(0, 6, n_points)] + rng.normal(0.0, 0.03, (n_points, 3))
    q, _ = np.linalg.qr(rng.normal(size=(n_poses, 3, 3)))
    q *= np.sign(np.linalg.det(q))[:, None, None]
    poses = np.tile(np.eye(4), (n_poses, 1, 1))
    poses[:, :3, :3], poses[:, :3, 3] = q, rng.uniform(-0.15, 0.15, (n_poses, 3))
    return points, poses, rng.uniform(0.0, 0.11, n_poses)


def _between_pads(points, poses, gripper, widths, sweep_m, margin_m):
    """Reference: a point between the pads of each grasp, every point scanned (the kernel's expressions)."""
    g = GripperGeometry.of(gripper)
    out = np.zeros(len(poses), dtype=bool)
    for b, r in enumerate(poses):
        dx, dy, dz = (points[:, a] - r[a, 3] for a in range(3))
        z = r[0, 2] * dx + r[1, 2] * dy + r[2, 2] * dz
        x = np.abs(r[0, 0] * dx + r[1, 0] * dy + r[2, 0] * dz)
        y = np.abs(r[0, 1] * dx + r[1, 1] * dy + r[2, 1] * dz)
        lo, hi = g.root_z_m - sweep_m - margin_m, g.tip_z_m + margin_m
        out[b] = ((x <= g.finger_width_m / 2 + margin_m) & (y < widths[b] / 2) & (lo <= z) & (z <= hi)).any()
    return out


@pytest.mark.parametrize("gripper", ["rg2", "panda"])
@pytest.mark.parametrize("margin_m", [0.0, 0.004])
def test_neighbour_hits_equal_a_scan_of_every_point(gripper, margin_m):
    cfg = plain_cfg("optimal", "bin", f"gripper={gripper}")
    points, poses, widths = _scene(1)
    got = neighbour_hits(cell_cloud(points), poses, cfg.gripper, widths, sweep_m=0.1, margin_m=margin_m)
    boxes = cloud_hits(points, poses, cfg.gripper, widths, sweep_m=0.1, margin_m=margin_m, stop_at=1) > 0
    want = boxes | _between_pads(points, poses, cfg.gripper, widths, 0.1, margin_m)
    assert 0.1 < want.mean() < 0.9  # both answers are exercised
    np.testing.assert_array_equal(got, want)
    plain = neighbour_hits(points, poses, cfg.gripper, widths, sweep_m=0.1, margin_m=margin_m)
    np.testing.assert_array_equal(plain, want)  # an uncubed cloud is cubed on the way
    meet = neighbour_hits(
        cell_cloud(points), poses, cfg.gripper, widths, sweep_m=0.1, margin_m=margin_m, between_pads=False
    )
    assert 0.1 < boxes.mean() < 0.9
    np.testing.assert_array_equal(meet, boxes)  # the finger and palm volumes alone


def test_a_cube_holds_its_points_within_its_sphere():
    points = _scene(2)[0]
    cells = cell_cloud(points, 0.03)
    assert len(cells.points) == len(points) and cells.starts[-1] == len(points)
    np.testing.assert_array_equal(np.sort(cells.points, axis=0), np.sort(points, axis=0))
    for c in range(len(cells.radii)):
        inside = cells.points[cells.starts[c] : cells.starts[c + 1]]
        assert len(inside) > 0
        assert np.ptp(np.floor(inside / 0.03), axis=0).max() <= 1  # one cube of the grid (its origin differs)
        assert np.linalg.norm(inside - cells.centres[c], axis=1).max() < cells.radii[c]


@pytest.mark.parametrize("voxel_m", [0.005, 0.01, 0.02])
def test_clear_of_equals_the_sorted_keys_search(monkeypatch, voxel_m):
    points = _scene(3, n_points=2000)[0]
    rng = np.random.default_rng(4)
    centers = rng.uniform(-0.1, 0.1, (3, 3))
    directions = approach_directions(centers, 256)
    radii = rng.uniform(0.0, 0.04, 3)
    grid = clear_of(centers, radii, directions, 0.1, points, voxel_m)
    monkeypatch.setattr(paths, "MAX_GRID_CELLS", 0)  # the fallback: the obstacle's sorted cube keys
    keys = clear_of(centers, radii, directions, 0.1, points, voxel_m)
    assert 0.05 < grid.mean() < 0.95
    np.testing.assert_array_equal(grid, keys)
