"""The configuration reference (Markdown), rendered from the schemas (``python -m graspexp config_reference``).

Every key of every config group (and of every installed planner) with its type, unit, default, allowed
values and docstring, read from the structured-config schemas (``graspexp/config/``), their
``CONSTRAINTS`` and the YAML options (``conf/``), so the reference cannot drift from the code.
The documentation site builds its page ``reference/configuration.md`` from :func:`render` (``docs/hooks.py``).
"""

from __future__ import annotations

import ast
import dataclasses
import inspect
import re
import textwrap
import typing
from pathlib import Path
from typing import Any

import yaml

from graspexp.config.constraints import BEFORE, describe
from graspexp.config.job import JobConfig
from graspexp.config.plugins import LoadedPlanner, load_planners
from graspexp.config.registry import CONF_DIR, SCHEMAS, SUBSCHEMAS, group_options
from graspexp.config.validate import NOT_CONFIG, SCHEMA_CONSTRAINTS

UNIT_SUFFIXES = (
    ("_ns_per_m", "N s/m"),
    ("_n_per_m", "N/m"),
    ("_kg_m3", "kg/m^3"),
    ("_mps", "m/s"),
    ("_radps", "rad/s"),
    ("_hz", "Hz"),
    ("_deg", "deg"),
    ("_rad", "rad"),
    ("_mm", "mm"),
    ("_kg", "kg"),
    ("_m", "m"),
    ("_s", "s"),
    ("_n", "N"),
)
"""A key's unit from its name's suffix (STYLE.md 4), where its constraint states none."""


@dataclasses.dataclass(frozen=True)
class Key:
    """One config key as the reference prints it."""

    dotted: str
    """The key as it is overridden on the command line, e.g. ``sim.timestep_s``."""
    type: str
    unit: str
    default: str
    allowed: str
    doc: str
    before: str = ""
    """For a key that came with a new behaviour: the value runs had before it existed."""


def field_docs(schema: type) -> dict[str, str]:
    """The attribute docstrings of ``schema``'s fields (the string literal under each field), inherited
    ones included; a subclass's docstring of a field wins."""
    docs: dict[str, str] = {}
    for cls in reversed(schema.__mro__):
        if cls is object or not dataclasses.is_dataclass(cls):
            continue
        try:
            tree = ast.parse(textwrap.dedent(inspect.getsource(cls)))
        except (OSError, TypeError):
            continue
        body = tree.body[0].body if tree.body and isinstance(tree.body[0], ast.ClassDef) else []
        for node, after in zip(body, body[1:], strict=False):
            if (
                isinstance(node, ast.AnnAssign)
                and isinstance(node.target, ast.Name)
                and isinstance(after, ast.Expr)
                and isinstance(after.value, ast.Constant)
                and isinstance(after.value.value, str)
            ):
                docs[node.target.id] = inspect.cleandoc(after.value.value)
    return docs


def _type_name(t: Any) -> str:
    if isinstance(t, type) and not typing.get_args(t):
        return t.__name__
    return re.sub(r"\b(typing|builtins)\.", "", str(t)).replace("NoneType", "None")


def _default(f: dataclasses.Field) -> Any:
    if f.default is not dataclasses.MISSING:
        return f.default
    if f.default_factory is not dataclasses.MISSING:
        return f.default_factory()
    return "???"


def _show(value: Any) -> str:
    if value == "???":
        return "required"
    if isinstance(value, bool):
        return str(value).lower()
    if isinstance(value, float):
        return f"{value:.6g}"
    if isinstance(value, tuple):
        value = list(value)
    return "null" if value is None else str(value)


def unit_of(name: str, alternatives: list) -> str:
    """The unit a key's constraint states, else the one its name's suffix says (``""``: none)."""
    for a in alternatives:
        unit = getattr(a, "unit", "") or getattr(getattr(a, "item", None), "unit", "")
        if unit:
            return unit
    return next((u for suffix, u in UNIT_SUFFIXES if name.endswith(suffix)), "")


