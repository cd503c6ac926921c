"""Field metadata and leaf values: a field's allowed range (its ``metadata``), and one TOML value
checked against its annotated type (number, integer, string, boolean, enum, list of numbers)."""

from __future__ import annotations

import enum
import math
import typing
from typing import Any

from warpcaustics.errors import ConfigError


def _range(lo: float | None = None, hi: float | None = None, *, lo_open: bool = False) -> dict:
    return {"range": (lo, hi, lo_open)}


MAX_LENGTH_M = 1.0e5
"""Largest length or coordinate a scene may give [m] (100 km): beyond any patch a float32 surface
resolves (a 1e30 m patch rendered NaN, issue 31)."""

MAX_TIME_S = 1.0e7
"""Largest time or period a scene may give [s] (about 116 days)."""


def _length(*, lo_open: bool = False) -> dict:
    """A length [m]: 0 (or above, ``lo_open``) to MAX_LENGTH_M."""
    return _range(0.0, MAX_LENGTH_M, lo_open=lo_open)


def _coordinate() -> dict:
    """A coordinate [m]: ±MAX_LENGTH_M."""
    return _range(-MAX_LENGTH_M, MAX_LENGTH_M)


def _duration(*, lo_open: bool = False) -> dict:
    """A time or period [s]: 0 (or above, ``lo_open``) to MAX_TIME_S."""
    return _range(0.0, MAX_TIME_S, lo_open=lo_open)


# Values other issues will add, each with why it is not built yet ("" where that is not known): named
# so an error can say where they stand instead of "unknown".
PLANNED_VALUES = {
    "sky.model": {
        "cie_clear": "it needs the CIE standard-sky coefficients from a maintained source, which no "
        "colour-science release has yet",
    },
}


DESCRIBE_CHARS = 80
"""An error quotes at most this many characters of a value (a 10 MB string is not echoed)."""


def _describe(value: Any) -> str:
    """A value as an error quotes it (TOML-like), cut to DESCRIBE_CHARS characters."""
    if isinstance(value, bool):
        return str(value).lower()
    try:
        text = repr(value) if isinstance(value, str) else str(value)
    except (RecursionError, ValueError):  # nested too deeply; an integer of more than 4300 digits
        text = ""
    if text and len(text) <= DESCRIBE_CHARS:
        return text
    kind = "a table" if isinstance(value, dict) else "a list" if isinstance(value, list) else "a value"
    return f"{text[:DESCRIBE_CHARS // 2]}… ({len(text)} characters)" if text else kind


def _convert(key: str, value: Any, tp: Any, meta: dict) -> Any:
    """Check one leaf value against its annotated type and range; return the typed value."""
    origin = typing.get_origin(tp)
    args = typing.get_args(tp)
    if origin in (typing.Union, getattr(__import__("types"), "UnionType", None)) and type(None) in args:
        if value is None:
            return None
        tp = next(a for a in args if a is not type(None))
    if isinstance(tp, type) and issubclass(tp, enum.Enum):
        allowed = [m.value for m in tp]
        if isinstance(value, str) and value in allowed:
            return tp(value)
        if not isinstance(value, str):
            raise ConfigError(f"{key} = {_describe(value)} has the wrong type; expected one of: "
                              f"{', '.join(allowed)}")
        planned = PLANNED_VALUES.get(key, {})
        if value in planned:
            why = planned[value]
            raise ConfigError(f"{key} = {_describe(value)} is not implemented yet"
                              + (f" ({why})" if why else "") + f"; allowed now: {', '.join(allowed)}")
        raise ConfigError(f"{key} = {_describe(value)} is not allowed; allowed: {', '.join(allowed)}")
    if typing.get_origin(tp) is tuple and typing.get_args(tp) == (float, Ellipsis):
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            value = [value]  # one number stands for a one-value list (a grey albedo, a uniform scale)
        if not isinstance(value, (list, tuple)) or not all(
                isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
            raise ConfigError(f"{key} = {_describe(value)} must be a list of numbers")
        return tuple(_convert(key, v, float, meta) for v in value)
    if tp is bool:
        if isinstance(value, bool):
            return value
        raise ConfigError(f"{key} = {_describe(value)} has the wrong type; expected true or false")
    if tp is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ConfigError(f"{key} = {_describe(value)} has the wrong type; expected an integer")
    elif tp is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ConfigError(f"{key} = {_describe(value)} has the wrong type; expected a number")
        value = float(value)
        if not math.isfinite(value):
            raise ConfigError(f"{key} = {value} is not finite; expected a finite number")
    elif tp is str:
        if not isinstance(value, str):
            raise ConfigError(f"{key} = {_describe(value)} has the wrong type; expected a string")
        return value
    lo, hi, lo_open = meta.get("range", (None, None, False))
    if lo is not None and (value < lo or (lo_open and value == lo)):
        raise ConfigError(f"{key} = {value} is out of range; allowed: {_range_text(lo, hi, lo_open)}")
    if hi is not None and value > hi:
        raise ConfigError(f"{key} = {value} is out of range; allowed: {_range_text(lo, hi, lo_open)}")
    return value


def _range_text(lo, hi, lo_open) -> str:
    left = "" if lo is None else f"{lo} {'<' if lo_open else '<='} "
    right = "" if hi is None else f" <= {hi}"
    return f"{left}value{right}"
