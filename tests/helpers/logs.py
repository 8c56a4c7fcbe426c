"""MCAP logs in tests: every message checked against its schema, and a file that is not a graspexp log."""

from pathlib import Path


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


def foreign_log(path: Path, result: dict) -> None:
    """Write an MCAP file holding only a /result message (no graspexp metadata): not a graspexp trial log."""
    import json

    from mcap.writer import Writer

    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "wb") as f:
        w = Writer(f)
        w.start()
        schema = w.register_schema("graspexp.TrialResult@2", "jsonschema", b"{}")
        channel = w.register_channel("/result", "json", schema)
        w.add_message(channel, 0, json.dumps(result).encode(), 0)
        w.finish()
