"""The compiled planner kernels against float64 numpy twins, down to the chosen grasp on every real object."""

import functools
import os
import re
import subprocess
import sys

import numpy as np
import pytest
from helpers.planning import RG2, UPRIGHT_SUPPORT_Z, upright_request

import graspexp.planning.optimal as optimal
from graspexp.config import CostConfig, DatasetConfig, OptimalConfig
from graspexp.datasets import available_objects, load_object
from graspexp.grippers import GripperGeometry
from graspexp.planning import NoFeasibleGrasp, PlanRequest, plan
from graspexp.planning.clusters import KMEANS_MAX_ITER, KMEANS_TOL, Clusters, max_radii_m, segment
from graspexp.planning.collision import cloud_hits
from graspexp.planning.cost import all_path_costs, distance_term
from graspexp.planning.kernels import _extremes
from graspexp.planning.pose import grasp_rotations, slab_spans_m
from graspexp.planning.stability import pad_contacts
from graspexp.run.upright import upright_pose

COST = CostConfig()


# --- float64 numpy twins of the compiled kernels (the planner's numpy code before it was compiled) ---


def segment_reference(area_points_m: np.ndarray, k: int, *, random_state: int) -> Clusters:
    """:func:`segment` in numpy: same seeding draws, Lloyd rule and outputs."""
    pts = np.asarray(area_points_m, dtype=np.float64)
    n = len(pts)
    rng = np.random.default_rng(random_state)
    chosen = [int(rng.integers(n))]

    def sq_distances(idx):  # (len(idx), n)
        return ((pts[None, :, :] - pts[idx][:, None, :]) ** 2).sum(axis=2)

    closest = sq_distances(np.array(chosen))[0]
    for _ in range(1, k):
        draws = rng.random(2 + int(np.log(k))) * closest.sum()
        cand = np.minimum(np.searchsorted(np.cumsum(closest), draws), n - 1)
        dist = np.minimum(sq_distances(cand), closest)
        best = int(np.argmin(dist.sum(axis=1)))
        closest = dist[best]
        chosen.append(int(cand[best]))
    centers = pts[chosen].copy()
    tol = KMEANS_TOL * float(np.var(pts, axis=0).mean())

    def assign(centers):
        labels = ((pts[:, None, :] - centers[None]) ** 2).sum(axis=2).argmin(axis=1)
        counts = np.bincount(labels, minlength=k).astype(np.float64)
        sums = np.stack([np.bincount(labels, pts[:, a], minlength=k) for a in range(3)], axis=1)
        return labels, counts, sums

    for _ in range(KMEANS_MAX_ITER):
        _, counts, sums = assign(centers)
        new = np.where(counts[:, None] > 0, sums / np.maximum(counts, 1.0)[:, None], centers)
        step = float(((new - centers) ** 2).sum())
        centers = new
        if step <= tol:
            break
    labels, counts, _ = assign(centers)
    used, labels = np.unique(labels, return_inverse=True)
    centers = np.stack([pts[labels == j].mean(axis=0) for j in range(len(used))])
    radii = np.sqrt([((pts[labels == j] - centers[j]) ** 2).sum(axis=1).mean() for j in range(len(used))])
    return Clusters(centers_m=centers, radii_m=radii, labels=labels)


def slab_spans_reference(points_m, centers_m, rotations, gripper):
    """:func:`slab_spans_m` in numpy: every point in every grasp frame."""
    rots = np.asarray(rotations, dtype=np.float64)
    centers = np.broadcast_to(np.asarray(centers_m, dtype=np.float64), (len(rots), 3))
    local = np.einsum("bji,bnj->bni", rots, np.asarray(points_m)[None] - centers[:, None])
    geometry = GripperGeometry.of(gripper)
    z_lo, z_hi = geometry.root_z_m, geometry.tip_z_m
    x, y, z = local[..., 0], local[..., 1], local[..., 2]
    inside = (np.abs(x) <= gripper.finger_width_m / 2) & (z >= z_lo) & (z <= z_hi)
    hi = np.where(inside, y, -np.inf).max(axis=1)
    lo = np.where(inside, y, np.inf).min(axis=1)
    any_in = inside.any(axis=1)
    return np.stack([np.where(any_in, lo, 0.0), np.where(any_in, hi, 0.0)], axis=1)


