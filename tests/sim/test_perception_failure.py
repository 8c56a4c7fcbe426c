"""Issue 51, findings 1 and 2: with ``perception.source=depth``, a camera that saw (almost) nothing of the object
or a registration that converged on nothing ends the trial ``registration_failed`` with its detail (the points
seen, the fitness): the planner is never called on the prior or on the identity. A registration that works is
unchanged, and a view-based planner's own "the camera saw N points" reason is kept in the result too."""

import math

import numpy as np
import pytest
from helpers.config import compose_cfg

from graspexp.core.outcome import FailureReason
from graspexp.planning import plan
from graspexp.run.objects import load_sim_object, trial_context
from graspexp.sim.trial import plain_config, run_trial

DEPTH = ("perception.source=depth",)


def _trial(obj: str, *overrides: str, trial: int = 0):
    """(result, the plan requests the planner got) of one trial of ``obj`` under ``overrides``."""
    cfg = compose_cfg(*overrides)
    plain = plain_config(cfg)
    asked = []

    def spy(req):
        asked.append(req)
        return plan(req)

    return run_trial(trial_context(plain, load_sim_object(cfg, obj, plain), trial, plan=spy)), asked


@pytest.mark.parametrize(
    "overrides",
    [
        ("perception.camera.distance_m=10",),
        ("perception.camera.max_range_m=0.2",),
        ("perception.registration.prior=none", "perception.camera.distance_m=10"),
        ("perception.camera.cx_px=10000",),
        ("perception.camera.workspace_half_m=0.001",),
    ],
)
def test_a_camera_that_sees_nothing_of_the_mug_is_a_failed_registration_never_a_plan(overrides, data_root):
    res, asked = _trial("025_mug", "dataset=ycb", f"dataset.root={data_root / 'ycb'}", *DEPTH, *overrides)
    assert not res.success and res.reason == FailureReason.REGISTRATION_FAILED.value, res
    assert asked == []  # neither the prior (the exact pose here: no noise) nor the identity was planned on
    assert res.detail.startswith("the camera saw 0 points of the target, fewer than ")
    assert res.registration_fitness == 0.0
    assert math.isnan(res.pose_adds_mm) and math.isnan(res.pose_trans_err_mm)  # no pose was registered


def test_icp_that_converges_on_nothing_is_a_failed_registration():
    """``fx_px=99999``: the camera sees a 2 mm patch of the can, ICP from the exact prior ends where no model
    point has an observed one within ``max_correspondence_m`` (fitness 0): refused, not planned on."""
    res, asked = _trial("can", "dataset=primitives", *DEPTH, "perception.camera.fx_px=99999", trial=2)
    assert res.reason == FailureReason.REGISTRATION_FAILED.value and asked == [], res
    assert "ICP aligned 0 model points (fitness 0.000)" in res.detail, res.detail


def test_a_registration_that_works_is_planned_on_as_before(data_root):
    res, asked = _trial(
        "025_mug", "dataset=ycb", f"dataset.root={data_root / 'ycb'}", *DEPTH, "perception.noise.trans_mm=10",
        "perception.noise.rot_deg=10",
    )  # fmt: skip
    assert res.success and res.detail == "" and len(asked) == 1, res
    assert np.isfinite(res.pose_adds_mm) and res.pose_adds_mm < 10.0 and res.registration_fitness > 0.5


def test_a_view_based_planners_reason_is_kept_in_the_result(data_root):
    """antipodal_view on a camera 10 m away: no_feasible_grasp, its "the camera saw 0 points" in ``detail``
    (a column of results.csv)."""
    res, _ = _trial(
        "025_mug", "dataset=ycb", f"dataset.root={data_root / 'ycb'}", "planner=antipodal_view",
        "perception.camera.distance_m=10",
    )  # fmt: skip
    assert res.reason == FailureReason.NO_FEASIBLE_GRASP.value and "detail" in res.to_dict()  # a CSV column
    assert res.detail == "antipodal_view: the camera saw 0 points of the object (< planner.min_points = 20)"


def test_a_view_based_planner_plans_from_the_cloud_whatever_the_registration(data_root):
    """With ``perception.source=depth`` a view-based planner (antipodal_view) is not stopped by a failed
    registration: it plans from the camera's cloud, not the pose, and says itself that the camera saw nothing;
    the failed registration leaves its fitness and no pose error."""
    res, asked = _trial(
        "025_mug", "dataset=ycb", f"dataset.root={data_root / 'ycb'}", "planner=antipodal_view", *DEPTH,
        "perception.camera.distance_m=10",
    )  # fmt: skip
    assert res.reason == FailureReason.NO_FEASIBLE_GRASP.value and len(asked) == 1, res
    assert "the camera saw 0 points of the object" in res.detail
    assert res.registration_fitness == 0.0 and math.isnan(res.pose_adds_mm)
