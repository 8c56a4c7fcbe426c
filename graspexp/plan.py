"""Plan one grasp from the command line and print it as one JSON object.

Usage::

    python -m graspexp.plan dataset=ycb object=025_mug [mode=bin] [gripper=panda] [+dump=FILE.npz]
    GRASPEXP_DATA=/path/to/datasets python -m graspexp.plan dataset=ycb object=025_mug

Every other argument is a Hydra override of ``conf/config.yaml`` (the config is composed with Hydra's
compose API, so no output folder is created). ``object=NAME`` (or ``+object=NAME``) names the object;
``+dump=FILE.npz`` (or ``dump=FILE.npz``) saves every intermediate of the plan (the keys of
``PlanResult.details`` plus ``object_pose``) with :func:`numpy.savez`.

The object stands upright on the support: its pose is the identity rotation translated so that the
mesh's lowest point sits on ``z = mode.support_height_m`` (x = y = 0). ``rot=`` is accepted but has no
effect here (it drives the drop in the simulated trials). Seeds match the runner's trial 0: the cloud
uses ``derive_seed(seed, "cloud", object)``, the plan ``derive_seed(derive_seed(seed, dataset, object, 0),
"plan")``.

Printed keys: ``object``, ``dataset``, ``mode``, ``pose`` (4x4 list, world, metres), ``width`` (m),
``cost``, ``cluster``, ``path``, ``K``, ``M``, ``n_feasible``, ``plan_ms`` (wall time of the planner
call). A bad argument, an unknown object or a plan with no feasible grasp prints one ``error:`` line
on stderr and exits non-zero, without a traceback.
"""

import json
import sys
import time
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from omegaconf import DictConfig, OmegaConf

from graspexp.cli import CONF_DIR
from graspexp.config import ConfigError, register_configs, validate
from graspexp.planning import NoFeasibleGrasp, PlanRequest, PlanResult, UnknownPlanner, plan
from graspexp.seeding import derive_seed

CLI_TRIAL = 0
"""The trial index whose planner seed the CLI uses."""


class CliError(Exception):
    """A command-line problem reported as one line."""


def split_args(argv: Sequence[str], keys: Sequence[str]) -> tuple[dict[str, str], list[str]]:
    """Pull ``key=value`` / ``+key=value`` for each of ``keys`` out of ``argv``; the rest are Hydra overrides."""
    found: dict[str, str] = {}
    rest: list[str] = []
    for arg in argv:
        name, sep, value = arg.partition("=")
        bare = name.lstrip("+")
        if sep and bare in keys and name in (bare, "+" + bare):
            found[bare] = value
        else:
            rest.append(arg)
    return found, rest


def compose(overrides: Sequence[str]) -> DictConfig:
    """Compose ``conf/config.yaml`` with ``overrides`` and validate it; errors become :class:`CliError`."""
    from hydra import compose as hydra_compose
    from hydra import initialize_config_dir
    from hydra.core.global_hydra import GlobalHydra
    from hydra.errors import HydraException
    from omegaconf.errors import OmegaConfBaseException

    register_configs()
    GlobalHydra.instance().clear()
    try:
        with initialize_config_dir(config_dir=CONF_DIR, version_base="1.3"):
            cfg = hydra_compose(config_name="config", overrides=list(overrides))
        validate(cfg)
    except (HydraException, OmegaConfBaseException, ConfigError) as err:
        raise CliError(" ".join(str(err).split())) from None
    return cfg


@dataclass(frozen=True)
class PlannedObject:
    """One object placed upright on the support and its plan."""

    model: object
    """The :class:`graspexp.datasets.ObjectModel` (object frame)."""
    object_pose: np.ndarray
    """(4,4) world pose of the object frame."""
    request: PlanRequest
    result: PlanResult
    plan_ms: float


def upright_pose(model, support_height_m: float) -> np.ndarray:
    """(4,4) identity rotation, translated so the mesh's lowest point is on ``z = support_height_m``."""
    pose = np.eye(4)
    pose[2, 3] = support_height_m - float(np.min(model.mesh.vertices[:, 2]))
    return pose


def load(cfg: DictConfig, name: str):
    """The object model of ``name`` with the configured cloud size; dataset errors become :class:`CliError`."""
    from graspexp.datasets import DatasetError, load_object

    try:
        return load_object(cfg.dataset, name, int(cfg.planner.n_points), derive_seed(cfg.seed, "cloud", name))
    except DatasetError as err:
        raise CliError(str(err)) from None


def upright_request(cfg: DictConfig, model) -> PlanRequest:
    """The planning request for ``model`` standing upright on the support (module doc)."""
    pose = upright_pose(model, float(cfg.mode.support_height_m))
    return PlanRequest(
        points=model.points @ pose[:3, :3].T + pose[:3, 3],
        normals=model.normals @ pose[:3, :3].T,
        area_mask=np.asarray(model.area_mask, dtype=bool),
        object_pose=pose,
        table_z=float(cfg.mode.support_height_m),
        mode=str(cfg.mode.name),
        gripper=OmegaConf.to_object(cfg.gripper),
        planner=OmegaConf.to_object(cfg.planner),
        cost=OmegaConf.to_object(cfg.cost),
        seed=derive_seed(derive_seed(cfg.seed, cfg.dataset.name, model.name, CLI_TRIAL), "plan"),
    )


def plan_upright(cfg: DictConfig, model) -> PlannedObject:
    """Place ``model`` upright on the support and plan with the configured planner."""
    req = upright_request(cfg, model)
    start = time.perf_counter()
    try:
        result = plan(req)
    except (NoFeasibleGrasp, UnknownPlanner) as err:
        raise CliError(f"{model.name}: {err}") from None
    plan_ms = (time.perf_counter() - start) * 1e3
    return PlannedObject(
        model=model, object_pose=req.object_pose, request=req, result=result, plan_ms=plan_ms
    )


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
    arrays = {key: np.asarray(value) for key, value in planned.result.details.items()}
    arrays["object_pose"] = planned.object_pose
    target = Path(path)
    target.parent.mkdir(parents=True, exist_ok=True)
    with target.open("wb") as fh:
        np.savez(fh, **arrays)


def main(argv: Sequence[str] | None = None) -> int:
    """CLI entry; returns the exit status."""
    args, overrides = split_args(sys.argv[1:] if argv is None else argv, ("object", "dump"))
    try:
        if not args.get("object"):
            raise CliError("missing object=NAME (e.g. python -m graspexp.plan dataset=ycb object=025_mug)")
        cfg = compose(overrides)
        planned = plan_upright(cfg, load(cfg, args["object"]))
        if args.get("dump"):
            dump(args["dump"], planned)
    except CliError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    print(json.dumps(grasp_record(cfg, planned)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
