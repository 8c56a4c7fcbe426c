"""The step loop's shortcuts decide as the plain computation would: the speed check's float64 sums of
squares against numpy's float32 dot products, and the arm's drive targets computed before stepping."""

import numpy as np

from graspexp.sim.gripper import Gripper
from graspexp.sim.trial import F32_DOT_REL_ERROR


def test_float64_sums_of_squares_stay_within_the_bound_of_numpys_float32_dot():
    rng = np.random.default_rng(0)
    for scale in (1e-6, 1e-2, 1.0, 3.0, 1e3):
        v = (scale * rng.standard_normal((20_000, 3))).astype(np.float32)
        exact = np.array([float(x.dot(x)) for x in v])
        fast = np.array([x * x + y * y + z * z for x, y, z in v.tolist()])
        assert np.all(np.abs(fast - exact) <= 0.5 * F32_DOT_REL_ERROR * exact)


class _Joint:
    def __init__(self, log: list, i: int):
        self.set_drive_target = lambda value: log.append((i, value))


def test_arm_moves_set_each_step_only_the_targets_that_changed():
    log: list = []
    gripper = Gripper(None, None, (None, None), [_Joint(log, i) for i in range(3)], close_target_m=-0.01)
    gripper.drive_arm(np.array([0.0, 0.0, -0.05]))
    assert log == [(0, 0.0), (1, 0.0), (2, -0.05)]
    s = np.arange(1, 5) / 4
    moves = gripper.arm_moves(np.stack([np.zeros(4), np.zeros(4), -0.05 * (1 - s)], axis=1))
    assert [[value for _, value in step] for step in moves] == [[-0.05 * (1 - x)] for x in s.tolist()]
    assert gripper.arm_targets == [0.0, 0.0, -0.0]
