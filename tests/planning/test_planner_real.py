"""The planner on every real mesh of the shared data root (skipped without it), plus its CLIs."""

import json

import numpy as np
import pytest
from helpers.cli import graspexp
from helpers.planning import IN_AREA, PAPER_STEPS_ONLY, RG2, UPRIGHT_SUPPORT_Z, upright_request

from graspexp.config import DatasetConfig, OptimalConfig
from graspexp.config.compose import compose_config
from graspexp.datasets import dataset_objects, load_object
from graspexp.datasets.catalog import candidate_paths, dataset_spec
from graspexp.planning import NoFeasibleGrasp, plan
from graspexp.planning.collision import cloud_hits, lowest_z
from graspexp.run.upright import upright_pose
from graspexp.tools.plan import main as plan_main


def _present(root, dataset):
    cfg = DatasetConfig(name=dataset, root=str(root), regions=f"{dataset}.yaml")
    return cfg, [
        n for n in dataset_spec(dataset).catalogue if any(p.is_file() for p in candidate_paths(cfg, n))
    ]


@pytest.mark.parametrize("dataset", ["ycb", "linemod"])
def test_plan_every_real_object_in_both_modes(data_root, dataset):
    """The paper's steps alone plan every object upright in both modes; with the swept check and the
    area rule (optimal_in_area's keys) a grasp, where there is one, keeps the gripper clear and its pads in the
    area, and the rest fail with the check that rejected them named."""
    cfg, names = _present(data_root, dataset)
    if not names:
        pytest.skip(f"no {dataset} mesh under {data_root}")
    support_z = UPRIGHT_SUPPORT_Z
    planned = 0
    for name in names:
        model = load_object(cfg, name, 2048, 0)
        pose = upright_pose(model, support_z)
        pts = model.points + pose[:3, 3]
        assert pts[:, 2].min() >= support_z - 1e-9
        for mode in ("collab", "bin"):
            for checked in (False, True):
                keys = IN_AREA if checked else PAPER_STEPS_ONLY
                req = upright_request(model, pose, mode, OptimalConfig(name="optimal", **keys))
                try:
                    res = plan(req)
                except NoFeasibleGrasp as e:
                    assert checked and ("planner.swept_check" in str(e) or "grasping area" in str(e)), (
                        name,
                        e,
                    )
                    continue
                planned += checked
                g, det = res.grasp, res.details
                R = g.pose[:3, :3]
                np.testing.assert_allclose(R.T @ R, np.eye(3), atol=1e-9, err_msg=f"{name} {mode}")
                assert np.linalg.det(R) == pytest.approx(1.0, abs=1e-9)
                assert np.isfinite(g.cost) and g.n_feasible > 0, (name, mode)
                start = g.position - 0.1 * g.approach
                assert start[2] >= support_z, (name, mode)
                assert RG2.min_width_m <= g.width_m <= RG2.max_width_m
                assert det.area_mask.sum() > 0
                # The grasp point is the centre of a cluster of area points, so it is near the area.
                area = pts[model.area_mask]
                assert np.min(np.linalg.norm(area - g.position, axis=1)) < 0.06, (name, mode)
                if checked:
                    assert cloud_hits(pts, g.pose[None], RG2, g.width_m, sweep_m=0.1, margin_m=0.0)[0] == 0
                    assert lowest_z(g.pose[None], RG2, g.width_m, 0.1)[0] >= support_z, (name, mode)
                    assert det.contact_share[g.cluster, g.path] == 1.0, (name, mode)
    assert planned > 0


