"""The ``protocol`` group: a published benchmark protocol as one word (``protocol=giga``, ``protocol=vgn``). None
by default (nothing changes); an option selects the options and sets the keys its protocol fixes, those of
the scene from ``mode`` and of the planner from ``planner``; every key stays overridable; the camera presets
``giga_side`` and ``vgn_ring`` are options of their own; ``--cfg job`` shows the keys; the reference lists
them."""

import re
from pathlib import Path

import pytest
from helpers.cli import graspexp, ok
from helpers.config import compose_cfg
from omegaconf import OmegaConf

from graspexp.config import ConfigError, validate
from graspexp.config.reference import PROTOCOL_GROUP, PROTOCOL_PARTS, protocol_section, render
from graspexp.config.registry import CONF_DIR, group_options

PROTOCOLS = ("giga", "vgn")
SCENES = {"pile": ([0.8, 1.0], "gap"), "packed": ([0.7, 0.9], "vgn")}
"""mode -> (the protocols' object scale, their packed placement): VGN's simulation.py, both protocols."""


def test_no_protocol_by_default():
    assert group_options(PROTOCOL_GROUP) == list(PROTOCOLS)
    cfg = compose_cfg()
    assert cfg.dataset.name == "primitives" and cfg.mode.name == "collab" and cfg.gripper.name == "rg2"
    assert cfg.perception.camera.name == "d435" and cfg.sim.collision_method == "mesh"
    for mode in SCENES:
        mode_cfg = compose_cfg(f"mode={mode}").mode
        assert list(mode_cfg.object_scale) == [1.0, 1.0] and mode_cfg.packed_placement == "gap"
        assert compose_cfg(f"mode={mode}", "planner=vgn").planner.selection == "random"


@pytest.mark.parametrize("mode", SCENES)
@pytest.mark.parametrize("protocol", PROTOCOLS)
def test_a_protocol_sets_what_it_fixes(protocol, mode):
    cfg = compose_cfg(f"protocol={protocol}", f"mode={mode}")
    validate(cfg)
    camera = {"giga": "giga_side", "vgn": "vgn_ring"}[protocol]
    assert cfg.mode.name == mode and cfg.dataset.name == f"vgn_{mode}" and cfg.gripper.name == "panda"
    assert cfg.perception.camera.name == camera
    assert (cfg.mode.objects_per_round, cfg.mode.max_consecutive_failures) == (5, 2)
    scale, placement = SCENES[mode]
    assert list(cfg.mode.object_scale) == scale and cfg.mode.packed_placement == placement
    assert cfg.sim.collision_method == "coacd" and cfg.rot.drop_height_m == 0.005
    rule = {"giga": ("best", 0.5, 0.02), "vgn": ("random", None, 0.0)}[protocol]
    planner = compose_cfg(f"protocol={protocol}", f"mode={mode}", "planner=vgn").planner
    assert (planner.selection, planner.force_threshold, planner.wall_margin_m) == rule
    assert compose_cfg(f"protocol={protocol}").mode.name == "pile"  # the scene when none is chosen


def test_the_camera_presets():
    side = compose_cfg("perception/camera=giga_side").perception
    validate(compose_cfg("perception/camera=giga_side"))
    cam = side.camera
    assert (cam.width_px, cam.height_px, cam.fx_px, cam.fy_px) == (640, 480, 540.0, 540.0)
    assert (cam.cx_px, cam.cy_px) == (319.5, 239.5)  # the image centre
    assert (cam.distance_m, cam.elevation_deg, list(cam.azimuths_deg), cam.look_at_height_m) == (
        0.6,
        30.0,
        [-90.0],
        0.05,
    )
    assert side.depth_noise.enabled and side.depth_noise.model == "dex"
    ring = compose_cfg("perception/camera=vgn_ring").perception
    assert (ring.camera.width_px, ring.camera.fx_px, ring.camera.distance_m, ring.camera.elevation_deg) == (
        640,
        540.0,
        0.6,
        60.0,
    )
    assert list(ring.camera.azimuths_deg) == [0.0, 60.0, 120.0, 180.0, 240.0, 300.0]
    assert ring.camera.look_at_height_m == -0.05 and not ring.depth_noise.enabled


