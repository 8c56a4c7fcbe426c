"""Clutter removal (``mode=pile``/``packed``): each rule that ends a round, a round re-run alone, and a whole
pile round of procedural objects through the runner, its log and its resume."""

import dataclasses
import importlib.util

import numpy as np
import pytest
from helpers.config import compose_cfg

from graspexp.config import ConfigError
from graspexp.config.compose import compose_validated
from graspexp.core.geometry import make_pose
from graspexp.core.rounds import RoundEnd, RoundResult
from graspexp.core.seeding import round_seed
from graspexp.perception.scene_view import slot_id
from graspexp.planning import plan
from graspexp.planning.grasp import Grasp, NoFeasibleGrasp
from graspexp.planning.request import PlanResult
from graspexp.planning.scene import per_object
from graspexp.run.job_config import make_ready
from graspexp.run.objects import load_sim_object, round_context
from graspexp.run.round_loop import draw_objects
from graspexp.sim.round_scene import add_clutter_object, clutter_scene
from graspexp.sim.rounds import run_round
from graspexp.sim.trial import plain_config


def _round(mode: str, objects: list[str], plan_fn=plan, r: int = 0, *overrides: str) -> RoundResult:
    cfg = compose_cfg(
        f"mode={mode}", "dataset=primitives", f"mode.objects_per_round={len(objects)}", *overrides
    )
    make_ready(cfg)
    plain = plain_config(cfg)
    loaded = [load_sim_object(cfg, name, plain) for name in objects]
    ctx = round_context(plain, loaded, r, round_seed(plain, r), planner=per_object(plan_fn))
    return run_round(ctx)


def _no_grasp(req):
    raise NoFeasibleGrasp("test: none")


def _above(req):
    """A grasp 30 cm above the object, pointing down: the fingers close on air."""
    pose = make_pose(np.diag([1.0, -1.0, -1.0]), req.object_pose[:3, 3] + [0.0, 0.0, 0.3])
    return PlanResult(
        Grasp(pose=pose, width_m=0.05, cost=1.0, cluster=0, path=0, n_feasible=1, planner="test")
    )


def _into_table(req):
    """A grasp whose fingers reach 5 cm into the table 20 cm beside the object."""
    pose = make_pose(
        np.diag([1.0, -1.0, -1.0]), req.object_pose[:3, 3] * [1, 1, 0] + [0.0, 0.2, req.table_z - 0.05]
    )
    return PlanResult(
        Grasp(pose=pose, width_m=0.05, cost=1.0, cluster=0, path=0, n_feasible=1, planner="test")
    )


def test_the_round_ends_when_the_planner_finds_no_grasp():
    res = _round("packed", ["can", "box"], _no_grasp)
    assert res.end == RoundEnd.NO_GRASP.value and res.removed == []
    (row,) = res.attempts
    assert not row.executed and row.reason == "no_feasible_grasp"
    assert row.n_planned == len(res.placed) == row.n_left


@pytest.mark.parametrize("limit", [2, 3])
def test_the_round_ends_after_the_failure_limit(limit):
    res = _round("packed", ["can", "box"], _above, 0, f"mode.max_consecutive_failures={limit}")
    assert res.end == RoundEnd.FAILURE_LIMIT.value
    assert [a.reason for a in res.attempts] == ["no_contact"] * limit
    assert all(a.executed for a in res.attempts)


def test_gripper_table_contact_fails_the_attempt():
    res = _round("packed", ["can"], _into_table)
    assert res.attempts[0].reason == "collision_support" and res.attempts[0].touched_support
    assert res.end == RoundEnd.FAILURE_LIMIT.value


def test_a_held_object_is_removed_and_the_cleared_table_ends_the_round():
    res = _round("packed", ["can", "bottle"])
    assert res.end == RoundEnd.CLEARED.value, res.attempts
    assert sorted(res.removed) == sorted(res.placed) and len(res.placed) == 2
    assert [a.success for a in res.attempts] == [True, True]
    assert res.attempts[0].n_left == 2 and res.attempts[1].n_left == 1


def test_a_round_rerun_alone_gives_the_same_result():
    one, two = _round("pile", ["can", "box", "mug"], plan, 3), _round("pile", ["can", "box", "mug"], plan, 3)
    timing = {"wall_s", "cpu_s", "plan_s", "plan_cpu_s", "execute_s"}

    def strip(r):
        d = dataclasses.asdict(r)
        d["attempts"] = [{k: v for k, v in a.items() if k not in timing} for a in d["attempts"]]
        return {k: v for k, v in d.items() if k not in timing}

    assert strip(one) == strip(two)


