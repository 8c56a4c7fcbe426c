"""The benchmark command's suite, arguments and ranking (no physics: the end-to-end run is in test_plugin)."""

import dataclasses
from pathlib import Path

import pandas as pd
import pytest

from graspexp.config import ConfigError
from graspexp.report.benchmark import ranking
from graspexp.report.paper import PAPER_TABLES, SETTINGS
from graspexp.run.benchmark import compared, jobs, sweep_command
from graspexp.run.suites import NOISE_LEVELS
from graspexp.tools.benchmark import parse_args


def test_standard_suite_is_four_settings_on_both_tables_at_every_noise_level_for_every_planner():
    bench = parse_args(["planner=obb", "planner.width_clearance_m=0.01", "gripper=panda"])
    assert bench.datasets == ["ycb", "linemod"] and bench.trials == 10
    others = compared(bench)
    assert "obb" not in others and {
        "optimal",
        "optimal_literal",
        "optimal_plus",
        "antipodal",
        "random",
    } <= set(others)
    todo = jobs(bench)
    assert len(todo) == (1 + len(others)) * 2 * len(SETTINGS) * (1 + len(NOISE_LEVELS))
    assert len({j.run_dir for j in todo}) == len(todo)
    for j in todo:  # planner keys go to the entered planner only, the rest to every planner
        assert ("planner.width_clearance_m=0.01" in j.overrides) == (j.planner == "obb")
        assert "gripper=panda" in j.overrides and "trials=10" in j.overrides


def test_bad_arguments_are_one_clear_error():
    with pytest.raises(ConfigError, match="planner is missing"):
        parse_args(["dataset=ycb"])
    with pytest.raises(SystemExit):  # argparse: usage and "invalid choice: 'pbs'"
        parse_args(["planner=obb", "--launcher", "pbs"])


def test_options_and_suite_keys_are_read_and_the_rest_goes_to_the_jobs():
    bench = parse_args(
        [
            "mode=collab",
            "rot=z",
            "--noise",
            "5:0,0:5",
            "--compare",
            "obb",
            "--n-jobs",
            "1",
            "planner=random",
        ]
        + ["dataset=ycb,primitives", "trials=3", "objects=[can,box]", "sim.close_s=0.5"]
    )
    assert (bench.planner, bench.datasets, bench.trials, bench.objects) == (
        "random",
        ["ycb", "primitives"],
        3,
        ["can", "box"],
    )
    assert bench.settings == ["collab/z"] and bench.noise == [[5.0, 0.0], [0.0, 5.0]]
    assert bench.compare == ["obb"] and bench.n_jobs == 1 and bench.overrides == ["sim.close_s=0.5"]
    assert parse_args(["planner=obb", "--noise", ""]).noise == []
    # settings: every combination of the given modes and rotations, in the paper's order
    assert parse_args(["planner=obb", "rot=xyz"]).settings == ["collab/xyz", "bin/xyz"]
    assert parse_args(["planner=obb", "mode=bin,collab", "rot=z"]).settings == ["bin/z", "collab/z"]


def test_ranking_puts_the_best_first_and_the_paper_printed_average_last():
    rows = []
    for planner, successes in (("a", [True, False]), ("b", [True, True])):
        for i, ok in enumerate(successes):
            rows.append(
                dict(dataset="ycb", planner=planner, mode="collab", rot="z", object="025_mug", trial=i, success=ok,
                     reason=None if ok else "dropped", fc_min_mu=0.4, plan_ms=10.0 + i, trans_mm=0.0, rot_deg=0.0,
                     contacts=2, contacts_in_area=1)
            )  # fmt: skip
    table = ranking(pd.DataFrame(rows), "ycb", ["collab/z"])
    assert list(table["planner"][:2]) == ["b", "a"]
    assert table["collab/z"].iloc[1] == "50 [9, 91] (2)"
    assert table["in-area contact %"].iloc[0] == "50" and table["failures"].iloc[1] == "dropped 1"
    assert table["collab/z"].iloc[2] == f"{PAPER_TABLES['ycb'].ours_average[0]:.0f}"


