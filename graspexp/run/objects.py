"""A job's objects made ready for their trials (model, collision shape, Foxglove scene), and the one
place a trial's context is set up from a config and an object: the runner, re-simulation, the benches and
the tests all go through :func:`load_sim_object`, :func:`trial_context` and :func:`round_context`."""

import dataclasses
import logging

from omegaconf import DictConfig

from graspexp.config.job import JobConfig
from graspexp.core.seeding import trial_seed
from graspexp.datasets import ObjectError, job_object
from graspexp.datasets.model import ObjectModel
from graspexp.planning import plan, plan_scene
from graspexp.planning.scene import ScenePlanner
from graspexp.quality import fc_min_mu
from graspexp.record.scene import ObjectScene, object_scene
from graspexp.sim.collision_shapes import ShapeError, shape_with_fallback
from graspexp.sim.rounds import RoundContext, RoundObject
from graspexp.sim.shape import CollisionShape
from graspexp.sim.trial import LogSink, NullRecorder, PlanFn, TrialContext, plain_config

log = logging.getLogger(__name__)


@dataclasses.dataclass(frozen=True)
class LoadedObject:
    """An object ready for its trials: model, collision shape, Foxglove scene, and what was assumed."""

    model: ObjectModel
    hulls: CollisionShape
    scene: ObjectScene | None
    """None: the trials log no /scene messages."""
    notes: tuple[str, ...]
    """The model's notes (units, mass, area) and the collision shape's (a fallback method)."""


def load_sim_object(cfg: DictConfig, name: str, plain: JobConfig | None = None) -> LoadedObject:
    """Object ``name`` of job config ``cfg`` (``plain``: the same config as dataclasses, made here if None)
    with its collision shape (the configured method, else the fallback: the note says so) and scene.
    Raises :class:`ObjectError` for an unusable mesh, sidecar or area, :class:`ShapeError` when no shape
    can be built."""
    plain = plain_config(cfg) if plain is None else plain
    model = job_object(cfg, name)
    hulls, shape_note = shape_with_fallback(model.mesh, plain.sim)
    notes = (*model.notes, shape_note) if shape_note else model.notes
    return LoadedObject(model, hulls, object_scene(plain, hulls), notes)


def load_models(cfg: DictConfig, objects: list[str]) -> tuple[dict[str, LoadedObject], dict[str, str]]:
    """({name: loaded object}, {name: why it cannot be used}), before any trial runs. An object whose mesh,
    sidecar or area is unusable (:class:`ObjectError`) or for which no collision shape can be built
    (:class:`ShapeError`) fails alone; a missing data folder or file, or a broken region spec file, stops
    the job here (DatasetError) instead of filling a table."""
    plain = plain_config(cfg)
    out, failed = {}, {}
    for name in objects:
        try:
            out[name] = load_sim_object(cfg, name, plain)
        except (ObjectError, ShapeError) as exc:
            log.error("object %s cannot be used: %s", name, exc)
            failed[name] = str(exc)
    return out, failed


def trial_context(
    plain: JobConfig,
    loaded: LoadedObject,
    trial: int,
    recorder: LogSink | None = None,
    *,
    plan: PlanFn = plan,
    seed: int | None = None,
) -> TrialContext:
    """The context of trial ``trial`` of ``loaded`` under job config ``plain``: its seed (None: the job's,
    :func:`graspexp.core.seeding.trial_seed`; re-simulation passes the one a log recorded), ``recorder``
    (None: nothing logged), the object's scene, the planner ``plan`` (default
    :func:`graspexp.planning.plan`) and the force-closure quality check."""
    seed = trial_seed(plain, loaded.model.name, trial) if seed is None else seed
    rec = NullRecorder() if recorder is None else recorder
    return TrialContext(
        plain, loaded.model, loaded.hulls, trial, seed, rec, loaded.scene, plan=plan, quality=fc_min_mu
    )


def round_context(
    plain: JobConfig,
    loaded: list[LoadedObject],
    round_index: int,
    seed: int,
    recorder: LogSink | None = None,
    scene: object | None = None,
    *,
    planner: ScenePlanner = plan_scene,
) -> RoundContext:
    """The context of round ``round_index`` (seed ``seed``) of the drawn objects ``loaded`` (by slot) under job
    config ``plain``: ``recorder`` (None: nothing logged), the round's Foxglove scene (None: none), the scene
    planner (default :func:`graspexp.planning.plan_scene`; a per-object planner through
    :func:`graspexp.planning.scene.per_object`) and the force-closure quality check."""
    rec = NullRecorder() if recorder is None else recorder
    objects = [RoundObject(o.model, o.hulls) for o in loaded]
    return RoundContext(plain, objects, round_index, seed, rec, scene, plan_scene=planner, quality=fc_min_mu)