def test_plan_cli_prints_one_json_object_and_dumps(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    dump = tmp_path / "mug.npz"
    assert plan_main(["dataset=primitives", "objects=[mug]", "mode=bin", "--dump", str(dump)]) == 0
    out = capsys.readouterr().out.strip().splitlines()
    assert len(out) == 1
    rec = json.loads(out[0])
    assert {"pose", "width", "cost", "cluster", "path", "object", "n_feasible", "plan_ms"} <= set(rec)
    assert rec["object"] == "mug" and rec["mode"] == "bin"
    pose = np.array(rec["pose"])
    assert pose.shape == (4, 4) and np.linalg.det(pose[:3, :3]) == pytest.approx(1.0)
    with np.load(dump) as d:
        for key in ("cloud", "area_mask", "centers", "radii", "main_axis", "directions", "feasible", "costs"):
            assert key in d.files
        assert d["costs"].shape == d["feasible"].shape == d["directions"].shape[:2]
        np.testing.assert_allclose(d["pose"], pose)
        assert str(d["mode"]) == "bin"
        # The object rests on the support z = mode.support_height_m (0.10 m): its mesh's lowest point
        # is on the plane, so the sampled cloud starts at or just above it.
        assert float(d["table_z"]) == pytest.approx(0.10)
        assert 0.10 - 1e-9 <= d["cloud"][:, 2].min() < 0.105
        np.testing.assert_array_equal(d["object_pose"][:3, :3], np.eye(3))
    assert not list(tmp_path.glob("outputs"))  # compose API: no Hydra run folder


@pytest.mark.slow
def test_plan_cli_unknown_object_is_one_line_and_non_zero():
    proc = graspexp("plan", "dataset=primitives", "objects=[teapot]", timeout=120)
    assert proc.returncode == 2
    assert proc.stdout == ""
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("graspexp plan: error: ") and "teapot" in lines[0]


@pytest.mark.parametrize("planner", ["optimal", "optimal_plus"])
def test_figures_cli_writes_the_pngs(tmp_path, planner):
    from graspexp.tools.figures import main as figures_main

    args = ["dataset=primitives", f"planner={planner}", "objects=[mug]", "--out", str(tmp_path)]
    assert figures_main(args) == 0
    names = sorted(p.name for p in tmp_path.glob("*.png"))
    assert names == [
        "fig03_cloud.png",
        "fig04_area.png",
        "fig05_clusters.png",
        "fig06_paths.png",
        "fig07_main_axis.png",
        "fig08_removed_paths.png",
        "fig09_grasp_pose.png",
    ]
    assert all((tmp_path / n).stat().st_size > 10_000 for n in names)


def test_plan_latency_bench_prints_a_row_per_object_and_mode(capsys):
    from graspexp.run.suites import PAPER_MODES as MODES
    from graspexp.tools.bench.plan_latency import main

    assert main(["--repeats", "2", "--runs", "2", "dataset=primitives", "planner.m=64"]) == 0
    out = capsys.readouterr().out.splitlines()
    objects = dataset_objects(compose_config(["dataset=primitives"]).dataset)
    rows = [ln.split() for ln in out if ln.split() and ln.split()[0] in objects]
    assert [(r[0], r[1]) for r in rows] == [(o, m) for o in objects for m in MODES]
    for r in rows:  # wall p50, p95, CPU p50, p95, vs paper, K-means, Eq.1-3, ns/el
        wall50, wall95, cpu50, cpu95, *rest = map(float, r[4:])
        assert 0 < wall50 <= wall95 and 0 < cpu50 <= cpu95 and all(v > 0 for v in rest), r
    assert "first plan of this process:" in out[1] and "ns/element" in out[1]
    assert out[-1].startswith("median p50 over objects and modes: CPU") and f"of {len(rows)} over" in out[-1]


def test_plan_latency_bench_prints_a_table_per_planner_with_its_cpu_target(capsys):
    from graspexp.tools.bench.plan_latency import main

    argv = ["--repeats", "1", "--runs", "2", "dataset=primitives", "objects=[can]", "mode=collab"]
    assert main([*argv, "planner=optimal,optimal_plus"]) == 0
    out = capsys.readouterr().out
    assert (
        "\noptimal, primitives, N=2048 M=256:\n" in out
        and "\noptimal_plus, primitives, N=4096 M=256:\n" in out
    )
    assert [ln.split()[:2] for ln in out.splitlines() if ln.startswith("can ")] == [["can", "collab"]] * 2
    assert "of 1 over the CPU target (p50 <= 2.5 ms and p95 <= 5 ms)" in out
    assert "of 1 over the CPU target (p95 <= 50 ms)" in out
