"""Plain values written back as TOML: the resolved configuration (``warpcaustics config``) and the
list or table cells of a sweep's summary.csv. ``tomllib.loads(dumps_toml(t))`` gives ``t`` back,
less the unset (None) values, which TOML cannot hold and which are written as comments."""

from __future__ import annotations

import json
import math
import re
from typing import Any

BARE_KEY = re.compile(r"^[A-Za-z0-9_-]+$")


def key(name: str) -> str:
    return name if BARE_KEY.match(name) else json.dumps(name)


def literal(value: Any) -> str:
    """One value as a TOML literal (strings in JSON's escaping, which TOML's basic strings share)."""
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(literal(v) for v in value) + "]"
    if isinstance(value, dict):
        items = [f"{key(k)} = {literal(v)}" for k, v in value.items() if v is not None]
        return "{ " + ", ".join(items) + " }" if items else "{}"
    raise TypeError(f"no TOML literal for {type(value).__name__}")


def _is_table_array(value: Any) -> bool:
    return isinstance(value, (list, tuple)) and bool(value) and all(isinstance(v, dict) for v in value)


def dumps_toml(table: dict, prefix: str = "") -> str:
    """A nested dict as a TOML document: the plain keys of each table first, then its sub-tables
    (``[a.b]``) and arrays of tables (``[[a.c]]``)."""
    lines = []
    subtables = []
    for name, value in table.items():
        if isinstance(value, dict):
            subtables.append((name, value, False))
        elif _is_table_array(value):
            subtables.append((name, value, True))
        elif value is None:
            lines.append(f"# {key(name)} is unset")
        else:
            lines.append(f"{key(name)} = {literal(value)}")
    out = "\n".join(lines) + ("\n" if lines else "")
    for name, value, many in subtables:
        path = f"{prefix}{key(name)}"
        if many:
            for item in value:
                out += f"\n[[{path}]]\n" + dumps_toml(item, f"{path}.")
        else:
            out += f"\n[{path}]\n" + dumps_toml(value, f"{path}.")
    return out
