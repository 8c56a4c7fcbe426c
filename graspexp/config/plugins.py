"""Planner plugins: what a planner package exposes, and their discovery through Python entry points.

A planner is a :class:`PlannerPlugin` registered under the entry-point group :data:`ENTRY_POINT_GROUP`;
the entry point's name is the planner's name (``planner=NAME``, ``planner.name``). The built-in planners
register the same way, in graspexp's own ``pyproject.toml``. A plugin's config schema and constraints
travel with it: they are stored in Hydra's ConfigStore by :func:`graspexp.config.registry.register_configs`
and checked by :func:`graspexp.config.validate`. This module imports no planner code: ``plan`` is resolved
by :mod:`graspexp.planning.registry` when a planner runs.

A learned planner (a network run from published weights) declares itself with :class:`Learned`
(``PlannerPlugin.learned``): the gripper it was trained for, its checkpoints, the optional extra it needs and
its column label. The shared code iterates over :func:`learned_planners` (the results pages' learned sweeps
and columns, ``bench.learned``, ``download_checkpoint``, ``nox -s learned``), so a new learned planner is its
plugin module, its entry point and its config preset, and no edit elsewhere.
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from importlib.metadata import EntryPoint, entry_points
from typing import Any

from graspexp.config.planner.base import PlannerConfig
from graspexp.core.checkpoints import Checkpoint

ENTRY_POINT_GROUP = "graspexp.planners"


class PluginError(RuntimeError):
    """A planner plugin that cannot be used (unknown name, failed import, malformed object); one line
    naming the planner, its package and the fix."""


@dataclass(frozen=True)
class Learned:
    """What a learned planner brings beside its plan function (:attr:`PlannerPlugin.learned`).

    The results pages run every learned planner on the gripper it was trained for (the camera page's
    column, the learned page, the camera clutter page) and on the paper's gripper (a transfer, the learned
    page); ``python -m graspexp bench.learned`` times its plans (its ``plan`` logs the CPU seconds of its
    two steps in ``Grasp.extras``: ``fuse_cpu_s``, ``infer_cpu_s``).
    """

    gripper: str
    """The gripper it was trained for (``gripper=NAME``): the pages and ``bench.learned`` run it with it."""
    checkpoints: tuple[Checkpoint, ...] = ()
    """The published checkpoints it loads: ``python -m graspexp download_checkpoint NAME`` fetches each,
    from any of the folders of ``$GRASPEXP_CHECKPOINTS`` (:mod:`graspexp.core.checkpoints`)."""
    extra: str = "learned"
    """The optional extra of its package that installs what it imports (torch, Open3D, ...)."""
    column: str = ""
    """Its column label on the camera page (:func:`column_label`); '' for ``NAME, gripper=G, camera views``."""

    def column_label(self, name: str) -> str:
        """The camera page's column label of the planner ``name``."""
        return self.column or f"{name}, gripper={self.gripper}, camera views"


@dataclass(frozen=True)
class PlannerPlugin:
    """What a planner package exposes under the ``graspexp.planners`` entry-point group.

    plan : the planner, ``PlanRequest -> PlanResult`` (:mod:`graspexp.planning.request`), or its import
        path ``"module:function"`` (imported only when the planner runs).
    config : the planner's schema, a dataclass deriving from :class:`PlannerConfig`; its field defaults
        are the option ``planner=NAME`` unless ``conf/planner/NAME.yaml`` gives a preset.
    constraints : allowed values of every field of ``config``, inherited ones included
        (``{**BASE_CONSTRAINTS, ...}``; see :mod:`graspexp.config.constraints`).
    version : the planner's version, recorded with every result; default the package's version.
    needs_observation : the planner reads the depth camera's output (``PlanRequest.observation``): the
        trial renders the camera for it even with ``perception.source=truth`` (the camera extra must be
        installed).
    plan_scene : optional, the planner for a whole scene at once, ``SceneRequest -> SceneResult``
        (:mod:`graspexp.planning.scene`: one fusion and one forward pass for every object of a clutter
        round), or its import path ``"module:function"``; None: the round plans each object with ``plan``.
    unavailable : optional ``() -> str``: '' when the planner can run on this machine, else one line
        naming what is missing and the command that brings it (an optional extra, a checkpoint); called
        when a config selects the planner, so the run stops before its first trial.
    learned : for a learned planner (a network from published weights), what it brings (:class:`Learned`);
        None for any other planner.
    """

    plan: Callable[..., Any] | str
    config: type[PlannerConfig]
    constraints: Mapping[str, list]
    version: str = ""
    needs_observation: bool = False
    plan_scene: Callable[..., Any] | str | None = None
    unavailable: Callable[[], str] | None = None
    learned: Learned | None = None


