"""Config tier: every option of every group composes and validates; bad overrides are one clear line."""

import dataclasses
from pathlib import Path

import pytest
from helpers.cli import graspexp
from helpers.config import compose_cfg
from helpers.objects import write_urdf_gripper
from omegaconf import OmegaConf

from graspexp.config import AntipodalConfig, ConfigError, JobConfig, OptimalConfig, sim, validate
from graspexp.config.compose import expand_sweeps
from graspexp.config.constraints import accepts, describe
from graspexp.config.plugins import load_planners
from graspexp.config.registry import CONF_DIR, group_options
from graspexp.config.validate import NOT_CONFIG, SCHEMA_CONSTRAINTS

REPO = Path(__file__).resolve().parents[2]
GROUPS = {
    g.name: sorted(p.stem for p in g.glob("*.yaml"))
    for g in Path(CONF_DIR).iterdir()
    if g.is_dir() and g.name != "hydra"
}


@pytest.mark.parametrize(("group", "option"), [(g, o) for g, opts in GROUPS.items() for o in opts])
def test_every_option_of_every_group_composes_and_validates(group, option, tmp_path):
    extra = [f"gripper.urdf={write_urdf_gripper(tmp_path)}"] if (group, option) == ("gripper", "urdf") else []
    cfg = compose_cfg(f"{group}={option}", *extra)
    validate(cfg)
    if group == "protocol":  # a protocol sets other groups' keys: it has no node of its own
        return
    if group not in ("cost", "sim"):  # single-option groups without a name field
        # dataset=vgn is the field's test objects of the chosen scene (vgn_pile unless mode.scene=packed)
        assert cfg[group].name == ("vgn_pile" if (group, option) == ("dataset", "vgn") else option)


def test_groups_are_the_documented_ones():
    assert {"dataset", "mode", "rot", "gripper", "planner", "cost", "sim"} <= set(GROUPS)
    assert GROUPS["gripper"] == ["panda", "rg2", "robotiq_2f85", "urdf"]
    assert {"optimal", "optimal_plus", "antipodal", "obb", "random"} <= set(GROUPS["planner"])


def test_paper_defaults():
    cfg = compose_cfg()
    assert (cfg.dataset.name, cfg.mode.name, cfg.rot.name, cfg.gripper.name) == (
        "primitives",
        "collab",
        "z",
        "rg2",
    )
    assert cfg.planner.m == 256 and cfg.planner.k == "auto" and cfg.trials == 10
    assert (cfg.gripper.max_width_m, cfg.gripper.grip_force_n) == (0.110, 40.0)
    c = cfg.cost
    assert (c.angle_weight, c.angle_target_deg, c.angle_offset, c.angle_divisor) == (0.1, 90.0, 0.5, 8.0)
    assert (c.distance_numerator_mm2, c.distance_offset_mm2, c.table_offset, c.table_beta_divisor) == (
        20,
        1,
        0.05,
        2,
    )


@pytest.mark.parametrize(
    ("override", "message"),
    [
        ("trials=0", "trials=0 is invalid: expected an integer in [1, 100000]"),
        (
            "gripper.min_width_m=0.2",
            "gripper.min_width_m=0.2 is invalid: expected < gripper.max_width_m=0.11",
        ),
        ("planner.k=0", "planner.k=0 is invalid: expected one of auto or an integer in [1, 64]"),
        (
            "sim.approach_speed_mps=0",
            "sim.approach_speed_mps=0.0 is invalid: expected a number in (0, 10] m/s",
        ),
        ("sim.coacd_threshold=-1", "sim.coacd_threshold=-1.0 is invalid: expected a number in [0.01, 1]"),
        ("sim.close_s=-1", "sim.close_s=-1.0 is invalid: expected a number in (0, 60] s"),
        (
            "gripper.finger_mass_kg=-1",
            "gripper.finger_mass_kg=-1.0 is invalid: expected a number in (0, 10] kg",
        ),
        (
            "gripper.palm_size_m=[-1,-1,-1]",
            "gripper.palm_size_m=[-1.0, -1.0, -1.0] is invalid: expected a list of 3 values, each a number in "
            "(0, 1] m",
        ),
        (
            "gripper.grip_force_n=1e30",
            "gripper.grip_force_n=1e+30 is invalid: expected a number in (0, 1000] N",
        ),
        (
            "+sim.bar=2",
            "sim.bar=2 is invalid: 'bar' is not a key of group 'sim'; expected one of timestep_s, .*",
        ),
        (
            "planner.main_axis=diagonal",
            "planner.main_axis='diagonal' is invalid: expected one of object, area",
        ),
    ],
)
def test_out_of_range_values_name_the_key(override, message):
    escaped = message.replace("(", r"\(").replace(")", r"\)").replace("[", r"\[").replace("+", r"\+")
    with pytest.raises(ConfigError, match="^" + escaped + "$"):
        validate(compose_cfg(override))


