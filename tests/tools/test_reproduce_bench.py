"""bench.reproduce: the paper suite with the paper's planner, its overrides, and a tiny run's printout."""

import pytest

from graspexp.tools.bench.reproduce import main, sweep_overrides


def test_the_sweep_is_the_paper_suite_with_the_papers_planner_logged_and_overrides_replace_its_keys():
    full = sweep_overrides([])
    assert {"mode=collab,bin", "rot=z,xyz", "dataset=ycb,linemod", "planner=optimal", "trials=10"} <= set(
        full
    )
    assert {"record=true", "progress=false"} <= set(full)
    subset = sweep_overrides(["trials=1", "dataset=ycb", "objects=[011_banana]"])
    assert "trials=10" not in subset and "dataset=ycb,linemod" not in subset
    assert {"trials=1", "dataset=ycb", "objects=[011_banana]", "planner=optimal"} <= set(subset)


@pytest.mark.slow
def test_a_tiny_subset_prints_wall_cpu_and_rate_for_one_and_two_workers(capsys):
    main(["dataset=ycb", "objects=[011_banana]", "mode=collab", "rot=z", "trials=1"])
    out = capsys.readouterr().out
    lines = {
        n: next(line for line in out.splitlines() if line.strip().startswith(f"{n} worker")) for n in (1, 2)
    }
    for line in lines.values():
        assert "1 trials" in line and "wall" in line and "CPU" in line and "trials/s" in line
    assert "x" in lines[2].split("trials/s")[1]
