"""Shared fixtures: composed configs, the real-mesh data root, an isolated convex-decomposition cache."""

import os
from pathlib import Path

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
