"""The grip force is what the config says: every gripper option, closed on a thin and on a wide box, presses
each finger with grip_force_n within 5 % once the fingers have stopped (real SAPIEN physics)."""

from pathlib import Path

import numpy as np
import pytest
from helpers.sim import THIN_M, WIDE_FRACTION, gripper_overrides, steady_finger_forces

from graspexp.config.registry import group_options
from graspexp.run.job_config import compose_job


@pytest.mark.parametrize("gripper", group_options("gripper"))
@pytest.mark.parametrize("wide", [False, True], ids=["thin", "wide"])
def test_steady_finger_force_is_the_configured_grip_force(gripper: str, wide: bool, tmp_path: Path) -> None:
    overrides = gripper_overrides(gripper, tmp_path)
    stroke = compose_job(overrides).gripper.max_width_m
    forces, grip_force = steady_finger_forces(overrides, WIDE_FRACTION * stroke if wide else THIN_M)
    np.testing.assert_allclose(forces, grip_force, rtol=0.05)