@dataclass(frozen=True)
class LoadedPlanner:
    """A discovered planner: its name, the package that provides it and its plugin object."""

    name: str
    package: str
    """Distribution name and version, e.g. ``top-down-planner 0.1.0``."""
    entry_point: str
    """``module:attribute`` of the entry point."""
    plugin: PlannerPlugin
    package_version: str = "unknown"

    @property
    def version(self) -> str:
        """The plugin's own version, else its package's."""
        return self.plugin.version or self.package_version


def _package(ep: EntryPoint) -> str:
    dist = getattr(ep, "dist", None)
    return f"{dist.metadata['Name']} {dist.version}" if dist is not None else "an unknown package"


def _entry_points() -> dict[str, EntryPoint]:
    found: dict[str, EntryPoint] = {}
    for ep in entry_points(group=ENTRY_POINT_GROUP):
        if ep.name in found and found[ep.name].value != ep.value:
            raise PluginError(
                f"planner {ep.name!r} is registered twice ({_package(found[ep.name])}: {found[ep.name].value}; "
                f"{_package(ep)}: {ep.value}): uninstall one of the two packages"
            )
        found[ep.name] = ep
    return found


def planner_names() -> list[str]:
    """The names of every installed planner (entry points of :data:`ENTRY_POINT_GROUP`), sorted; nothing
    is imported."""
    return sorted(_entry_points())


def _load(ep: EntryPoint) -> LoadedPlanner:
    where = f"planner {ep.name!r} of {_package(ep)} (entry point {ep.value})"
    try:
        plugin = ep.load()
    except Exception as exc:
        raise PluginError(f"{where} failed to load: {type(exc).__name__}: {exc}") from exc
    if not isinstance(plugin, PlannerPlugin):
        raise PluginError(f"{where} is a {type(plugin).__name__}: expected a graspexp.config.PlannerPlugin")
    schema = plugin.config
    if not (
        dataclasses.is_dataclass(schema) and isinstance(schema, type) and issubclass(schema, PlannerConfig)
    ):
        raise PluginError(f"{where}: config={schema!r} is not a dataclass deriving from PlannerConfig")
    unconstrained = [f.name for f in dataclasses.fields(schema) if f.name not in plugin.constraints]
    if unconstrained:
        raise PluginError(
            f"{where}: constraints lacks {', '.join(unconstrained)}: declare every config field"
        )
    if not (callable(plugin.plan) or (isinstance(plugin.plan, str) and ":" in plugin.plan)):
        raise PluginError(f"{where}: plan={plugin.plan!r} is neither a function nor 'module:function'")
    scene = plugin.plan_scene
    if not (scene is None or callable(scene) or (isinstance(scene, str) and ":" in scene)):
        raise PluginError(f"{where}: plan_scene={scene!r} is neither None, a function nor 'module:function'")
    if plugin.learned is not None and not isinstance(plugin.learned, Learned):
        raise PluginError(
            f"{where}: learned={plugin.learned!r} is neither None nor a graspexp.config.Learned"
        )
    dist = getattr(ep, "dist", None)
    return LoadedPlanner(
        ep.name, _package(ep), ep.value, plugin, dist.version if dist is not None else "unknown"
    )


@functools.cache
def load_planners() -> dict[str, LoadedPlanner | PluginError]:
    """Every installed planner by name, or the :class:`PluginError` that says why it cannot be used."""
    out: dict[str, LoadedPlanner | PluginError] = {}
    for name, ep in sorted(_entry_points().items()):
        try:
            out[name] = _load(ep)
        except PluginError as exc:
            out[name] = exc
    if not any(isinstance(p, LoadedPlanner) and p.package.startswith("graspexp ") for p in out.values()):
        raise PluginError(
            f"no built-in planner is registered under the entry-point group {ENTRY_POINT_GROUP!r}: "
            "graspexp's install metadata is stale; reinstall it (pip install -e .)"
        )
    return out


def get_plugin(name: str) -> LoadedPlanner:
    """The planner called ``name``; :class:`PluginError` for an unknown name (listing the valid ones) or a
    broken plugin (naming its package)."""
    found = load_planners().get(name)
    if found is None:
        raise PluginError(
            f"planner.name={name!r} is unknown: expected one of {', '.join(sorted(load_planners()))} "
            f"(a planner package registers itself under the entry-point group {ENTRY_POINT_GROUP!r}; "
            "is it installed in this environment?)"
        )
    if isinstance(found, PluginError):
        raise found
    return found


def learned_planners() -> dict[str, Learned]:
    """Every installed planner that declares itself learned (:attr:`PlannerPlugin.learned`), by name in
    name order; a plugin that fails to load is left out (selecting it says why)."""
    return {
        name: found.plugin.learned
        for name, found in sorted(load_planners().items())
        if isinstance(found, LoadedPlanner) and found.plugin.learned is not None
    }
