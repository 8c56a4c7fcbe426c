"""bench.plan_grasps: the grasps planners choose on fixed seeded poses, saved and checked bit for bit."""

import numpy as np
import pytest

from graspexp.tools.bench.plan_grasps import main


@pytest.mark.slow
def test_plan_grasps_finds_its_own_plans_identical_and_names_a_changed_one(tmp_path, capsys) -> None:
    saved = tmp_path / "grasps.npz"
    argv = ["--poses", "3", "dataset=primitives", "mode=collab", "objects=[can,mug]"]
    assert main(["--save", str(saved), *argv]) == 0
    with np.load(saved) as f:
        plans = dict(f)
    keys = [
        f"{p}/primitives/collab/{o}/{i}"
        for p in ("optimal", "optimal_plus")
        for o in ("can", "mug")
        for i in range(3)
    ]
    assert list(plans["keys"]) == keys
    assert plans["pose"].shape == (12, 4, 4) and plans["width_m"].shape == (12,)
    assert main(["--check", str(saved)]) == 0
    assert "12 plans identical" in capsys.readouterr().out

    plans["pose"][4, 0, 3] = np.nextafter(plans["pose"][4, 0, 3], np.inf)  # one ulp off
    np.savez(saved, **plans)
    assert main(["--check", str(saved)]) == 1
    assert capsys.readouterr().out.strip() == f"{keys[4]}: pose differ"