def schema_keys(schema: type, prefix: str, constraints: dict[str, list] | None = None) -> list[Key]:
    """Every key of ``schema`` under ``prefix`` (e.g. ``sim.``), nested schemas flattened."""
    constraints = SCHEMA_CONSTRAINTS[schema] if constraints is None else constraints
    hints = typing.get_type_hints(schema)
    docs = field_docs(schema)
    keys = []
    for f in dataclasses.fields(schema):
        if f.name in NOT_CONFIG or (schema is JobConfig and f.name in (*SCHEMAS, "planner")):
            continue
        t = hints.get(f.name, f.type)
        if dataclasses.is_dataclass(t):
            keys += schema_keys(t, f"{prefix}{f.name}.")
            continue
        alternatives = constraints[f.name]
        before = _show(f.metadata[BEFORE]) if BEFORE in f.metadata else ""
        keys.append(
            Key(
                f"{prefix}{f.name}",
                _type_name(t),
                unit_of(f.name, alternatives),
                _show(_default(f)),
                describe(alternatives),
                docs.get(f.name, ""),
                before,
            )
        )
    return keys


def _md(text: str) -> str:
    """reStructuredText-flavoured docstring text as one Markdown table cell (a pipe inside a code span
    needs no escape: Python-Markdown's tables skip code spans)."""
    text = re.sub(r":[a-z]+:`~?([^`]+)`", r"``\1``", text)  # :class:`x` -> ``x``
    parts = re.split(r"(``[^`]+``|`[^`]+`)", " ".join(text.split()))
    out = []
    for part in parts:
        if part.startswith("`"):
            out.append("`" + part.strip("`") + "`")
        else:
            out.append(
                part.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;").replace("|", "\\|")
            )
    return "".join(out)


def _table(keys: list[Key]) -> list[str]:
    lines = ["| key | type | unit | default | allowed | description |", "|---|---|---|---|---|---|"]
    for k in keys:
        doc = _md(k.doc)
        if k.before:
            doc += f" (added later; runs before it behaved as `{k.before}`)"
        lines.append(f"| `{k.dotted}` | `{k.type}` | {k.unit} | `{k.default}` | {_md(k.allowed)} | {doc} |")
    return lines


def preset_values(group: str, option: str) -> dict[str, Any]:
    """The values the YAML option ``conf/<group>/<option>.yaml`` sets (its ``defaults`` list left out)."""
    path = Path(CONF_DIR) / group / f"{option}.yaml"
    if not path.is_file():
        return {}
    data = yaml.safe_load(path.read_text()) or {}
    return {k: v for k, v in data.items() if k != "defaults"}


def _flat(data: dict, prefix: str = "") -> dict[str, Any]:
    out: dict[str, Any] = {}
    for k, v in data.items():
        if isinstance(v, dict):
            out.update(_flat(v, f"{prefix}{k}."))
        else:
            out[f"{prefix}{k}"] = v
    return out


def _options(group: str, keys: list[Key], options: list[str]) -> list[str]:
    defaults = {k.dotted: k.default for k in keys}
    lines = ["| option | values it sets that differ from the schema's defaults |", "|---|---|"]
    for option in options:
        changed = [
            f"`{key}={_show(v)}`"
            for key, v in _flat(preset_values(group, option), f"{group}.").items()
            if defaults.get(key) != _show(v) and key != f"{group}.name"
        ]
        lines.append(f"| `{group}={option}` | {', '.join(changed) or f'only `{group}.name`'} |")
    return lines


PROTOCOL_GROUP = "protocol"
"""The group of the published benchmark protocols (``conf/protocol/<name>.yaml``, package ``_global_``): each
selects options of other groups and sets their keys; its scene- and planner-dependent keys are in
``conf/protocol/scene/<name>_<mode>.yaml`` and ``conf/protocol/planner/<name>_<planner>.yaml``, which
``conf/config.yaml`` picks by interpolation once the choices are known."""
PROTOCOL_PARTS = {"scene": "mode", "planner": "planner"}
"""The protocol's sub-folders -> the group whose choice names their option (``<protocol>_<choice>``)."""


def _sets(data: dict) -> tuple[list[str], list[str]]:
    """(the group options, the key values) a ``_global_`` YAML option sets, as ``group=option`` and
    ``key=value`` strings."""
    groups = [
        f"`{key.removeprefix('override').strip().lstrip('/')}={value}`"
        for entry in data.get("defaults") or []
        if isinstance(entry, dict)
        for key, value in entry.items()
    ]
    values = [
        f"`{k}={_show(v)}`" for k, v in _flat({k: v for k, v in data.items() if k != "defaults"}).items()
    ]
    return groups, values