def test_objects_are_drawn_per_round_from_the_pool():
    pool = ["a", "b", "c", "d", "e", "f"]
    assert draw_objects(pool, 5, 1) == draw_objects(pool, 5, 1)
    assert len(set(draw_objects(pool, 5, 1))) == 5  # without replacement when the pool holds enough
    assert len(draw_objects(pool[:2], 5, 1)) == 5


def test_a_clutter_setting_it_cannot_run_is_one_line():
    with pytest.raises(ConfigError) as exc:
        compose_validated(["mode=pile", "mode.pick_order=random"])
    assert "mode.pick_order='random' is invalid" in str(exc.value) and "\n" not in str(exc.value)


@pytest.mark.slow
def test_a_three_object_pile_round_runs_end_to_end_resimulates_and_resumes(tmp_path):
    from helpers.logs import strictly_valid

    from graspexp.record import read_round, read_trial
    from graspexp.run.resim import resimulate
    from graspexp.run.runner import run_in_dir

    def cfg():
        return compose_cfg(
            "mode=pile", "dataset=primitives", "objects=[can,box,mug]", "mode.objects_per_round=3", "trials=1",
            "progress=false",
        )  # fmt: skip

    run_in_dir(cfg(), tmp_path)
    path = tmp_path / "trials" / "pile" / "000.mcap"
    res = RoundResult.from_dict(read_round(path))
    assert sorted(res.drawn) == ["box", "can", "mug"] and res.end in {e.value for e in RoundEnd}
    assert res.attempts and all(a.plan_s > 0 for a in res.attempts)
    log = read_trial(path)
    assert {f"object_{i}" for i in range(3)} <= set(log.transforms)  # every object's pose over time
    assert len(log.grasps) == sum(a.executed for a in res.attempts)
    assert {"remove_tray", "settled", "plan", "close", "round_end"} <= {name for _, name, _ in log.phases}
    with open(path, "rb") as f:
        counts = strictly_valid(f)  # every message valid against its schema (Foxglove's and ours)
    assert counts["/round"] == 1 and counts["/contacts"] > 0 and counts["/scene"] >= 2
    agrees, why = resimulate(log)  # the heap re-settled from the round's seed, every attempt again
    assert agrees, why
    attempts = (tmp_path / "attempts.csv").read_text().splitlines()
    assert len(attempts) == 1 + len(res.attempts)
    assert "GSR" in (tmp_path / "summary.md").read_text()
    stamp = path.stat().st_mtime_ns
    run_in_dir(cfg(), tmp_path)  # resume: the finished round is read back, not re-run
    assert path.stat().st_mtime_ns == stamp


@pytest.mark.slow
def test_a_logged_depth_round_records_what_the_camera_saw_and_resimulates(tmp_path):
    """perception.source=depth with logs: before every attempt the round log gets the camera's frames,
    cloud and the target's true, prior and registered poses (as a trial's log does); resim agrees."""
    from helpers.logs import strictly_valid

    from graspexp.record import read_trial
    from graspexp.record import schemas as S
    from graspexp.run.resim import resimulate
    from graspexp.run.runner import run_in_dir

    cfg = compose_cfg(
        "mode=pile", "dataset=primitives", "objects=[can,box]", "mode.objects_per_round=2", "trials=1",
        "progress=false", "perception.source=depth", "perception.noise.trans_mm=10", "perception.noise.rot_deg=10",
    )  # fmt: skip
    run_in_dir(cfg, tmp_path)
    path = tmp_path / "trials" / "pile" / "000.mcap"
    log = read_trial(path)
    with open(path, "rb") as f:
        counts = strictly_valid(f)
    plans = [name for _, name, _ in log.phases if name == "plan"]
    assert counts[S.TOPIC_PERCEPTION] == len(plans) == counts[S.TOPIC_CLOUD] > 0
    assert (
        counts[S.TOPIC_DEPTH] == counts[S.TOPIC_IDS] == len(plans) * len(cfg.perception.camera.azimuths_deg)
    )
    last = log.perception
    assert last["source"] == "depth" and "estimated_pose" in last and last["n_target_points"] > 0
    assert np.linalg.norm(last["estimated_pose"][:3, 3] - last["true_pose"][:3, 3]) < 0.015
    agrees, why = resimulate(log)  # the heap, the camera and every registration again, from the seed
    assert agrees, why


