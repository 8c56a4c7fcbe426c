"""A job config made ready to run, the one way for a Hydra job and a tool alike: its values checked by the
config stage (:func:`graspexp.config.validate`, no file read), then the keys the gripper model gives filled
in by the grippers stage (:func:`graspexp.grippers.fill_gripper`: a URDF gripper's stroke and palm); a clutter
mode's scene type must be registered (:mod:`graspexp.sim.scene_types`)."""

import functools
from collections.abc import Sequence

from omegaconf import DictConfig

from graspexp.config import validate
from graspexp.config.compose import compose_config, compose_validated
from graspexp.config.mode import is_clutter
from graspexp.config.registry import group_options
from graspexp.grippers import fill_gripper
from graspexp.sim.scene_types import scene_type


def make_ready(cfg: DictConfig) -> None:
    """Check ``cfg`` and fill in what its gripper model gives; :class:`graspexp.config.ConfigError` (one
    line) for a bad value or a gripper file that is not a parallel gripper."""
    validate(cfg)
    _check_scene(cfg)
    fill_gripper(cfg)


def compose_job(overrides: Sequence[str]) -> DictConfig:
    """The job config of Hydra ``overrides``, composed, checked and completed (:func:`make_ready`);
    :class:`graspexp.config.ConfigError` (one line) for any problem."""
    cfg = compose_validated(overrides)
    _check_scene(cfg)
    fill_gripper(cfg)
    return cfg


def _check_scene(cfg: DictConfig) -> None:
    """A clutter mode's ``mode.scene`` names a registered scene type (:class:`ConfigError` naming them)."""
    if is_clutter(cfg.mode):
        scene_type(cfg.mode.scene)


@functools.cache
def clutter_modes() -> tuple[str, ...]:
    """The options of the ``mode`` group that run clutter rounds (their schema is
    :class:`graspexp.config.mode.ClutterModeConfig`: ``pile``, ``packed``, and any preset added beside them),
    sorted."""
    return tuple(m for m in group_options("mode") if is_clutter(compose_config([f"mode={m}"]).mode))
