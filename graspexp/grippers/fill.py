"""The keys of a job config that its gripper model gives: a URDF gripper's stroke and palm size come from
its file, so the file is read here, when a job (or a tool) is about to use the gripper, not while the
config's values are checked (:func:`graspexp.config.validate` reads no files and writes nothing)."""

from omegaconf import DictConfig, OmegaConf

from graspexp.config.errors import ConfigError
from graspexp.grippers.geometry import GripperGeometry, hand_of
from graspexp.grippers.urdf import UrdfError


def fill_gripper(cfg: DictConfig) -> None:
    """Read the URDF of ``cfg.gripper.urdf`` (a job config already validated; a box model is left as it is)
    and set an unset ``gripper.max_width_m`` to its stroke (a set one must not exceed it) and an unset
    ``gripper.palm_size_m`` to the palm's bounding box, m. :class:`ConfigError` in one line naming the key
    and the file when the file is not a parallel gripper."""
    node = OmegaConf.select(cfg, "gripper", throw_on_missing=False)
    if not isinstance(node, DictConfig) or node.get("urdf") is None:
        return
    try:
        hand = hand_of(node)
    except UrdfError as exc:
        raise ConfigError(f"gripper.urdf={node.urdf!r} is invalid: {exc}") from None
    if OmegaConf.is_missing(node, "palm_size_m"):
        node.palm_size_m = list(GripperGeometry.of_hand(hand).palm_size_m)
    if OmegaConf.is_missing(node, "max_width_m"):
        node.max_width_m = hand.max_width_m
    elif node.max_width_m > hand.max_width_m + 1e-9:
        raise ConfigError(
            f"gripper.max_width_m={node.max_width_m!r} is invalid: expected <= {hand.max_width_m:.6g} m, the "
            f"stroke of the finger joints of {node.urdf}"
        )
    if not node.min_width_m < node.max_width_m:
        raise ConfigError(
            f"gripper.min_width_m={node.min_width_m!r} is invalid: expected < gripper.max_width_m="
            f"{node.max_width_m!r} (the stroke of {node.urdf})"
        )
