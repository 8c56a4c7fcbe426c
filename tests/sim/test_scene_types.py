"""Scene types registered by name (:mod:`graspexp.sim.scene_types`): pile and packed are two implementations
of one protocol, and a new scene type is one class (here, in this file) selected by ``mode.scene`` (a preset
``conf/mode/<name>.yaml`` would set it)."""

import numpy as np
import pytest
from helpers.config import compose_cfg

from graspexp.config import ConfigError
from graspexp.core.bodies import clutter_body
from graspexp.core.geometry import make_pose
from graspexp.core.seeding import round_seed
from graspexp.planning import plan
from graspexp.planning.scene import per_object
from graspexp.run.job_config import make_ready
from graspexp.run.objects import load_sim_object, round_context
from graspexp.sim.round_scene import add_clutter_object
from graspexp.sim.rounds import run_round
from graspexp.sim.scene_types import register, scene_type, scene_type_names
from graspexp.sim.trial import plain_config


@register("in_a_row")
class InARow:
    """The objects upright in a row along x, 2 cm apart, centred on y = 0 (a new scene type: this class)."""

    def fixtures(self, ts, cfg) -> None:
        pass

    def place(self, sim, objects, rng) -> None:
        x = -0.12
        for slot, obj in enumerate(objects):
            lo, hi = obj.model.mesh.bounds
            pose = make_pose(np.eye(3), [x - lo[0], -(lo[1] + hi[1]) / 2, sim.ts.table_z - lo[2] + 0.002])
            add_clutter_object(sim.ts, clutter_body(slot), obj.model, obj.shape, pose, sim.cfg)
            x += hi[0] - lo[0] + 0.02


def test_pile_and_packed_are_registered_scene_types():
    assert {"pile", "packed"} <= set(scene_type_names())
    for name in ("pile", "packed"):
        assert callable(scene_type(name).place) and callable(scene_type(name).fixtures)


def test_a_new_scene_type_is_a_class_selected_by_mode_scene():
    cfg = compose_cfg("mode=packed", "dataset=primitives", "mode.objects_per_round=3", "mode.scene=in_a_row")
    make_ready(cfg)
    plain = plain_config(cfg)
    loaded = [load_sim_object(cfg, name, plain) for name in ("can", "box", "mug")]
    res = run_round(round_context(plain, loaded, 0, round_seed(plain, 0), planner=per_object(plan)))
    assert res.placed == ["object_0", "object_1", "object_2"], res  # every object stood in the row
    assert res.attempts and res.end != "error", res.error


def test_an_unknown_scene_type_is_one_line_naming_the_registered_ones():
    cfg = compose_cfg("mode=pile", "dataset=primitives", "mode.scene=heap")
    with pytest.raises(
        ConfigError, match=r"mode.scene='heap' is invalid: expected a registered scene type.*pile"
    ):
        make_ready(cfg)
