"""Which differences between two job configs can change a trial's result: the one rule that resume (a
log is reused only under the same config) and the report (a table cell never merges two configs) share."""

import dataclasses

from omegaconf import DictConfig, OmegaConf

from graspexp.config.constraints import BEFORE
from graspexp.config.mode import CLUTTER_KEYS, LEGACY_SCENES, ClutterModeConfig
from graspexp.core.userinput import load_user_yaml

RESULT_NEUTRAL_KEYS = (
    "progress",  # the progress bar
    "record",  # whether logs are written: a log that exists was recorded
    "trials",  # which trials run, not what one gives (a trial's seed derives from its object and index)
    "objects",
    "dataset.objects",
    "dataset.split",  # which objects run
    "objective",  # what the job returns to a sweeper, computed from the results
    "dataset.max_faces",  # which objects may run (a larger one is refused), not what a trial gives
    "sim.cache_dir",  # where collision shapes are cached; entries are keyed by mesh content
    "sim.prepare_workers",  # how many processes build the collision shapes, not what they build
    "live",  # whether trials also stream to the Foxglove app
    "live_port",
)
"""Config keys (and their sub-keys) that resume ignores when it compares a log's recorded config with the
current one: they change what is shown or which trials run, never a trial's result. Add presentation-only
keys here (e.g. live-streaming flags). ``hydra.*`` is not part of the job config and never compared."""


def _flatten(node: object, prefix: str = "") -> dict[str, object]:
    if isinstance(node, dict):
        out: dict[str, object] = {}
        for k, v in node.items():
            out.update(_flatten(v, f"{prefix}{k}."))
        return out
    return {prefix[:-1]: node}


def _neutral(key: str) -> bool:
    return any(key == n or key.startswith(n + ".") for n in RESULT_NEUTRAL_KEYS)


_NO_DEFAULT = object()


def _value_before(cfg: DictConfig, key: str) -> object:
    """The value dotted ``key`` had before graspexp added it: its schema field's ``metadata["before"]``
    (:data:`graspexp.config.BEFORE`) when the key came with a new behaviour, else its default; else
    ``_NO_DEFAULT``."""
    parent, _, leaf = key.rpartition(".")
    node = OmegaConf.select(cfg, parent) if parent else cfg
    schema = OmegaConf.get_type(node) if isinstance(node, DictConfig) else None
    for f in dataclasses.fields(schema) if dataclasses.is_dataclass(schema) else ():
        if f.name != leaf:
            continue
        if BEFORE in f.metadata:
            return f.metadata[BEFORE]
        if f.default is not dataclasses.MISSING:
            return f.default
        if f.default_factory is not dataclasses.MISSING:
            return f.default_factory()
    return _NO_DEFAULT


def result_config(config: dict) -> dict[str, object]:
    """A recorded job config (a plain dict) flattened to ``dotted key -> value``, without the keys that
    cannot change a result (:data:`RESULT_NEUTRAL_KEYS`)."""
    return {k: v for k, v in _flatten(config).items() if not _neutral(k)}


def config_differences(recorded_yaml: str, cfg: DictConfig) -> dict[str, tuple[object, object]]:
    """dotted key -> (value in the log, value now) for every key that affects a result and differs; a key
    absent on one side shows as ``<absent>``. A key the log lacks is not a difference when it now has the
    value the code had before the key was added (:func:`_value_before`). A recorded config that holds YAML
    aliases or is too large raises :class:`graspexp.core.userinput.UserInputError` before it is expanded
    (a log in a shared directory may be anyone's)."""
    load_user_yaml(recorded_yaml, "the log's recorded config")  # bounded, no alias expands below
    old = _flatten(OmegaConf.to_container(OmegaConf.create(recorded_yaml), resolve=True))
    new = _flatten(OmegaConf.to_container(cfg, resolve=True))
    absent = "<absent>"
    return {
        k: (old.get(k, absent), new.get(k, absent))
        for k in sorted(old.keys() | new.keys())
        if not _neutral(k)
        and old.get(k, absent) != new.get(k, absent)
        and not (k not in old and k in new and new[k] == _value_before(cfg, k))
        and not _moved(k, old, new)
    }


def _moved(key: str, old: dict[str, object], new: dict[str, object]) -> bool:
    """Whether ``key`` differs only because the clutter keys moved into their own schema
    (:class:`graspexp.config.mode.ClutterModeConfig`): a single-object mode's log that recorded one at its
    default, or a clutter log without ``mode.scene`` whose mode is named after its scene type."""
    group, _, leaf = key.partition(".")
    if group != "mode":
        return False
    if leaf == "scene" and key not in old:
        return old.get("mode.name") in LEGACY_SCENES and new[key] == old["mode.name"]
    field = next((f for f in dataclasses.fields(ClutterModeConfig) if f.name == leaf), None)
    if leaf not in CLUTTER_KEYS or key in new or field is None:
        return False
    default = field.default_factory() if field.default_factory is not dataclasses.MISSING else field.default
    return old[key] == default
