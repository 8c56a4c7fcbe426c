"""Shared fixtures: composed configs, the real-mesh data root, an isolated convex-decomposition cache, a
small URDF gripper written at test time."""

import os
from pathlib import Path

import numpy as np
import pytest
from omegaconf import DictConfig

from graspexp.config.compose import compose_config

REPO = Path(__file__).resolve().parent.parent


def shared_data_root() -> Path:
    """``GRASPEXP_DATA`` if set, else ``../shared/datasets`` beside the checkout."""
    return Path(os.environ.get("GRASPEXP_DATA", REPO.parent / "shared" / "datasets"))


def compose_cfg(*overrides: str) -> DictConfig:
    """The job config composed from ``conf/`` with Hydra overrides (no run directory, no logging)."""
    return compose_config(list(overrides))


@pytest.fixture(scope="session", autouse=True)
def _coacd_cache(tmp_path_factory: pytest.TempPathFactory) -> None:
    """Keep convex decompositions out of the user's cache unless CI names one (GRASPEXP_CACHE)."""
    if "GRASPEXP_CACHE" not in os.environ:
        os.environ["GRASPEXP_CACHE"] = str(tmp_path_factory.mktemp("coacd-cache"))


@pytest.fixture(scope="session")
def data_root() -> Path:
    """The shared real meshes (``ycb/`` and ``linemod/``); tests that need them skip when they are absent."""
    root = shared_data_root()
    if not (root / "ycb").is_dir() or not (root / "linemod").is_dir():
        pytest.skip(f"real meshes (ycb/, linemod/) not found at {root}: set GRASPEXP_DATA")
    return root


def strictly_valid(source) -> dict[str, int]:
    """Validate every message of an MCAP log (binary stream) against its declared schema with independent
    tools: protobuf decoding with the schema stored in the file (every byte a field of that schema), and
    ``jsonschema`` for JSON channels. Returns the message count per topic."""
    import json

    import jsonschema
    from mcap.reader import make_reader
    from mcap_protobuf.decoder import DecoderFactory

    counts: dict[str, int] = {}
    decoders = DecoderFactory()
    validators: dict[int, jsonschema.protocols.Validator] = {}
    for schema, channel, message in make_reader(source, validate_crcs=True).iter_messages():
        counts[channel.topic] = counts.get(channel.topic, 0) + 1
        if channel.message_encoding == "protobuf":
            assert schema.encoding == "protobuf" and schema.name.startswith("foxglove."), schema.name
            body = decoders.decoder_for("protobuf", schema)(message.data)
            assert body.ByteSize() == len(message.data), channel.topic
        else:
            assert (channel.message_encoding, schema.encoding) == ("json", "jsonschema"), channel.topic
            assert schema.name.startswith("graspexp."), schema.name
            if schema.id not in validators:
                doc = json.loads(schema.data)
                cls = jsonschema.validators.validator_for(doc)
                cls.check_schema(doc)
                validators[schema.id] = cls(doc)
            validators[schema.id].validate(json.loads(message.data))
    return counts


def write_urdf_gripper(
    folder: Path,
    *,
    palm_size_m: tuple[float, float, float] = (0.045, 0.15, 0.06),
    finger_size_m: tuple[float, float, float] = (0.022, 0.01, 0.08),
    upper_m: float = 0.055,
    curved_tip: bool = True,
) -> Path:
    """A parallel gripper URDF in ``folder`` shaped like the RG2 box model: a palm box (link ``hand``, its
    front face at z = 0), two prismatic fingers (``left_joint`` along +y, ``right_joint`` along -y, limits
    [0, ``upper_m``], pads touching at q = 0) made of a box each, and with ``curved_tip`` a fingertip
    mesh (``tip.stl``: half a cylinder, written with trimesh) at the top of each finger. Returns the file."""
    import trimesh

    px, py, pz = palm_size_m
    fx, ft, fl = finger_size_m
    tip = ""
    if curved_tip:  # a half cylinder along x, radius ft/2, flat face down: a rounded fingertip
        a = np.linspace(0.0, np.pi, 13)
        arc = np.stack([ft / 2 * np.cos(a), ft / 2 * np.sin(a)], axis=1)
        pts = np.concatenate([np.insert(arc, 0, x, axis=1) for x in (-fx / 2, fx / 2)])
        trimesh.convex.convex_hull(pts).export(folder / "tip.stl")
    links, joints = [], []
    for name, sign in (("left", 1.0), ("right", -1.0)):
        if curved_tip:
            tip = (
                f'<collision><origin xyz="0 {sign * ft / 2} {fl}"/>'
                '<geometry><mesh filename="tip.stl"/></geometry></collision>'
            )
        links.append(
            f'<link name="{name}_finger"><collision><origin xyz="0 {sign * ft / 2} {fl / 2}"/>'
            f'<geometry><box size="{fx} {ft} {fl}"/></geometry></collision>{tip}</link>'
        )
        joints.append(
            f'<joint name="{name}_joint" type="prismatic"><parent link="hand"/><child link="{name}_finger"/>'
            f'<axis xyz="0 {sign:g} 0"/><limit lower="0" upper="{upper_m}" effort="100" velocity="1"/></joint>'
        )
    text = (
        '<?xml version="1.0"?><robot name="test_gripper"><link name="world_mount"/>'
        f'<link name="hand"><collision><origin xyz="0 0 {-pz / 2}"/><geometry><box size="{px} {py} {pz}"/>'
        f"</geometry></collision></link>{''.join(links)}{''.join(joints)}</robot>"
    )
    path = folder / "gripper.urdf"
    path.write_text(text)
    return path
