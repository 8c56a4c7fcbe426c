"""The per-scene object scale of a clutter round (``mode.object_scale``) and VGN's packed placement
(``mode.packed_placement=vgn``): the range [1, 1] draws nothing and leaves every object as it is (the rounds of
every preset unchanged); a scale is drawn per object from the round's generator; a scaled object's mesh, cloud
and collision shape (hulls, or the SDF mesh PhysX scales) are scaled and its mass kept, and it rests at its
scaled height; VGN's placement leaves no two objects inside one another and repeats for a seed."""

import dataclasses

import numpy as np
import pytest
from helpers.config import compose_cfg

from graspexp.core.seeding import rng_for
from graspexp.run.job_config import make_ready
from graspexp.run.objects import load_sim_object
from graspexp.sim.object_scale import draw_scales, scale_round_objects, scaled_model, scaled_shape
from graspexp.sim.round_scene import RoundObject, add_clutter_object, clutter_scene
from graspexp.sim.round_sim import RoundSim
from graspexp.sim.scene_types import scene_type
from graspexp.sim.trial import NullRecorder, plain_config


def _round(*overrides: str, names: tuple[str, ...]) -> tuple[object, list[RoundObject]]:
    """(plain job config, the round's objects by slot) of ``overrides`` on the primitives."""
    cfg = compose_cfg("dataset=primitives", *overrides)
    make_ready(cfg)
    plain = plain_config(cfg)
    loaded = {n: load_sim_object(cfg, n, plain) for n in set(names)}
    return plain, [RoundObject(loaded[n].model, loaded[n].hulls) for n in names]


def _sim(plain) -> RoundSim:
    ts = clutter_scene(plain.mode, plain)
    scene_type(plain.mode.scene).fixtures(ts, plain)
    timings = dict.fromkeys(("build", "settle", "plan", "quality", "execute", "log", "physics"), 0.0)
    return RoundSim(ts, plain, NullRecorder(), timings)


@pytest.mark.parametrize("mode", ["pile", "packed"])
def test_the_range_one_draws_nothing_and_leaves_every_object_as_it_is(mode):
    plain, objects = _round(f"mode={mode}", names=("can", "mug"))
    assert list(plain.mode.object_scale) == [1.0, 1.0] and plain.mode.packed_placement == "gap"
    before = list(objects)
    rng = np.random.default_rng(3)
    state = rng.bit_generator.state
    assert scale_round_objects(objects, plain.mode, rng) == [1.0, 1.0]
    assert rng.bit_generator.state == state  # no draw: the placement's draws stay those of every round so far
    assert all(a is b for a, b in zip(objects, before, strict=True))


def test_scales_are_drawn_per_object_from_the_round_generator():
    plain, _ = _round("mode=pile", "mode.object_scale=[0.8,1.0]", names=("can",))
    scales = draw_scales(plain.mode, 5, rng_for(11, "place"))
    assert np.array_equal(scales, rng_for(11, "place").uniform(0.8, 1.0, size=5))
    assert np.all((scales >= 0.8) & (scales < 1.0)) and len(set(scales.tolist())) == 5
    assert not np.array_equal(scales, draw_scales(plain.mode, 5, rng_for(12, "place")))
    fixed = dataclasses.replace(plain.mode, object_scale=[0.9, 0.9])
    rng = np.random.default_rng(0)
    state = rng.bit_generator.state
    assert np.array_equal(draw_scales(fixed, 3, rng), [0.9, 0.9, 0.9]) and rng.bit_generator.state == state


@pytest.mark.parametrize("name", ["can", "mug"])  # one convex hull; a closed mesh PhysX collides by its SDF
def test_a_scaled_object_scales_mesh_cloud_and_shape_keeps_its_mass_and_rests_at_its_height(name):
    plain, (obj,) = _round("mode=packed", names=(name,))
    s = 0.7
    model, shape = scaled_model(obj.model, s), scaled_shape(obj.shape, s)
    assert np.allclose(model.mesh.extents, s * obj.model.mesh.extents)
    assert np.allclose(model.points, s * obj.model.points) and np.array_equal(
        model.normals, obj.model.normals
    )
    assert model.mass_kg == obj.model.mass_kg and np.array_equal(model.area_mask, obj.model.area_mask)
    for (v, f), (v0, f0) in zip(shape.parts, obj.shape.parts, strict=True):
        assert np.allclose(v, s * v0, atol=1e-7) and np.array_equal(f, f0)
    assert shape.convex == obj.shape.convex and shape.file_scale == (1.0 if shape.convex else s)
    assert shape.mesh_file == obj.shape.mesh_file  # a closed mesh's cooked file is shared, PhysX scales it
    sim = _sim(plain)
    lo, hi = model.mesh.bounds
    pose = np.eye(4)
    pose[:3, 3] = [-(lo[0] + hi[0]) / 2, -(lo[1] + hi[1]) / 2, sim.ts.table_z + 0.005 - lo[2]]
    add_clutter_object(sim.ts, "object_0", model, shape, pose, plain)
    sim.track("object_0")
    sim.run(1.0)
    top = sim.ts.pose_of("object_0")[2, 3] + hi[2]
    assert top - sim.ts.table_z == pytest.approx(s * obj.model.mesh.extents[2], abs=0.002)


def test_pile_places_the_scaled_objects():
    plain, objects = _round("mode=pile", "mode.object_scale=[0.8,1.0]", names=("can", "box", "block"))
    sizes = [o.model.mesh.extents.copy() for o in objects]
    sim = _sim(plain)
    scene_type("pile").place(sim, objects, rng_for(5, "place"))
    scales = draw_scales(plain.mode, 3, rng_for(5, "place"))  # drawn first, before the drops
    for obj, size, s in zip(objects, sizes, scales, strict=True):
        assert np.allclose(obj.model.mesh.extents, s * size)  # the round plans and renders these
    assert sorted(sim.ts.bodies) == ["object_0", "object_1", "object_2"]


def _packed_vgn() -> tuple[list[str], dict[str, np.ndarray], list[float]]:
    """(placed bodies, their poses, the deepest overlap of any two of them, m) of one VGN packed placement of
    five convex primitives."""
    plain, objects = _round(
        "mode=packed",
        "mode.packed_placement=vgn",
        "mode.object_scale=[0.7,0.9]",
        "rot.drop_height_m=0.005",
        names=("box", "can", "block", "box", "can"),
    )
    sim = _sim(plain)
    scene_type("packed").place(sim, objects, rng_for(2, "place"))
    sim.ts.scene.physx_system.step()  # the contacts of a step after the last attempt (not of a removed body)
    seps = [
        p.separation
        for c in sim.ts.scene.physx_system.get_contacts()
        if {b.entity.name for b in c.bodies} <= set(sim.ts.bodies)
        for p in c.points
    ]
    return sorted(sim.ts.bodies), {n: sim.ts.pose_of(n) for n in sim.ts.bodies}, seps


def test_vgn_packed_placement_puts_no_object_inside_another_and_repeats():
    placed, poses, seps = _packed_vgn()
    assert 1 <= len(placed) <= 5
    assert min(seps, default=0.0) > -0.002  # objects may touch once settled, never sit inside one another
    placed2, poses2, _ = _packed_vgn()
    assert placed2 == placed and all(np.array_equal(poses[n], poses2[n]) for n in placed)