def reference_plan(req: PlanRequest, monkeypatch: pytest.MonkeyPatch):
    """The same plan with every compiled step replaced by its float64 numpy twin."""
    with monkeypatch.context() as patch:
        patch.setattr(optimal, "segment", segment_reference)
        patch.setattr(optimal, "all_path_costs", functools.partial(all_path_costs, dtype=np.float64))
        patch.setattr(optimal, "slab_spans_m", slab_spans_reference)
        return plan(req)


# --- unit checks ---


def test_distance_kernel_matches_the_float64_reference_on_a_large_cloud():
    rng = np.random.default_rng(3)
    pts_mm = rng.normal(size=(2048, 3)) * 50.0
    dirs = rng.normal(size=(256, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    fast = distance_term(pts_mm, dirs, 40.0, COST)
    ref = distance_term(pts_mm, dirs, 40.0, COST, dtype=np.float64)
    np.testing.assert_allclose(fast, ref, rtol=2e-6)
    np.testing.assert_array_equal(fast, distance_term(pts_mm, dirs, 40.0, COST))  # deterministic


def test_distance_kernel_rejects_inputs_fastmath_cannot_handle():
    pts, dirs = np.ones((4, 3)), np.eye(3)
    with pytest.raises(ValueError, match="cost.distance_offset_mm2=0.0 is invalid"):
        distance_term(pts, dirs, 1.0, CostConfig(distance_offset_mm2=0.0))
    with pytest.raises(ValueError, match="non-finite"):
        distance_term(np.vstack([pts, [np.nan, 0.0, 0.0]]), dirs, 1.0, COST)
    with pytest.raises(ValueError, match="non-finite"):
        distance_term(pts, dirs, 1.0, CostConfig(distance_cap=np.inf))
    with pytest.raises(ValueError, match="dtype="):
        distance_term(pts, dirs, 1.0, COST, dtype=np.float16)


def test_slab_kernel_matches_the_numpy_twin_on_random_frames():
    rng = np.random.default_rng(4)
    pts = rng.normal(size=(3000, 3)) * 0.04
    approaches = rng.normal(size=(40, 3))
    rots = grasp_rotations(approaches, np.array([0.0, 0.0, 1.0]))
    centers = rng.normal(size=(40, 3)) * 0.01
    got = slab_spans_m(pts, centers, rots, RG2)
    np.testing.assert_allclose(got, slab_spans_reference(pts, centers, rots, RG2), atol=1e-15)
    assert (got[:, 1] > got[:, 0]).all()  # every frame holds points


def test_extremes_in_four_chains_are_one_chain_s_signed_zeros_included():
    """The section's and the pads' extremes (:func:`graspexp.planning.kernels._extremes`): the values of a
    scan in point order for every length (the chains' tails), a zero with the sign of the first in order."""
    rng = np.random.default_rng(6)
    for k in range(12):
        y = rng.normal(size=k)
        inside = rng.random(k) < 0.6
        y_lo, y_hi = np.where(inside, y, 1e30), np.where(inside, y, -1e30)
        lo, hi = _extremes(y_lo, y_hi, k, 1e30)
        assert (lo, hi) == (min([1e30, *y_lo]), max([-1e30, *y_hi]))
    lo, hi = _extremes(np.array([0.0, -0.0, 1.0]), np.array([-0.0, 0.0, -1.0]), 3, np.inf)
    assert (lo, hi) == (0.0, 0.0) and not np.signbit(lo) and np.signbit(hi)


def _runs_of_tries(rng: np.random.Generator, n_paths: int) -> np.ndarray:
    """(n_paths * 7, 4, 4) frames as optimal_plus tries them: per path one rotation, 7 depths along its Z,
    each moved along its Y (centring) by its own amount."""
    rots = grasp_rotations(rng.normal(size=(n_paths, 3)), np.array([0.0, 0.0, 1.0]))
    poses = np.tile(np.eye(4), (n_paths, 7, 1, 1))
    poses[:, :, :3, :3] = rots[:, None]
    depth = np.linspace(-0.02, 0.04, 7)[None, :, None] * rots[:, None, :, 2]
    side = rng.normal(size=(n_paths, 7, 1)) * 0.01 * rots[:, None, :, 1]
    poses[:, :, :3, 3] = rng.normal(size=(n_paths, 1, 3)) * 0.02 + depth + side
    return poses.reshape(-1, 4, 4)


def test_runs_of_one_rotation_give_each_frame_s_own_results_bit_for_bit():
    """The kernels cull the cloud once per run of frames with one rotation (kernels module doc): batched
    runs give, bit for bit, what each frame gives alone, and the swept-box counts equal a numpy count."""
    rng = np.random.default_rng(5)
    normals = rng.normal(size=(3000, 3))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    pts = normals * [0.04, 0.03, 0.05]  # an ellipsoid's surface (its normals only roughly: enough here)
    area = rng.random(3000) < 0.8
    poses = _runs_of_tries(rng, 30)
    widths = rng.uniform(0.0, 0.11, len(poses))
    geometry = GripperGeometry.of(RG2)
    rots, centers = poses[:, :3, :3], poses[:, :3, 3]
    one = [slab_spans_m(pts, centers[i : i + 1], rots[i : i + 1], RG2, 0.002) for i in range(len(poses))]
    np.testing.assert_array_equal(slab_spans_m(pts, centers, rots, RG2, 0.002), np.concatenate(one))
    pads = np.stack(pad_contacts(pts, normals, poses, geometry, 0.004, area), axis=1)
    alone = [
        np.stack(pad_contacts(pts, normals, poses[i : i + 1], geometry, 0.004, area), axis=1)
        for i in range(len(poses))
    ]
    np.testing.assert_array_equal(pads, np.concatenate(alone))
    assert np.isfinite(pads[:, 0]).sum() > len(poses) // 2  # most frames have both pads' contacts
    counts = cloud_hits(pts, poses, RG2, widths, sweep_m=0.1, margin_m=0.002)
    local = np.einsum("bji,bnj->bni", rots, pts[None] - centers[:, None])
    x, y, z = np.abs(local[..., 0]), np.abs(local[..., 1]), local[..., 2]
    fw, t, m = geometry.finger_width_m / 2 + 0.002, geometry.finger_thickness_m, 0.002
    px, py, pz = geometry.palm_size_m
    h = widths[:, None] / 2
    root, tip = geometry.root_z_m, geometry.tip_z_m
    finger = (x <= fw) & (z >= root - 0.1 - m) & (z <= tip + m) & (y >= h - m) & (y <= h + t + m)
    palm = (x <= px / 2 + m) & (y <= py / 2 + m) & (z >= root - pz - 0.1 - m) & (z <= root + m)
    np.testing.assert_array_equal(counts, (finger | palm).sum(axis=1))
    assert 0 < (counts == 0).sum() < len(poses)  # free and colliding frames both
    free = cloud_hits(pts, poses, RG2, widths, sweep_m=0.1, margin_m=0.002, stop_at=1)
    np.testing.assert_array_equal(free, np.minimum(counts, 1))


def test_kmeans_kernel_matches_the_numpy_twin_on_blobs():
    rng = np.random.default_rng(5)
    blobs = np.concatenate([rng.normal(size=(300, 3)) * 0.01 + [0.0, z, 0.0] for z in (0.0, 0.05, 0.1, 0.3)])
    for k in (1, 2, 4, 7):
        got, ref = segment(blobs, k, random_state=11), segment_reference(blobs, k, random_state=11)
        np.testing.assert_array_equal(got.labels, ref.labels)
        np.testing.assert_allclose(got.centers_m, ref.centers_m, atol=1e-14)
        np.testing.assert_allclose(got.radii_m, ref.radii_m, rtol=1e-9)
        far = np.zeros(len(ref.centers_m))  # max_radii_m in numpy
        np.maximum.at(far, ref.labels, ((blobs - ref.centers_m[ref.labels]) ** 2).sum(axis=1))
        np.testing.assert_array_equal(max_radii_m(blobs, ref), np.sqrt(far))


@pytest.mark.slow
def test_kernel_cache_is_per_user_private_and_survives_an_unusable_one(tmp_path):
    """A subprocess per case: numba's cache folder is fixed when the kernels module is imported. The
    kernels are cached under XDG_CACHE_HOME (mode 0700), never under the shared GRASPEXP_CACHE; a folder
    others can write, or one that cannot be made, is not used (compiled in the process instead)."""
    script = (
        "import numba, numpy as np\n"
        "from graspexp.config import CostConfig\n"
        "from graspexp.planning import kernels\n"
        "from graspexp.planning.cost import distance_term\n"
        "print(kernels._CACHE, numba.config.CACHE_DIR)\n"
        "print(distance_term(np.ones((5, 3)), np.eye(3), 1.0, CostConfig()).sum())\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "NUMBA_CACHE_DIR"}
    blocker = tmp_path / "a_file"
    blocker.write_text("")
    shared = tmp_path / "shared"
    (shared / "graspexp" / "numba").mkdir(parents=True)
    (shared / "graspexp" / "numba").chmod(0o777)
    for xdg, usable in ((tmp_path / "home", True), (blocker, False), (shared, False)):
        proc = subprocess.run(
            [sys.executable, "-c", script],
            env={**env, "XDG_CACHE_HOME": str(xdg), "GRASPEXP_CACHE": str(tmp_path / "graspexp-cache")},
            capture_output=True,
            text=True,
            timeout=300,
        )
        assert proc.returncode == 0, proc.stderr
        flag, folder, total = proc.stdout.split()
        assert (flag, folder) == (str(usable), str(xdg / "graspexp" / "numba"))
        assert float(total) == 15.0  # 3 paths x 5 points, each term capped at 1 (Y = sqrt(2), r = 1)
        assert bool(list((xdg / "graspexp" / "numba").rglob("*.nbi"))) is usable
        assert not (tmp_path / "graspexp-cache" / "numba").exists()
    assert (tmp_path / "home" / "graspexp" / "numba").stat().st_mode & 0o777 == 0o700


def test_a_numba_cache_dir_others_can_write_is_not_used(tmp_path):
    """NUMBA_CACHE_DIR set by the user is used only if it is private too: numba's index files are pickles,
    and a world-writable folder would let anyone run code in the next process (issue 39)."""
    shared = tmp_path / "numba"
    shared.mkdir()
    shared.chmod(0o777)
    script = "from graspexp.planning import kernels\nprint(kernels._CACHE)\n"
    env = {**os.environ, "NUMBA_CACHE_DIR": str(shared)}
    proc = subprocess.run(
        [sys.executable, "-c", script], env=env, capture_output=True, text=True, timeout=120
    )
    assert proc.returncode == 0 and proc.stdout.split() == ["False"], proc.stderr
    assert "NUMBA_CACHE_DIR) is not private to this user" in proc.stderr
    assert "set NUMBA_CACHE_DIR" not in proc.stderr  # the advice is never "set it" to anything


# --- the whole plan on the real meshes ---


def _objects(dataset: str, root) -> tuple[DatasetConfig, list[str]]:
    """The dataset's default objects (paper Table 1 / Table 2) whose meshes are present under ``root``."""
    cfg = DatasetConfig(name=dataset, root=str(root), regions=f"{dataset}.yaml")
    return cfg, available_objects(cfg)


@pytest.mark.parametrize("dataset", ["ycb", "linemod"])
def test_compiled_plan_matches_the_numpy_reference_on_every_real_object(data_root, dataset, monkeypatch):
    cfg, names = _objects(dataset, data_root)
    if not names:
        pytest.skip(f"no {dataset} mesh under {data_root}")
    compared = 0
    for name in names:
        model = load_object(cfg, name, 2048, 0)
        pose = upright_pose(model, UPRIGHT_SUPPORT_Z)
        for mode in ("collab", "bin"):
            req = upright_request(model, pose, mode, OptimalConfig(name="optimal"))
            what = f"{dataset} {name} {mode}"
            try:
                got = plan(req)
            except NoFeasibleGrasp as e:  # the swept check or the area rule found no path: so must the twin
                with pytest.raises(NoFeasibleGrasp, match=re.escape(str(e))):
                    reference_plan(req, monkeypatch)
                continue
            ref = reference_plan(req, monkeypatch)
            compared += 1
            np.testing.assert_array_equal(got.details.labels, ref.details.labels, err_msg=what)
            assert (got.grasp.cluster, got.grasp.path) == (ref.grasp.cluster, ref.grasp.path), what
            assert got.grasp.n_feasible == ref.grasp.n_feasible, what
            assert got.grasp.width_m == pytest.approx(ref.grasp.width_m, rel=1e-9), what
            np.testing.assert_allclose(got.grasp.pose, ref.grasp.pose, atol=1e-9, err_msg=what)
            np.testing.assert_array_equal(
                np.isfinite(got.details.costs), np.isfinite(ref.details.costs), err_msg=what
            )
            finite = np.isfinite(ref.details.costs)
            np.testing.assert_allclose(
                got.details.costs[finite], ref.details.costs[finite], rtol=1e-5, err_msg=what
            )
    assert compared >= len(names), f"only {compared} of {2 * len(names)} plans found a grasp to compare"