@pytest.mark.parametrize(
    ("args", "line"),
    [
        (
            ["mode=foo"],
            "graspexp: error: In 'config': Could not find 'mode/foo'; Available options in 'mode': bin, collab, packed, pile",
        ),
        (["mode.nme=3"], "graspexp: error: Could not override 'mode.nme'. Key 'nme' not in 'ModeConfig'"),
        (
            ["-m", "rot=z,q"],
            "graspexp: error: In 'config': Could not find 'rot/q'; Available options in 'rot': xyz, z",
        ),
        (["trials=-2"], "graspexp: error: trials=-2 is invalid: expected an integer in [1, 100000]"),
        (
            ["+foo=1"],
            "graspexp: error: foo=1 is invalid: 'foo' is not a key of the job config; expected one of "
            "dataset, mode, rot, gripper, planner, cost, sim, perception, trials, seed, objects, record, live, live_port, progress, objective",
        ),
    ],
)
def test_bad_override_is_one_line_and_exit_2(args, line):
    proc = graspexp(*args)
    assert proc.returncode == 2
    assert proc.stderr.strip() == line
    assert "Traceback" not in proc.stderr


def test_cfg_job_prints_the_composed_config():
    args = ["--cfg", "job", "mode=bin", "rot=xyz", "dataset=linemod", "gripper=robotiq_2f85"]
    proc = graspexp(*args)
    assert proc.returncode == 0, proc.stderr
    assert "name: robotiq_2f85" in proc.stdout and "max_width_m: 0.085" in proc.stdout
    assert "name: linemod" in proc.stdout and "pull_back_m: 0.1" in proc.stdout


def test_expand_sweeps_gives_every_combination_in_launch_order_without_hydra_keys():
    assert expand_sweeps(["mode=collab,bin", "rot=z,xyz", "trials=2", "hydra.sweep.dir=x", "+a.b=[1,2]"]) == [
        ["mode=collab", "rot=z", "trials=2", "+a.b=[1,2]"],
        ["mode=collab", "rot=xyz", "trials=2", "+a.b=[1,2]"],
        ["mode=bin", "rot=z", "trials=2", "+a.b=[1,2]"],
        ["mode=bin", "rot=xyz", "trials=2", "+a.b=[1,2]"],
    ]


def test_every_key_of_every_schema_has_a_constraint():
    for schema, constraints in SCHEMA_CONSTRAINTS.items():
        keys = {f.name for f in dataclasses.fields(schema) if not dataclasses.is_dataclass(f.type)}
        planner = {"planner"} if schema is JobConfig else set()  # checked against the planner's own schema
        assert keys - NOT_CONFIG - planner == set(constraints), schema.__name__
    for name, found in load_planners().items():
        assert {f.name for f in dataclasses.fields(found.plugin.config)} == set(found.plugin.constraints), (
            name
        )


def test_each_planner_has_its_own_schema_and_the_names_come_from_the_registry():
    assert group_options("planner") == sorted(load_planners())
    assert type(OmegaConf.to_object(compose_cfg("planner=antipodal").planner)) is AntipodalConfig
    assert type(OmegaConf.to_object(compose_cfg("planner=optimal_literal").planner)) is OptimalConfig
    with pytest.raises(
        ConfigError, match="^planner.seed=1 is invalid: 'seed' is not a key of group 'planner'"
    ):
        validate(compose_cfg("planner=antipodal", "+planner.seed=1"))  # it would be ignored
    with pytest.raises(Exception, match=r"Could not find 'planner/schema_planner_optimal'"):
        compose_cfg("planner=schema_planner_optimal")  # the schemas are not options of the group
    with pytest.raises(
        ConfigError,
        match=r"^planner.name has no value: choose an option, planner= one of antipodal, antipodal_area, antipodal_area_pads, antipodal_view, giga, obb,",
    ):
        validate(compose_cfg("planner.name=???"))
    with pytest.raises(
        ConfigError,
        match=r"^planner.name='nope' is unknown: expected one of antipodal, antipodal_area, antipodal_area_pads, antipodal_view, giga, obb,",
    ):
        validate(compose_cfg("planner.name=nope"))


def test_optional_slip_threshold_accepts_null_and_positive_values_only():
    alternatives = sim.CONSTRAINTS["slip_threshold_m"]
    assert accepts(alternatives, None) and accepts(alternatives, 0.02)
    assert not accepts(alternatives, 0.0) and not accepts(alternatives, float("nan"))
    assert describe(alternatives) == "null or a number in (0, 1] m"
