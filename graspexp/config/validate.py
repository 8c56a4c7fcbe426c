"""Checks on a composed job config that the type system cannot express.

Ranges are declared as data (dotted key -> constraint), in the manner of scikit-learn's
``_parameter_constraints``; every message names the dotted key and the bad value.
"""

import math
from collections.abc import Callable

from omegaconf import DictConfig, OmegaConf


class ConfigError(ValueError):
    """A composed config holds a value the job cannot use."""


def _positive(v: float) -> bool:
    return v > 0 and math.isfinite(v)


def _non_negative(v: float) -> bool:
    return v >= 0 and math.isfinite(v)


def _k_value(v: object) -> bool:
    return v == "auto" or (isinstance(v, int) and not isinstance(v, bool) and v >= 1)


CONSTRAINTS: dict[str, tuple[Callable[[object], bool], str]] = {
    "dataset.name": (lambda v: v in ("ycb", "linemod", "primitives"), "one of ycb, linemod, primitives"),
    "dataset.density_kg_m3": (_positive, "a positive number"),
    "mode.name": (lambda v: v in ("collab", "bin"), "one of collab, bin"),
    "mode.support_height_m": (_positive, "a positive number"),
    "mode.hold_s": (_positive, "a positive number"),
    "mode.pull_back_m": (_non_negative, "a non-negative number"),
    "mode.lift_m": (_non_negative, "a non-negative number"),
    "rot.name": (lambda v: v in ("z", "xyz"), "one of z, xyz"),
    "rot.drop_height_m": (_non_negative, "a non-negative number"),
    "gripper.max_width_m": (_positive, "a positive number"),
    "gripper.min_width_m": (_non_negative, "a non-negative number"),
    "gripper.grip_force_n": (_positive, "a positive number"),
    "gripper.finger_length_m": (_positive, "a positive number"),
    "gripper.finger_width_m": (_positive, "a positive number"),
    "gripper.finger_thickness_m": (_positive, "a positive number"),
    "gripper.pad_friction": (_non_negative, "a non-negative number"),
    "planner.k": (_k_value, "'auto' or a positive integer"),
    "planner.k_max": (lambda v: v >= 1, "a positive integer"),
    "planner.m": (lambda v: v >= 1, "a positive integer"),
    "planner.n_points": (lambda v: v >= 16, "an integer >= 16"),
    "planner.main_axis": (lambda v: v in ("object", "area"), "one of object, area"),
    "planner.pose_axis": (lambda v: v in ("object", "area"), "one of object, area"),
    "planner.cluster_radius": (lambda v: v in ("max", "rms"), "one of max, rms"),
    "planner.grasp_point": (lambda v: v in ("centre", "section_middle"), "one of centre, section_middle"),
    "planner.auto_k_stroke_fraction": (_positive, "a positive number"),
    "planner.n_candidates": (lambda v: v >= 1, "a positive integer"),
    "planner.n_approach": (lambda v: v >= 1, "a positive integer"),
    "planner.friction_coef": (_non_negative, "a non-negative number"),
    "planner.approach_tilt_weight": (_non_negative, "a non-negative number"),
    "planner.collision_margin_m": (_non_negative, "a non-negative number"),
    "planner.width_clearance_m": (_non_negative, "a non-negative number"),
    "planner.com_weight": (_non_negative, "a non-negative number"),
    "planner.sphere_radius_m": (_positive, "a positive number"),
    "planner.width_margin": (_non_negative, "a non-negative number"),
    "sim.timestep_s": (lambda v: 0 < v <= 0.02, "a step in (0, 0.02] s"),
    "sim.solver_position_iterations": (lambda v: v >= 1, "a positive integer"),
    "sim.log_rate_hz": (_positive, "a positive number"),
    "sim.slip_threshold_m": (_positive, "a positive number or null (off)"),
    "sim.max_redrops": (_non_negative, "a non-negative integer"),
    "trials": (lambda v: v >= 1, "a positive integer"),
    "perception.noise.trans_mm": (_non_negative, "a non-negative number"),
    "perception.noise.rot_deg": (_non_negative, "a non-negative number"),
}


def validate(cfg: DictConfig) -> None:
    """Raise :class:`ConfigError` naming the first dotted key whose value is out of range."""
    for key, (ok, expected) in CONSTRAINTS.items():
        value = OmegaConf.select(cfg, key, default=None)
        if value is None:
            continue
        if not ok(value):
            raise ConfigError(f"{key}={value!r} is invalid: expected {expected}")
    name = OmegaConf.select(cfg, "planner.name", default=None)
    if name is not None:
        from graspexp.planning.registry import PLANNERS

        if name not in PLANNERS:
            raise ConfigError(
                f"planner.name={name!r} is invalid: expected one of {', '.join(sorted(PLANNERS))}"
            )
    g = cfg.get("gripper")
    if g is not None and g.min_width_m >= g.max_width_m:
        raise ConfigError(
            f"gripper.min_width_m={g.min_width_m!r} is invalid: must be below gripper.max_width_m={g.max_width_m!r}"
        )
    if g is not None and len(g.palm_size_m) != 3:
        raise ConfigError(
            f"gripper.palm_size_m={list(g.palm_size_m)!r} is invalid: expected [x, y, z] in metres"
        )
