"""Scene types of a clutter round, registered by name (``mode.scene``): how the drawn objects come onto
the table. Each is a class implementing :class:`SceneType`, registered with :func:`register`, in a module
of this package or of another package that names the module under the entry-point group
:data:`ENTRY_POINT_GROUP` (as planners register theirs); a preset ``conf/mode/<name>.yaml`` (schema
``/schema_clutter_mode``) selects it. ``pile`` and ``packed`` are VGN's and GIGA's two scenes (Breyer et
al., CoRL 2020; Jiang et al., RSS 2021).
"""

import functools
import importlib
import pkgutil
from collections.abc import Callable, Sequence
from importlib.metadata import entry_points
from typing import Protocol

import numpy as np

from graspexp.config import JobConfig
from graspexp.config.errors import ConfigError
from graspexp.sim.round_scene import ClutterScene, RoundObject
from graspexp.sim.round_sim import RoundSim


class SceneType(Protocol):
    """How a round's drawn objects come onto the table. The round then settles them, takes away those
    outside ``mode.workspace_half_size_m`` and counts the rest as placed."""

    def fixtures(self, ts: ClutterScene, cfg: JobConfig) -> None:
        """Add the static bodies placing needs (into ``ts.fixtures``) before any object; may add none."""

    def place(self, sim: RoundSim, objects: Sequence[RoundObject], rng: np.random.Generator) -> None:
        """Add every object of ``objects`` that finds a place as body ``object_<slot>``
        (:func:`graspexp.sim.round_scene.add_clutter_object`), stepping ``sim`` as it needs; every draw from
        ``rng``."""


ENTRY_POINT_GROUP = "graspexp.scene_types"
"""Entry-point group of other packages' scene-type modules (``name = "package.module"``)."""
_REGISTERED: dict[str, type] = {}


def register(name: str) -> Callable[[type], type]:
    """Class decorator: register a :class:`SceneType` under ``name`` (the value of ``mode.scene``)."""

    def add(cls: type) -> type:
        if name in _REGISTERED and _REGISTERED[name] is not cls:
            raise ValueError(f"scene type {name!r} is registered twice ({_REGISTERED[name]} and {cls})")
        _REGISTERED[name] = cls
        return cls

    return add


@functools.cache
def _discover() -> None:
    """Import every module of this package and every module named under :data:`ENTRY_POINT_GROUP` once: each
    registers its scene types."""
    for info in pkgutil.iter_modules(__path__):
        importlib.import_module(f"{__name__}.{info.name}")
    for ep in entry_points(group=ENTRY_POINT_GROUP):
        try:
            importlib.import_module(ep.value.partition(":")[0])
        except ImportError as exc:
            raise ConfigError(
                f"scene type module {ep.value} (entry point {ep.name!r}) cannot be imported: {exc}"
            ) from None


def scene_type_names() -> list[str]:
    """The names of every registered scene type, sorted."""
    _discover()
    return sorted(_REGISTERED)


def scene_type(name: str) -> SceneType:
    """The scene type registered as ``name``; :class:`ConfigError` (one line naming the registered ones)
    otherwise."""
    _discover()
    if name not in _REGISTERED:
        raise ConfigError(
            f"mode.scene={name!r} is invalid: expected a registered scene type, one of "
            f"{', '.join(scene_type_names())} (graspexp.sim.scene_types)"
        )
    return _REGISTERED[name]()