@pytest.mark.slow
def test_a_depth_pile_round_plans_on_registered_poses_and_records_their_errors():
    """perception.source=depth in a 3-object pile: each plan request carries the camera's observation of
    the whole scene (every object's id, its own target's), and each attempt records its target's errors."""
    from graspexp.perception.scene_view import slot_id

    seen = []

    def capture(req):
        obs = req.observation
        seen.append((obs.target_id, set(np.unique(obs.point_ids).tolist())))
        return plan(req)

    res = _round(
        "pile", ["can", "box", "mug"], capture, 0, "perception.source=depth", "perception.noise.trans_mm=10",
        "perception.noise.rot_deg=10",
    )  # fmt: skip
    rows = res.attempts
    assert res.end != RoundEnd.ERROR.value and rows, res.error
    first_ids = seen[0][1] - {0}
    assert len(first_ids) == res.n_placed  # every object placed is in the first observation
    assert all(target in ids for target, ids in seen)
    assert {target for target, _ in seen[: res.n_placed]} == {slot_id(int(b[-1])) for b in res.placed}
    for a in rows:
        assert np.isfinite(a.pose_adds_mm) and np.isfinite(a.pose_trans_err_mm) and 0 < a.registration_fitness
        assert a.pose_adds_mm < 15.0  # ICP from a 10 mm / 10 deg prior lands near the truth


def test_truth_rounds_record_no_pose_error():
    res = _round("packed", ["can", "box"], _no_grasp)
    (row,) = res.attempts
    assert np.isnan(row.pose_adds_mm) and np.isnan(row.registration_fitness)


@pytest.mark.parametrize("threshold", [0.0, 0.005])
def test_objects_of_a_round_sleep_only_with_a_sleep_threshold(threshold):
    """``mode.sleep_threshold``: a box resting on the table is put to sleep by PhysX after its wake counter
    (0.4 s) with a threshold, never without one (every trial's default)."""
    cfg = compose_cfg("mode=packed", "dataset=primitives", f"mode.sleep_threshold={threshold}")
    make_ready(cfg)
    plain = plain_config(cfg)
    box = load_sim_object(cfg, "box", plain)
    ts = clutter_scene(plain.mode, plain)
    rest = make_pose(np.eye(3), [0.0, 0.0, ts.table_z - float(box.model.points[:, 2].min())])
    add_clutter_object(ts, "object_0", box.model, box.hulls, rest, plain)
    body = ts.bodies["object_0"][1]
    assert body.sleep_threshold == pytest.approx(threshold)
    for _ in range(int(1.5 / plain.sim.timestep_s)):
        ts.scene.step()
    assert body.is_sleeping == (threshold > 0)


def test_a_clutter_jobs_objective_is_its_gsr_and_zero_when_no_grasp_was_attempted():
    """The objective of a clutter job (what a sweep or a study reads) is its GSR over the executed
    attempts; rounds whose planner found no grasp are a result (GSR 0), not a failed job."""
    from types import SimpleNamespace

    from graspexp.run.round_loop import round_objective

    def rnd(*attempts):
        return SimpleNamespace(attempts=[SimpleNamespace(executed=e, success=s) for e, s in attempts])

    assert round_objective([rnd((True, True), (True, False)), rnd((False, False))]) == 0.5
    assert round_objective([rnd((False, False)), rnd()]) == 0.0


# issue 51: clutter rounds follow the single-object rules (findings 1 and 9)


def _scene_round(mode: str, objects: list[str], *overrides: str) -> tuple[RoundResult, list]:
    """(round 0 of ``objects``, every SceneRequest its planner got), as :func:`_round`."""
    asked = []

    def spy(req):
        asked.append(req)
        return per_object(plan)(req)

    cfg = compose_cfg(
        f"mode={mode}", "dataset=primitives", f"mode.objects_per_round={len(objects)}", *overrides
    )
    make_ready(cfg)
    plain = plain_config(cfg)
    loaded = [load_sim_object(cfg, name, plain) for name in objects]
    return run_round(round_context(plain, loaded, 0, round_seed(plain, 0), planner=spy)), asked


def test_no_attempt_is_planned_on_objects_the_camera_cannot_see():
    """``perception.source=depth`` with the camera 10 m away: no object can be registered, so nothing is
    planned; the round ends as a no-grasp round, its one row (not executed) ``registration_failed``."""
    res, asked = _scene_round("pile", ["can", "box", "mug"], "perception.source=depth",
                              "perception.camera.distance_m=10")  # fmt: skip
    assert asked == [] and res.end == RoundEnd.NO_GRASP.value and res.removed == [], res
    (row,) = res.attempts
    assert not row.executed and row.reason == "registration_failed" and row.n_planned == 0
    assert row.registration_fitness == 0.0 and np.isnan(row.pose_adds_mm)


