"""A job config made ready to run, the one way for a Hydra job and a tool alike: its values checked by the
config stage (:func:`graspexp.config.validate`, no file read), then the keys the gripper model gives filled
in by the grippers stage (:func:`graspexp.grippers.fill_gripper`: a URDF gripper's stroke and palm)."""

from collections.abc import Sequence

from omegaconf import DictConfig

from graspexp.config import validate
from graspexp.config.compose import compose_validated
from graspexp.grippers import fill_gripper


def make_ready(cfg: DictConfig) -> None:
    """Check ``cfg`` and fill in what its gripper model gives; :class:`graspexp.config.ConfigError` (one
    line) for a bad value or a gripper file that is not a parallel gripper."""
    validate(cfg)
    fill_gripper(cfg)


def compose_job(overrides: Sequence[str]) -> DictConfig:
    """The job config of Hydra ``overrides``, composed, checked and completed (:func:`make_ready`);
    :class:`graspexp.config.ConfigError` (one line) for any problem."""
    cfg = compose_validated(overrides)
    fill_gripper(cfg)
    return cfg