def protocol_section() -> list[str]:
    """The ``protocol`` group's part of the reference: every option, the groups it selects and the keys it
    sets, those that depend on the scene or the planner with their condition."""
    base = Path(CONF_DIR) / PROTOCOL_GROUP
    lines = [
        "",
        f"## `{PROTOCOL_GROUP}`",
        "",
        "A published benchmark protocol as one word (`conf/protocol/`): `protocol=NAME` selects the options "
        "and sets the keys the protocol fixes; none by default. `mode=pile` / `mode=packed` still choose the "
        "scene (the protocol's default is pile), and every key it sets stays overridable on the command line; "
        "`python -m graspexp protocol=NAME --cfg job` shows them. "
        f"Options: {', '.join(f'`{PROTOCOL_GROUP}={o}`' for o in group_options(PROTOCOL_GROUP))}.",
        "",
        "| option | when | selects | sets |",
        "|---|---|---|---|",
    ]
    for option in group_options(PROTOCOL_GROUP):
        groups, values = _sets(yaml.safe_load((base / f"{option}.yaml").read_text()) or {})
        lines.append(f"| `{PROTOCOL_GROUP}={option}` | always | {', '.join(groups)} | {', '.join(values)} |")
        for part, group in PROTOCOL_PARTS.items():
            for path in sorted((base / part).glob(f"{option}_*.yaml")):
                groups, values = _sets(yaml.safe_load(path.read_text()) or {})
                when = f"`{group}={path.stem.removeprefix(option + '_')}`"
                lines.append(
                    f"| `{PROTOCOL_GROUP}={option}` | {when} | {', '.join(groups)} | {', '.join(values)} |"
                )
    return lines


def render() -> str:
    """The whole reference page as Markdown."""
    out = [
        "# Configuration reference",
        "",
        "Generated from the schemas (`graspexp/config/`), their `CONSTRAINTS` and the YAML options "
        "(`conf/`) by `python -m graspexp config_reference` each time the site is built: do not "
        "edit it by hand, edit the field's docstring. Override any key as `python -m graspexp KEY=VALUE`; "
        "pick an option as `GROUP=OPTION`. *allowed* is what validation accepts (a value outside it is one "
        "`graspexp: error:` line).",
        "",
        "## Top-level keys (`graspexp/config/job.py`)",
        "",
        *_table(schema_keys(JobConfig, "")),
    ]
    for group, schema in SCHEMAS.items():
        keys = schema_keys(schema, f"{group}.")
        out += [
            "",
            f"## `{group}` (`{schema.__module__}.{schema.__qualname__}`)",
            "",
            f"Options: {', '.join(f'`{group}={o}`' for o in group_options(group))}.",
            "",
            *_table(keys),
            "",
            *_options(group, keys, group_options(group)),
        ]
        for sub in (sub for g, sub in SUBSCHEMAS.values() if g == group):
            own = {k.dotted for k in keys}
            out += [
                "",
                f"### `{group}` options with `{sub.__module__}.{sub.__qualname__}`",
                "",
                _md(" ".join((sub.__doc__ or "").split())),
                "",
                *_table([k for k in schema_keys(sub, f"{group}.") if k.dotted not in own]),
            ]
    out += protocol_section()
    out += [
        "",
        "## `planner`",
        "",
        "Each planner has its own schema, from its plugin (`graspexp.config.PlannerPlugin`, entry-point "
        "group `graspexp.planners`); `planner=NAME` selects it and its preset `conf/planner/NAME.yaml` "
        "where there is one.",
    ]
    for name, found in load_planners().items():
        out += ["", f"### `planner={name}`", ""]
        if not isinstance(found, LoadedPlanner):
            out.append(f"Not loadable: {_md(str(found))}")
            continue
        schema = found.plugin.config
        keys = schema_keys(schema, "planner.", dict(found.plugin.constraints))
        out += [
            f"Schema `{schema.__module__}.{schema.__qualname__}` from {_md(found.package)}.",
            "",
            *_table(keys),
            "",
            *_options("planner", keys, [name]),
        ]
    return "\n".join(out) + "\n"
