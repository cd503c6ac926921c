"""Field metadata and leaf values: a field's allowed range (its ``metadata``), and one TOML value
checked against its annotated type (number, integer, string, boolean, enum, list of numbers)."""

from __future__ import annotations

import enum
import math
import os
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


MIN_SIZE = 1.0e-6
"""Smallest value of a length [m], time [s] or other quantity that must be positive: a 5e-324 m
patch and a 5e-324 CFL number divided by zero (found by tests/test_fuzz.py)."""


def _length(*, positive: bool = False) -> dict:
    """A length [m]: MIN_SIZE to MAX_LENGTH_M, or also exactly 0 (where 0 means "none" or "the
    default"; ``positive``: it may not be 0). A 5e-324 m map window divided by zero."""
    if positive:
        return _range(MIN_SIZE, MAX_LENGTH_M)
    return {**_range(0.0, MAX_LENGTH_M), "zero_or_at_least": MIN_SIZE}


def _positive(hi: float) -> dict:
    """A quantity that must be positive: MIN_SIZE to ``hi`` (a subnormal CFL or wind divided by zero)."""
    return _range(MIN_SIZE, hi)


def _coordinate() -> dict:
    """A coordinate [m]: ±MAX_LENGTH_M."""
    return _range(-MAX_LENGTH_M, MAX_LENGTH_M)


def _duration(*, positive: bool = False) -> dict:
    """A time or period [s]: 0 (or MIN_SIZE, ``positive``) to MAX_TIME_S."""
    return _range(MIN_SIZE if positive else 0.0, MAX_TIME_S)


# Values other issues will add, each with why it is not built yet ("" where that is not known): named
# so an error can say where they stand instead of "unknown".
PLANNED_VALUES: dict[str, dict[str, str]] = {}


DESCRIBE_CHARS = 80
"""An error quotes at most this many characters of a value (a 10 MB string is not echoed)."""


def _describe(value: Any) -> str:
    """A value as an error quotes it (TOML-like); past DESCRIBE_CHARS characters, its first and last
    DESCRIBE_CHARS/4 with the length."""
    if isinstance(value, bool):
        return str(value).lower()
    try:
        text = repr(value) if isinstance(value, str) else str(value)
    except (RecursionError, ValueError):  # nested too deeply; an integer of more than 4300 digits
        text = ""
    if text and len(text) <= DESCRIBE_CHARS:
        return text
    kind = "a table" if isinstance(value, dict) else "a list" if isinstance(value, list) else "a value"
    if not text:
        return kind
    # its start and its end: a long path keeps its file name
    keep = DESCRIBE_CHARS // 4
    return f"{text[:keep]}…{text[-keep:]} ({len(text)} characters)"


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
        try:
            value = float(value)
        except OverflowError:  # an integer past float's range
            raise ConfigError(f"{key} = {_describe(value)} is beyond a float's range (±1.8e308); expected "
                              "a finite number") from None
        if not math.isfinite(value):
            raise ConfigError(f"{key} = {value} is not finite; expected a finite number")
    elif tp is str:
        if isinstance(value, os.PathLike) and isinstance(os.fspath(value), str):
            return os.fspath(value)  # a file key given as a pathlib.Path, as load_scene's own path may be
        if not isinstance(value, str):
            raise ConfigError(f"{key} = {_describe(value)} has the wrong type; expected a string")
        return value
    lo, hi, lo_open = meta.get("range", (None, None, False))
    least = meta.get("zero_or_at_least")
    shown = _describe(value)  # a 400-digit integer is not echoed whole
    if least is not None and 0 < value < least:
        raise ConfigError(f"{key} = {shown} is out of range; allowed: 0 or {least:g} <= value <= {hi}")
    if lo is not None and (value < lo or (lo_open and value == lo)):
        raise ConfigError(f"{key} = {shown} is out of range; allowed: {_range_text(lo, hi, lo_open)}")
    if hi is not None and value > hi:
        raise ConfigError(f"{key} = {shown} is out of range; allowed: {_range_text(lo, hi, lo_open)}")
    return value


def _range_text(lo, hi, lo_open) -> str:
    left = "" if lo is None else f"{lo} {'<' if lo_open else '<='} "
    right = "" if hi is None else f" <= {hi}"
    return f"{left}value{right}"


def _number(x: float, integer: bool) -> str:
    """A bound as the docs write it: 60, 0.7, 1e5, 2147483647, −360 (a minus sign, not a hyphen)."""
    if integer:
        text = str(int(x))
    elif (abs(x) >= 1e5 or 0 < abs(x) < 1e-3) and f"{abs(x):.0e}".startswith("1e"):
        text = f"{x:.0e}".replace("e+0", "e").replace("e+", "e").replace("e-0", "e-")
    else:
        text = f"{x:g}"
    return "−" + text[1:] if text.startswith("-") else text


def range_doc(tp: Any, meta: dict) -> str:
    """A numeric key's type and valid range as docs/config.md's table states it, from the same
    metadata the checks read: ``float 0…60``, ``float > 0, ≤ 60``, ``int 1…16384``, ``float ≥ 0``
    (a list of floats: the range of each); "" for a key that is not a number."""
    args = typing.get_args(tp)
    if type(None) in args:
        tp = next(a for a in args if a is not type(None))
    if typing.get_origin(tp) is tuple and typing.get_args(tp) == (float, Ellipsis):
        kind = "floats"
    elif tp in (int, float):
        kind = tp.__name__
    else:
        return ""
    lo, hi, lo_open = meta.get("range", (None, None, False))
    if lo is None and hi is None:
        return kind
    whole = kind == "int"
    if meta.get("zero_or_at_least") is not None:
        return f"{kind} 0 or {_number(meta['zero_or_at_least'], whole)}…{_number(hi, whole)}"
    if lo is not None and hi is not None and not lo_open:
        return f"{kind} {_number(lo, whole)}…{_number(hi, whole)}"
    parts = ([f"{'>' if lo_open else '≥'} {_number(lo, whole)}"] if lo is not None else []) + \
        ([f"≤ {_number(hi, whole)}"] if hi is not None else [])
    return f"{kind} {', '.join(parts)}"
