"""Reading what comes from other people's folders: YAML without alias bombs, object names that are safe as
file names, bounded echoes of bad values in messages.

Every function raises :class:`UserInputError` (a ValueError) with one line naming the file or the value.
"""

from __future__ import annotations

import os
import reprlib
from pathlib import Path
from typing import Any

import yaml

MAX_USER_YAML_BYTES = 1 << 20
"""Largest YAML file read from a user's folder (a sidecar, a grasping-area spec, a run's recorded config),
bytes: a real one is a few kB."""


class UserInputError(ValueError):
    """Input from a user's folder that graspexp will not use (too large, YAML aliases, not YAML, a name
    that is not a safe file name); the message is one line."""


class _NoAliasLoader(yaml.SafeLoader):
    """PyYAML's safe loader refusing aliases: ``&a``/``*a`` let a few hundred bytes expand into gigabytes
    ("billion laughs") once the value is formatted or walked; no graspexp file needs them."""

    def compose_node(self, parent, index):  # noqa: ANN001, ANN201 (PyYAML's signature)
        if self.check_event(yaml.AliasEvent):
            mark = self.peek_event().start_mark
            raise UserInputError(f"YAML alias at line {mark.line + 1}: aliases (*name) are not accepted")
        return super().compose_node(parent, index)


def load_user_yaml(text: str, what: str) -> Any:
    """``text``, YAML read from a user's file ``what``, parsed safely (at most :data:`MAX_USER_YAML_BYTES`,
    no aliases)."""
    if len(text) > MAX_USER_YAML_BYTES:
        raise UserInputError(f"{what} holds {len(text)} characters, more than {MAX_USER_YAML_BYTES}")
    try:
        return yaml.load(text, Loader=_NoAliasLoader)  # noqa: S506 (a SafeLoader subclass)
    except UserInputError as err:
        raise UserInputError(f"{what}: {err}") from None
    except yaml.YAMLError as err:
        raise UserInputError(f"{what} is not valid YAML: {' '.join(str(err).split())}") from None


def read_user_yaml(path: Path, what: str = "") -> Any:
    """The YAML file ``path`` from a user's folder (:func:`load_user_yaml`), of which at most
    :data:`MAX_USER_YAML_BYTES` + 1 bytes are read; ``what`` names it in messages (default: the path)."""
    what = what or str(path)
    try:
        with open(path, "rb") as fh:
            data = fh.read(MAX_USER_YAML_BYTES + 1)
    except OSError as err:
        raise UserInputError(f"{what} cannot be read: {err.strerror or err}") from None
    if len(data) > MAX_USER_YAML_BYTES:
        raise UserInputError(
            f"{what} is larger than {MAX_USER_YAML_BYTES} bytes; such a YAML file is a few kB"
        )
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise UserInputError(f"{what} is not UTF-8 text") from None
    return load_user_yaml(text, what)


def shown(value: Any, limit: int = 60) -> str:
    """A bounded ``repr`` of a value read from a user's file, for a message (long parts cut, marked ...)."""
    short = reprlib.Repr()
    short.maxstring = short.maxother = limit
    short.maxlist = short.maxdict = 6
    short.maxlevel = 2
    text = short.repr(value)
    return text if len(text) <= 2 * limit else text[: 2 * limit] + "..."


def object_name_problem(name: object) -> str:
    """Why ``name`` cannot name an object ("" if it can). An object's name becomes a folder of the run
    (``trials/<name>/``) and a row of its tables, so it is a non-empty string, not ``.`` or ``..``, not
    starting with ``.`` (hidden, and ``.quarantine`` is the run's own), without path separators, control
    characters (a newline splits a table row) or surrounding spaces, at most 200 characters."""
    if not isinstance(name, str) or not name:
        return "an object name is a non-empty text"
    if name.startswith("."):
        return "it starts with '.' (., .. and hidden names are not object names)"
    if any(c in name for c in "/\\") or any(ord(c) < 32 or ord(c) == 127 for c in name):
        return "it holds a path separator or a control character (a newline, a tab)"
    if name != name.strip():
        return "it starts or ends with a space"
    if len(name) > 200:
        return "it is longer than 200 characters"
    return ""


def check_object_name(name: object, where: str = "") -> str:
    """``name`` if it is a valid object name (:func:`object_name_problem`), else :class:`UserInputError`."""
    problem = object_name_problem(name)
    if problem:
        raise UserInputError(
            f"{shown(name)}{f' ({where})' if where else ''} is not a valid object name: {problem}"
        )
    return name  # type: ignore[return-value]


def inside_folder(path: Path, folder: Path) -> bool:
    """Whether ``path`` (absolute, or relative to the working directory) names a file inside ``folder``,
    read lexically (``..`` resolved, symbolic links not followed: a dataset may link its files)."""
    path, folder = Path(os.path.abspath(path)), Path(os.path.abspath(folder))
    return path != folder and path.is_relative_to(folder)