def test_an_object_whose_registration_failed_is_no_target_and_stays_on_the_table(monkeypatch):
    """An object the camera could not register (here: slot 0, made to fail) is never a target; the others are
    planned and grasped (it stays their obstacle at its prior); once only it is left, the attempt records
    ``registration_failed`` and the round ends ``no_grasp``."""
    import graspexp.sim.rounds as rounds

    real = rounds.perceive_scene

    def slot_0_unseen(cfg, objects, table_z, seed):
        view = real(cfg, objects, table_z, seed)
        poses = {s: p for s, p in view.poses.items() if s != 0}
        return dataclasses.replace(view, poses=poses, failed={0: "test: unseen"} if 0 in objects else {})

    monkeypatch.setattr(rounds, "perceive_scene", slot_0_unseen)
    res, asked = _scene_round("packed", ["can", "bottle"])
    assert asked and all(slot_id(0) not in req.ids for req in asked)
    assert all(0 in {n.id for n in t.neighbours} for req in asked for t in req.targets)
    assert res.removed == ["object_1"] and res.end == RoundEnd.NO_GRASP.value, res
    assert [(a.target, a.executed, a.reason) for a in res.attempts] == [
        ("bottle", True, None),
        ("can", False, "registration_failed"),
    ]


def test_a_heap_still_moving_is_never_planned_on():
    """``sim.settle_max_s=0.01``: the heap still falls when the planner would look; as a single-object trial,
    nothing is planned: the round ends ``not_at_rest``, its one row (not executed) names a moving object."""
    res, asked = _scene_round("pile", ["can", "box", "mug"], "sim.settle_min_s=0", "sim.settle_max_s=0.01")
    assert asked == [] and res.end == RoundEnd.NOT_AT_REST.value and res.removed == [], res
    (row,) = res.attempts
    assert not row.executed and row.reason == "not_at_rest" and row.n_left == len(res.placed) > 0


def test_a_round_that_placed_nothing_is_not_cleared():
    """A workspace of 2 mm: every object is taken away, nothing is placed; the round is ``nothing_placed``
    (not ``cleared``) and the clutter table counts it among no planner's rounds."""
    from graspexp.report.round_tables import clutter_table

    res, asked = _scene_round("packed", ["can", "box"], "mode.workspace_half_size_m=[0.001,0.001]")
    assert res.placed == [] and res.end == RoundEnd.NOTHING_PLACED.value and asked == [] and not res.attempts
    row = clutter_table([res]).iloc[0]
    assert row["rounds"] == 0 and row["end_nothing_placed"] == 1 and row["end_cleared"] == 0


def test_a_clutter_job_whose_every_round_erred_is_refused(tmp_path, monkeypatch):
    """As a single-object job none of whose trials ran: a clutter job whose every round ended in an error
    raises RunError (exit status 2 from the command line), naming the first error."""
    import graspexp.run.round_loop as round_loop
    from graspexp.run.locks import RunError
    from graspexp.run.runner import run_in_dir

    def broken(ctx):
        raise RuntimeError("test: the planner cannot load")

    monkeypatch.setattr(round_loop, "run_round", broken)
    cfg = compose_cfg("mode=pile", "dataset=primitives", "objects=[can]", "trials=2", "progress=false",
                      "mode.objects_per_round=1", "record=false")  # fmt: skip
    with pytest.raises(RunError, match=r"^no round ran: every one of the 2 rounds ended in an error \(first: "
                       r"RuntimeError: test: the planner cannot load\)$"):  # fmt: skip
        run_in_dir(cfg, tmp_path / "run")


@pytest.mark.slow
def test_a_pile_job_with_a_corrupted_vgn_checkpoint_exits_2_as_bin_does(tmp_path):
    """The issue's command: ``planner=vgn`` with a checkpoint that fails its hash, ``mode=pile``: every round
    errs, and the job exits 2 with one line, as ``mode=bin`` does."""
    from helpers.cli import one_error_line, run_job

    from graspexp.config.planner.vgn import EXTRA_MODULES
    from graspexp.core.checkpoints import VGN

    if any(importlib.util.find_spec(m) is None for m in EXTRA_MODULES):
        pytest.skip("planner=vgn needs the optional extra 'learned'")
    (tmp_path / "ckpt").mkdir()
    (tmp_path / "ckpt" / VGN.filename).write_bytes(bytes(VGN.size_bytes))
    env = {"GRASPEXP_CHECKPOINTS": str(tmp_path / "ckpt")}
    overrides = ("planner=vgn", "gripper=panda", "dataset=primitives", "objects=[can]", "trials=1")
    for mode, extra in (("bin", ()), ("pile", ("mode.objects_per_round=1",))):  # one can: a heap at rest
        line = one_error_line(run_job(tmp_path / mode, f"mode={mode}", *overrides, *extra, env=env))
        assert "SHA-256" in line and ("no round ran" if mode == "pile" else "no trial ran") in line, line