def test_every_key_a_protocol_sets_stays_overridable():
    cfg = compose_cfg(
        "protocol=giga",
        "mode=packed",
        "planner=vgn",
        "dataset=ycb",
        "gripper=rg2",
        "perception/camera=d435",
        "mode.object_scale=[1,1]",
        "mode.packed_placement=gap",
        "mode.objects_per_round=3",
        "mode.max_consecutive_failures=4",
        "planner.selection=random",
        "planner.force_threshold=null",
        "planner.wall_margin_m=0",
        "sim.collision_method=mesh",
        "rot.drop_height_m=0.02",
        "perception.depth_noise.model=nguyen",
    )
    assert (cfg.dataset.name, cfg.gripper.name, cfg.perception.camera.name) == ("ycb", "rg2", "d435")
    assert list(cfg.mode.object_scale) == [1.0, 1.0] and cfg.mode.packed_placement == "gap"
    assert (cfg.mode.objects_per_round, cfg.mode.max_consecutive_failures) == (3, 4)
    assert cfg.planner.selection == "random" and cfg.sim.collision_method == "mesh"
    assert cfg.planner.force_threshold is None and cfg.planner.wall_margin_m == 0.0
    assert cfg.rot.drop_height_m == 0.02 and cfg.perception.depth_noise.model == "nguyen"


def test_a_planner_without_protocol_keys_runs_under_the_protocol():
    cfg = compose_cfg("protocol=giga", "planner=optimal")
    validate(cfg)
    assert "selection" not in cfg.planner


def _options(group: str) -> set[str]:
    """The options of ``group``; for ``planner`` also the planners this package declares (pyproject.toml),
    installed in this environment or not yet."""
    names = set(group_options(group))
    pyproject = Path(__file__).resolve().parents[2] / "pyproject.toml"
    if group == "planner" and pyproject.is_file():
        section = (
            pyproject.read_text()
            .split('[project.entry-points."graspexp.planners"]', 1)[-1]
            .split("\n[", 1)[0]
        )
        names |= set(re.findall(r"^(\w+) = \"graspexp\.", section, flags=re.M))
    return names


def test_every_scene_or_planner_part_names_a_protocol_and_an_option():
    """A part that names no protocol or no option would never be chosen (its entry is optional): refused here."""
    base = Path(CONF_DIR) / PROTOCOL_GROUP
    for part, group in PROTOCOL_PARTS.items():
        paths = sorted((base / part).glob("*.yaml"))
        assert paths, part
        for path in paths:
            protocol, _, option = path.stem.partition("_")
            assert protocol in PROTOCOLS and option in _options(group), path


def test_a_protocol_with_a_single_object_mode_takes_the_pile_objects():
    cfg = compose_cfg("protocol=giga", "mode=bin")
    validate(cfg)
    assert cfg.dataset.name == "vgn_pile" and cfg.perception.camera.name == "giga_side"
    assert "object_scale" not in cfg.mode  # a single-object mode has no round to scale


def test_a_bad_scale_range_is_one_line():
    with pytest.raises(
        ConfigError, match=r"^mode\.object_scale=\[0\.9, 0\.8\] is invalid: expected \[min, max\]"
    ):
        validate(compose_cfg("mode=pile", "mode.object_scale=[0.9,0.8]"))


def test_the_reference_documents_the_protocols():
    section = "\n".join(protocol_section())
    assert section in render()
    for protocol in PROTOCOLS:
        assert f"| `protocol={protocol}` | always |" in section
        packed = next(
            ln for ln in section.splitlines() if ln.startswith(f"| `protocol={protocol}` | `mode=packed` |")
        )
        assert "`mode.object_scale=[0.7, 0.9]`" in packed and "`mode.packed_placement=vgn`" in packed
    assert "`perception/camera=giga_side`" in section and "`planner.selection=best`" in section


def test_cfg_job_shows_the_protocol_keys():
    out = ok(graspexp("protocol=giga", "mode=pile", "--cfg", "job")).stdout
    job = OmegaConf.create(out)
    assert job.mode.name == "pile" and list(job.mode.object_scale) == [0.8, 1.0]
    assert job.perception.camera.name == "giga_side" and job.perception.depth_noise.model == "dex"
    assert job.gripper.name == "panda" and job.mode.objects_per_round == 5
    assert OmegaConf.to_container(job.dataset, resolve=False)["name"] == "vgn_${oc.select:mode.scene,pile}"
    assert job.dataset.name == "vgn_pile"
