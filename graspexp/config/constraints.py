"""Value constraints, declared as data next to each schema (scikit-learn ``_parameter_constraints`` style).

Each schema module holds a mapping ``field name -> list of alternatives``; a value is valid when one
alternative accepts it (``None`` in the list allows null). Every field of every schema has an entry,
so a new key without one fails ``tests/test_config.py``. The text of an alternative is the allowed range
that the error message prints.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field
from typing import Any

BEFORE = "before"
"""Metadata key of a schema field that came with a new behaviour: the value the code had before the
field existed. Resume compares a log written before then against it (graspexp/runner.py)."""


def added(default: object, before: object) -> Any:
    """A schema field with ``default`` that was added to graspexp after runs had behaved as ``before``."""
    return field(default=default, metadata={BEFORE: before})


def _is_int(v: object) -> bool:
    return isinstance(v, int) and not isinstance(v, bool)


def is_real(v: object) -> bool:
    """A finite int or float, not a bool (YAML ``true`` is not 1)."""
    return (isinstance(v, int | float) and not isinstance(v, bool)) and math.isfinite(v)


@dataclass(frozen=True)
class Interval:
    """A finite number (``integer=True``: an int) between ``low`` and ``high`` (None: unbounded)."""

    low: float | None
    high: float | None
    closed: str = "both"
    """Which ends belong to the interval: ``both``, ``left``, ``right`` or ``neither``."""
    unit: str = ""
    integer: bool = False

    def accepts(self, v: object) -> bool:
        if not (_is_int(v) if self.integer else is_real(v)):
            return False
        lo_ok = self.low is None or (v >= self.low if self.closed in ("both", "left") else v > self.low)
        hi_ok = self.high is None or (v <= self.high if self.closed in ("both", "right") else v < self.high)
        return lo_ok and hi_ok

    def __str__(self) -> str:
        kind = "an integer" if self.integer else "a number"
        unit = f" {self.unit}" if self.unit else ""
        if self.low is None and self.high is None:
            return f"{kind} (finite){unit}".rstrip()
        if self.high is None:
            return f"{kind} {'>=' if self.closed in ('both', 'left') else '>'} {self.low:g}{unit}"
        if self.low is None:
            return f"{kind} {'<=' if self.closed in ('both', 'right') else '<'} {self.high:g}{unit}"
        left = "[" if self.closed in ("both", "left") else "("
        right = "]" if self.closed in ("both", "right") else ")"
        return f"{kind} in {left}{self.low:g}, {self.high:g}{right}{unit}"


@dataclass(frozen=True)
class Options:
    """One of a fixed set of values (compared with their type: ``1`` is not ``True``)."""

    values: tuple

    def accepts(self, v: object) -> bool:
        return any(type(v) is type(o) and v == o for o in self.values)

    def __str__(self) -> str:
        return "one of " + ", ".join(str(o) for o in self.values)


@dataclass(frozen=True)
class Text:
    """A non-empty string."""

    def accepts(self, v: object) -> bool:
        return isinstance(v, str) and v.strip() != ""

    def __str__(self) -> str:
        return "a non-empty string"


@dataclass(frozen=True)
class Pattern:
    """A string that matches a regular expression (``what`` says it in words)."""

    regex: str
    what: str

    def accepts(self, v: object) -> bool:
        return isinstance(v, str) and re.fullmatch(self.regex, v) is not None

    def __str__(self) -> str:
        return self.what


@dataclass(frozen=True)
class Names:
    """A list of non-empty strings (object names)."""

    def accepts(self, v: object) -> bool:
        return isinstance(v, list | tuple) and all(Text().accepts(x) for x in v)

    def __str__(self) -> str:
        return "a list of names"


@dataclass(frozen=True)
class Vector:
    """A list of ``length`` values (None: one or more), each accepted by ``item``."""

    length: int | None
    item: Interval

    def accepts(self, v: object) -> bool:
        n_ok = (
            len(v) == self.length
            if self.length is not None
            else len(v) > 0
            if isinstance(v, list | tuple)
            else False
        )
        return isinstance(v, list | tuple) and n_ok and all(self.item.accepts(x) for x in v)

    def __str__(self) -> str:
        n = "one or more" if self.length is None else f"{self.length}"
        return f"a list of {n} values, each {self.item}"


BOOL = [Options((True, False))]
"""A boolean key (Hydra already types it; listed so that every key has an entry)."""
TEXT = [Text()]
Constraint = Interval | Options | Text | Names | Vector | None


def describe(alternatives: list[Constraint]) -> str:
    """The allowed range as one phrase, e.g. ``null or a number in (0, 1] m``."""
    return " or ".join("null" if a is None else str(a) for a in alternatives)


def accepts(alternatives: list[Constraint], value: object) -> bool:
    """True when one alternative accepts ``value`` (None accepts only None)."""
    return any(value is None if a is None else a.accepts(value) for a in alternatives)
