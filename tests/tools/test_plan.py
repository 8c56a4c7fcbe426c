"""``graspexp plan`` refuses, with one line and exit status 2, what it cannot plan (issue 51): a clutter mode
(finding 10: it plans one object alone) and a pose the camera could not register (finding 1: it printed a
grasp on the true pose, or ``prior=none``'s 10 cm below the object)."""

import pytest

from graspexp.tools.plan import main


def _refusal(capsys, *overrides: str) -> str:
    with pytest.raises(SystemExit) as exc:
        main(list(overrides))
    out, err = capsys.readouterr()
    assert exc.value.code == 2 and out == "" and err.count("\n") == 1, (out, err)
    assert err.startswith("graspexp plan: error: ")
    return err.strip()


@pytest.mark.parametrize("mode", ["pile", "packed"])
def test_plan_refuses_a_clutter_mode_in_one_line(capsys, mode):
    line = _refusal(capsys, f"mode={mode}", "objects=[can]")
    assert f"mode={mode} is a clutter scene; plan plans one object standing alone" in line
    assert f"`python -m graspexp mode={mode} objects=[...] trials=1`" in line


@pytest.mark.parametrize(
    "overrides",
    [
        ("perception.camera.distance_m=10",),
        ("perception.camera.max_range_m=0.2",),
        ("perception.registration.prior=none", "perception.camera.distance_m=10"),
    ],
)
def test_plan_refuses_a_pose_the_camera_could_not_register(capsys, overrides, data_root):
    line = _refusal(
        capsys, "objects=[025_mug]", "dataset=ycb", f"dataset.root={data_root / 'ycb'}", "perception.source=depth",
        *overrides,
    )  # fmt: skip
    assert line == (
        "graspexp plan: error: 025_mug: registration_failed: the camera saw 0 points of the target, fewer than "
        "perception.registration.min_target_points=6"
    )
