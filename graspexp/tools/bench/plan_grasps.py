"""The grasps planners choose on fixed seeded poses, saved or checked bit for bit (a refactoring must keep
every one).

Usage::

    python -m graspexp bench.plan_grasps --save FILE.npz [--poses 5] [key=value ...]
    python -m graspexp bench.plan_grasps --check FILE.npz [key=value ...]

For every planner (``planner=a,b``; default ``optimal,optimal_plus``), dataset (``dataset=a,b``; default the
paper's), mode (``mode=a,b``; default the paper's) and object (``objects=[...]``, default every staged
one), ``--poses`` requests are planned: pose 0
upright (:func:`graspexp.run.upright.upright_request`, the plan bench's request), then turned about Z (odd
poses) or uniformly (even poses) by a rotation seeded by the object and pose, resting on the support
(:func:`graspexp.run.upright.resting_pose`), each with the planner seed of that trial index. Saved per plan:
the grasp pose (4, 4), width, m, cost, cluster, path, ``n_feasible`` and the scalar ``extras``, or the
:class:`~graspexp.planning.NoFeasibleGrasp` message. ``--check`` re-plans the saved file's keys with its
saved settings and compares every float with ``np.array_equal``; exit status 1 on a difference.
"""

import json
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from graspexp.core.geometry import random_rotation, yaw_rotation
from graspexp.core.seeding import rng_for, trial_seed
from graspexp.datasets import available_objects, job_object
from graspexp.planning import NoFeasibleGrasp, plan
from graspexp.run.suites import PAPER_DATASETS, PAPER_MODES
from graspexp.run.upright import posed_request, resting_pose, upright_request
from graspexp.tools.cli import compose_checked, fail, positive_int, take_sweep, tool_parser

PROG = "graspexp bench.plan_grasps"
PLANNERS = ("optimal", "optimal_plus")
"""The planners planned by default."""


def plan_all(
    overrides: list[str], planners: list[str], datasets: list[str], modes: list[str], poses: int
) -> dict[str, np.ndarray]:
    """Every plan of the module doc, as arrays: ``keys`` (R,) ``planner/dataset/mode/object/pose``,
    ``pose`` (R, 4, 4) (NaN where no grasp), ``width_m``, ``cost`` (R,), ``index`` (R, 3) cluster, path and
    ``n_feasible`` (-1 where no grasp), ``extras`` (R,) JSON and ``failure`` (R,) message ('' where planned)."""
    rows = []
    for planner in planners:
        for dataset in datasets:
            for mode in modes:
                cfg = compose_checked(
                    [f"planner={planner}", f"dataset={dataset}", f"mode={mode}", *overrides], PROG
                )
                for name in list(cfg.objects) if cfg.objects else available_objects(cfg.dataset):
                    model = job_object(cfg, name)
                    for i in range(poses):
                        rows.append((f"{planner}/{dataset}/{mode}/{name}/{i}", _plan(cfg, model, i)))
    return {
        "keys": np.array([k for k, _ in rows]),
        **{field: np.stack([r[field] for _, r in rows]) for field in rows[0][1]},
    }


def _plan(cfg, model, i: int) -> dict[str, np.ndarray]:
    """One plan of pose ``i`` (module doc) as the fields of :func:`plan_all`."""
    if i == 0:
        req = upright_request(cfg, model)
    else:
        rng = rng_for(trial_seed(cfg, model.name, i), "pose")
        rotation = yaw_rotation(rng.uniform(0.0, 2.0 * np.pi)) if i % 2 else random_rotation(rng)
        req = posed_request(cfg, model, resting_pose(model, rotation, float(cfg.mode.support_height_m)), i)
    try:
        g = plan(req).grasp
    except NoFeasibleGrasp as exc:
        return {
            "pose": np.full((4, 4), np.nan),
            "width_m": np.float64(np.nan),
            "cost": np.float64(np.nan),
            "index": np.full(3, -1),
            "extras": np.str_(""),
            "failure": np.str_(str(exc)),
        }
    scalars = {k: v for k, v in g.extras.items() if isinstance(v, (int, float, str))}
    return {
        "pose": g.pose,
        "width_m": np.float64(g.width_m),
        "cost": np.float64(g.cost),
        "index": np.array([g.cluster, g.path, g.n_feasible]),
        "extras": np.str_(json.dumps(scalars, sort_keys=True)),
        "failure": np.str_(""),
    }


def differences(saved: dict[str, np.ndarray], now: dict[str, np.ndarray]) -> list[str]:
    """One line per plan of ``saved`` whose fields differ in ``now`` (same keys); [] when identical."""
    out = []
    for i, key in enumerate(saved["keys"]):
        changed = [
            f
            for f in saved
            if f != "keys"
            and not np.array_equal(saved[f][i], now[f][i], equal_nan=f != "extras" and f != "failure")
        ]
        if changed:
            out.append(f"{key}: {', '.join(changed)} differ")
    return out


def main(argv: Sequence[str] | None = None) -> int:
    parser = tool_parser(PROG, __doc__.split("\n")[0], overrides=True)
    action = parser.add_mutually_exclusive_group(required=True)
    action.add_argument("--save", type=Path, metavar="FILE", help="plan and write FILE (.npz)")
    action.add_argument("--check", type=Path, metavar="FILE", help="re-plan FILE's keys and compare")
    parser.add_argument("--poses", type=positive_int, default=5, help="poses per object (default 5)")
    args = parser.parse_intermixed_args(argv)
    if args.check:
        with np.load(args.check) as f:
            saved = dict(f)
        settings = json.loads(str(saved.pop("settings")))
        now = plan_all(**settings)
        if list(now["keys"]) != list(saved["keys"]):
            fail(f"{args.check}: the plans of its settings are not the saved keys", PROG)
        problems = differences(saved, now)
        print("\n".join(problems) or f"{len(saved['keys'])} plans identical to {args.check}")
        return 1 if problems else 0
    planners, rest = take_sweep(args.overrides, "planner", PLANNERS)
    datasets, rest = take_sweep(rest, "dataset", PAPER_DATASETS)
    modes, rest = take_sweep(rest, "mode", PAPER_MODES)
    settings = {
        "overrides": rest,
        "planners": planners,
        "datasets": datasets,
        "modes": modes,
        "poses": args.poses,
    }
    out = plan_all(**settings)
    np.savez(args.save, settings=np.str_(json.dumps(settings)), **out)
    failed = int((out["failure"] != "").sum())
    print(f"{PROG}: {len(out['keys'])} plans ({failed} without a grasp) in {args.save}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