def test_each_planner_launches_as_one_hydra_multirun_into_the_job_directories():
    bench = parse_args(["planner=random", "dataset=ycb", "mode=bin", "--noise", "10:0", "--n-jobs", "3"])
    todo = [j for j in jobs(bench) if j.planner == "random"]
    cmd = sweep_command(bench, todo)
    assert cmd[1:4] == ["-m", "graspexp", "-m"]
    assert "mode=bin" in cmd and "rot=z,xyz" in cmd and "dataset=ycb" in cmd
    assert "perception.noise={trans_mm:0,rot_deg:0},{trans_mm:10,rot_deg:0}" in cmd
    assert "hydra/launcher=joblib" in cmd and "hydra.launcher.n_jobs=3" in cmd
    assert sorted(
        Path(j.run_dir).relative_to(Path(bench.out) / "random" / "runs").as_posix() for j in todo
    ) == [
        "ycb/bin_xyz_t0_r0",
        "ycb/bin_xyz_t10_r0",
        "ycb/bin_z_t0_r0",
        "ycb/bin_z_t10_r0",
    ]
    slurm = dataclasses.replace(bench, launcher="submitit", slurm_partition="gpu")
    assert {"hydra/launcher=submitit_slurm", "hydra.launcher.partition=gpu"} <= set(
        sweep_command(slurm, todo)
    )


def test_n_jobs_below_one_is_refused_before_any_work(capsys):
    with pytest.raises(SystemExit) as exc:
        parse_args(["planner=obb", "--n-jobs", "0"])
    assert exc.value.code == 2
    assert "argument --n-jobs: expected an integer >= 1, got 0" in capsys.readouterr().err


def test_the_clutter_modes_run_one_job_per_scene_and_rank_planners_by_dr_then_gsr(tmp_path):
    from graspexp.core.rounds import AttemptResult, RoundResult
    from graspexp.report.benchmark import clutter_lines, same_rounds

    bench = parse_args(["planner=obb", "mode=pile,packed", "rot=xyz", "--noise", ""])
    assert bench.settings == ["pile/z", "packed/z"]  # the drop rotation is not read by the clutter modes
    with pytest.raises(ConfigError, match="rank on rounds"):
        parse_args(["planner=obb", "mode=pile,bin"])

    def rounds(planner, removed, seeds=(1, 2)):
        def attempts(r, n):
            return [
                AttemptResult(round=r, attempt=i, target="a", slot=i, executed=True, success=i < n,
                              reason=None if i < n else "dropped", pick_order="lowest_cost", n_left=2 - i,
                              n_planned=2 - i, plan_s=0.01, plan_cpu_s=0.01)
                for i in range(n + 1)
            ]  # fmt: skip

        return [
            RoundResult(
                "ycb",
                "pile",
                planner,
                r,
                seed,
                ["a", "b"],
                ["object_0", "object_1"],
                ["object_0", "object_1"][:n],
                "failure_limit",
                attempts(r, n),
            )  # fmt: skip
            for r, (seed, n) in enumerate(zip(seeds, removed, strict=True))
        ]

    both = rounds("obb", [1, 1]) + rounds("optimal", [2, 2])
    lines = "\n".join(clutter_lines({(0.0, 0.0): both, (10.0, 0.0): both}, tmp_path))
    ranking = lines.split("## Ranking on `ycb`, clutter removal `pile` (zero pose noise)")[1]
    assert ranking.index("| optimal |") < ranking.index("| obb |")  # DR 100 % before 50 %
    assert "Same heaps" in lines and "## Clutter removal at pose noise 10 mm / 0 deg" in lines
    csv = pd.read_csv(tmp_path / "clutter_ranking.csv")
    assert list(csv["planner"][:2]) == ["optimal", "obb"] and set(csv["trans_mm"]) == {0.0, 10.0}
    assert not same_rounds(rounds("obb", [1, 1]) + rounds("optimal", [2, 2], seeds=(1, 3)))
