"""Plan one grasp from the command line and print it as one JSON object.

Usage::

    python -m graspexp plan objects=[025_mug] [--dump FILE.npz] dataset=ycb [mode=bin] [gripper=panda]
    GRASPEXP_DATA=/path/to/datasets python -m graspexp plan objects=[025_mug] dataset=ycb

``key=value`` arguments are Hydra overrides of ``conf/config.yaml`` (composed with Hydra's compose API, so
no output folder is created). ``--dump FILE.npz`` saves every intermediate of the plan (the keys of
``PlanResult.details`` plus ``object_pose``) with :func:`numpy.savez`.

The object stands upright on the support (:mod:`graspexp.run.upright`: identity rotation, the mesh's
lowest point on ``z = mode.support_height_m``, x = y = 0). ``rot=`` is accepted but has no effect here (it
drives the drop in the simulated trials). Seeds match the runner's trial 0.

Printed keys: ``object``, ``dataset``, ``mode``, ``pose`` (4x4 list, world, metres), ``width`` (m),
``cost``, ``cluster``, ``path``, ``K``, ``M``, ``n_feasible``, ``plan_ms`` (wall time of the planner
call). A bad argument, an unknown object, a clutter mode (``mode=pile``/``packed``: this tool plans one
object alone), a pose the camera could not register (``perception.source=depth``) or a plan with no feasible
grasp prints one ``graspexp plan: error:`` line on stderr and exits with status 2, without a traceback.
"""

import json
import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np
from omegaconf import DictConfig

from graspexp.config.mode import is_clutter
from graspexp.core.files import write_atomic
from graspexp.datasets import DatasetError, job_object
from graspexp.perception.scene_view import RegistrationFailed
from graspexp.planning import NoFeasibleGrasp, UnknownPlanner
from graspexp.run.upright import PlannedObject, plan_upright
from graspexp.tools.cli import compose_checked, fail, tool_parser

PROG = "graspexp plan"


def grasp_record(cfg: DictConfig, planned: PlannedObject) -> dict:
    """The JSON-ready summary of a plan."""
    g = planned.result.grasp
    return {
        "object": planned.model.name,
        "dataset": str(cfg.dataset.name),
        "mode": str(cfg.mode.name),
        "pose": g.pose.tolist(),
        "width": g.width_m,
        "cost": g.cost,
        "cluster": g.cluster,
        "path": g.path,
        "K": g.extras.get("K"),
        "M": g.extras.get("M"),
        "n_feasible": g.n_feasible,
        "plan_ms": round(planned.plan_ms, 3),
    }


def dump(path: str, planned: PlannedObject) -> None:
    """Save every intermediate of the plan to ``path`` (``.npz``)."""
    arrays = planned.result.detail_arrays()
    arrays["object_pose"] = planned.object_pose
    write_atomic(Path(path), lambda fh: np.savez(fh, **arrays))


def main(argv: Sequence[str] | None = None) -> int:
    """CLI entry; returns the exit status."""
    parser = tool_parser(PROG, __doc__.splitlines()[0], overrides=True)
    parser.add_argument("--dump", metavar="FILE.npz", help="save every intermediate of the plan")
    args = parser.parse_intermixed_args(argv)
    cfg = compose_checked(args.overrides, PROG)
    if is_clutter(cfg.mode):
        fail(
            f"mode={cfg.mode.name} is a clutter scene; plan plans one object standing alone (mode=collab or "
            f"mode=bin): run a round with `python -m graspexp mode={cfg.mode.name} objects=[...] trials=1`",
            PROG,
        )
    if not cfg.objects or len(cfg.objects) != 1:
        fail("name the one object to plan for: objects=[NAME], e.g. objects=[025_mug]", PROG)
    name = str(cfg.objects[0])
    try:
        planned = plan_upright(cfg, job_object(cfg, name))
    except (DatasetError, NoFeasibleGrasp, UnknownPlanner, RegistrationFailed) as err:
        fail(f"{name}: {err}" if not isinstance(err, DatasetError) else str(err), PROG)
    if args.dump:
        try:
            dump(args.dump, planned)
        except OSError as err:
            fail(f"cannot write {args.dump}: {err.strerror or err}; choose another path for --dump", PROG)
    print(json.dumps(grasp_record(cfg, planned)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
