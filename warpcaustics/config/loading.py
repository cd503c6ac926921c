"""Reading a configuration: TOML files and dotted overrides validated into a :class:`Config`, and
a Config written back as plain values."""

from __future__ import annotations

import dataclasses
import datetime
import difflib
import enum
import sys
import typing
from pathlib import Path
from typing import Any

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

from warpcaustics.config.checks import _check_consistency
from warpcaustics.config.fields import _convert, _describe
from warpcaustics.config.schema import Config
from warpcaustics.errors import ConfigError


def _hints(cls: type) -> dict[str, Any]:
    return typing.get_type_hints(cls)


def _is_section(tp: Any) -> bool:
    return dataclasses.is_dataclass(tp)


def all_keys(cls: type = Config, prefix: str = "") -> list[str]:
    """Every dotted key of the configuration tree (leaves only)."""
    keys = []
    for name, tp in _hints(cls).items():
        if _tuple_item(tp) is not None:
            keys += [f"{prefix}{name}[].{k}" for k in all_keys(_tuple_item(tp))]
        elif _is_section(tp):
            keys += all_keys(tp, f"{prefix}{name}.")
        else:
            keys.append(f"{prefix}{name}")
    return keys


def _tuple_item(tp: Any) -> type | None:
    """The dataclass D of a ``tuple[D, ...]`` annotation (a TOML array of tables), else None."""
    if typing.get_origin(tp) is tuple:
        args = typing.get_args(tp)
        if len(args) == 2 and args[1] is Ellipsis and dataclasses.is_dataclass(args[0]):
            return args[0]
    return None


def _nearest(key: str) -> str:
    keys = all_keys() + [k.rsplit(".", 1)[0] for k in all_keys() if "." in k]
    match = difflib.get_close_matches(key, keys, n=1, cutoff=0.0)
    return match[0] if match else ""


def settable_keys() -> set[str]:
    """Every dotted key an override may set: the leaves, the arrays of tables (``water.drops``) and
    the sections (``[]`` dropped: an array is set whole)."""
    leaves = {k.replace("[]", "") for k in all_keys()}
    parents = {k.rsplit(".", i)[0] for k in leaves for i in range(1, k.count(".") + 1)}
    return leaves | parents


def check_key(key: str, where: str) -> None:
    """Refuse a dotted key no config has, naming the nearest valid one (``where``: what gave it,
    e.g. "sweep [grid]"); a retired key names its successor."""
    if key in RETIRED_KEYS:
        fate, successor = RETIRED_KEYS[key]
        raise ConfigError(f"{where}: {key} was {fate} {successor}; set that instead")
    if key not in settable_keys():
        raise ConfigError(f"{where}: unknown key '{key}'; nearest valid key: '{_nearest(key)}' "
                          "(see docs/config.md)")


RETIRED_KEYS: dict[str, tuple[str, str]] = {
    "caustics.sunmap_disk_deg": ("merged into", "sun.angular_diameter_deg"),
}
"""Keys that are gone, each with what became of it and the key to set instead: named so an error
can say where to go instead of "unknown"."""


def _build(cls: type, table: dict, prefix: str) -> Any:
    fields = {f.name: f for f in dataclasses.fields(cls)}
    hints = _hints(cls)
    kwargs = {}
    for name, value in table.items():
        key = f"{prefix}{name}"
        if key in RETIRED_KEYS:
            fate, successor = RETIRED_KEYS[key]
            raise ConfigError(f"{key} was {fate} {successor}; set that instead")
        if name not in fields:
            raise ConfigError(f"unknown key '{key}' = {_describe(value)}; nearest valid key: "
                              f"'{_nearest(key)}' (see docs/config.md)")
        tp = hints[name]
        item = _tuple_item(tp)
        if item is not None:
            if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
                raise ConfigError(f"{key} must be a list of tables, e.g. {key} = [{{ ... }}] or "
                                  f"[[{key}]] sections")
            kwargs[name] = tuple(_build(item, v, f"{key}[{i}].") for i, v in enumerate(value))
        elif _is_section(tp):
            if not isinstance(value, dict):
                raise ConfigError(f"{key} = {_describe(value)} must be a table ([{key}] or "
                                  f"{key}.<name> = ...)")
            kwargs[name] = _build(tp, value, f"{key}.")
        else:
            kwargs[name] = _convert(key, value, tp, dict(fields[name].metadata))
    return cls(**kwargs)


WHOLE_VALUES = ("optics.wavelengths",)
"""Keys whose table is one value (the bins' min_nm, max_nm and bins, or a resolved config's list_nm
beside them): a table given for one replaces it rather than merging into it."""


def dotted_keys(overrides: dict, prefix: str = "") -> list[str]:
    """Every dotted key overrides reach, a table's keys inside it included (``sun={elevation_deg=…}``
    sets ``sun.elevation_deg``)."""
    keys = []
    for key, value in overrides.items():
        name = f"{prefix}{key}"
        keys.append(name)
        if isinstance(value, dict):
            keys += dotted_keys(value, f"{name}.")
    return keys


def _set_dotted(table: dict, key: str, value: Any, prefix: str = "") -> None:
    """Set ``key`` (dotted) in ``table`` to a copy of ``value``; a table given for a table merges into
    it key by key (``--set 'sun={elevation_deg=30}'`` changes the elevation alone, as
    ``--set sun.elevation_deg=30`` does) but for :data:`WHOLE_VALUES`; anything else replaces what
    was there."""
    if not isinstance(key, str) or not key:
        raise ConfigError(f"override key {key!r} must be a dotted name, e.g. 'sun.elevation_deg'")
    parts = key.split(".")
    node = table
    for i, part in enumerate(parts[:-1]):
        child = node.setdefault(part, {})
        if not isinstance(child, dict):
            raise ConfigError(f"override '{key}': '{'.'.join(parts[: i + 1])}' is a value, not a table")
        node = child
    whole = f"{prefix}{key}" in WHOLE_VALUES
    if isinstance(value, dict) and isinstance(node.get(parts[-1]), dict) and not whole:
        for name, item in value.items():
            _set_dotted(node[parts[-1]], name, item, f"{prefix}{key}.")
    else:
        node[parts[-1]] = _deepcopy(value) if isinstance(value, dict) else value


def parse_override(text: str) -> tuple[str, Any]:
    """Parse ``key=value`` from the command line; the value is a TOML literal or a bare string."""
    if "=" not in text:
        raise ConfigError(f"--set {text!r} must look like key=value, e.g. sun.elevation_deg=45")
    key, raw = (s.strip() for s in text.split("=", 1))
    try:
        value = tomllib.loads(f"v = {raw}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw
    except RecursionError:
        raise ConfigError(f"--set {key}=…: the value nests lists or tables too deeply (at most "
                          f"{MAX_DEPTH} levels)") from None
    except ValueError:  # Python reads integers of at most 4300 digits
        raise ConfigError(f"--set {key}=…: the value is a number of {len(raw)} digits, too long to "
                          "read; give an ordinary number") from None
    check_depth(value, f"--set {key}")
    return key, value


MAX_DEPTH = 32
"""Deepest nesting of tables and lists a configuration may hold (the schema needs four)."""


def check_depth(value: Any, where: str = "the configuration") -> None:
    """Refuse tables and lists nested more than MAX_DEPTH deep (walked without recursion, so a
    pathological input gets a one-line error naming ``where``, not a RecursionError)."""
    stack = [(value, "", 0)]
    while stack:
        node, path, depth = stack.pop()
        if depth > MAX_DEPTH:
            under = f" (under {path.split('.')[0]!r})" if path else ""
            raise ConfigError(f"{where} nests tables or lists more than {MAX_DEPTH} levels deep{under}; "
                              "the configuration needs at most four (see docs/config.md)")
        if isinstance(node, dict):
            stack += [(v, f"{path}.{k}" if path else str(k), depth + 1) for k, v in node.items()]
        elif isinstance(node, list):
            stack += [(v, path, depth + 1) for v in node]


def config_from_dict(table: dict, overrides: dict[str, Any] | None = None) -> Config:
    """Validate a plain nested dict (as read from TOML) plus dotted overrides into a Config."""
    check_depth(table)
    for key, value in (overrides or {}).items():
        check_depth(value, key)
    table = _deepcopy(table)
    for key, value in (overrides or {}).items():
        _set_dotted(table, key, _plain(value))
    optics = table.get("optics")
    if isinstance(optics, dict):
        wavelengths = optics.get("wavelengths")
        # Shorthands: a list of centres, or "rgb" (three equal bins over 400-700 nm).
        if isinstance(wavelengths, list):
            if not wavelengths:
                raise ConfigError("optics.wavelengths = [] needs at least one wavelength [nm]")
            optics["wavelengths"] = {"list_nm": wavelengths}
        elif wavelengths == "rgb":
            optics["wavelengths"] = {"min_nm": 400.0, "max_nm": 700.0, "bins": 3}
        elif isinstance(wavelengths, str):
            raise ConfigError(f"optics.wavelengths = {wavelengths!r} is not allowed; allowed: a table "
                              f"{{min_nm, max_nm, bins}}, a list of centres [nm] or \"rgb\"")
    _resolve_sun_position(table, set(dotted_keys(overrides or {})))
    cfg = _build(Config, table, "")
    _check_consistency(cfg)
    return cfg


def _resolve_sun_position(table: dict, overridden: set[str]) -> None:
    """``sun.datetime`` with latitude and longitude: write the sun's elevation and azimuth into the
    table (so the resolved config, run.json and sweep ids carry them). A place given by overrides
    replaces an elevation and azimuth from the file; given in the same layer, they conflict."""
    sun = table.get("sun")
    if not isinstance(sun, dict):
        return
    place = [k for k in ("datetime", "latitude_deg", "longitude_deg") if sun.get(k) is not None]
    if not place:
        return
    if len(place) < 3:
        missing = [f"sun.{k}" for k in ("datetime", "latitude_deg", "longitude_deg") if k not in place]
        raise ConfigError(f"sun.{place[0]} needs {' and '.join(missing)} too (the sun's position comes "
                          "from a date, a time and a place)")
    explicit = [k for k in ("elevation_deg", "azimuth_deg") if k in sun]
    place_overridden = any(f"sun.{k}" in overridden for k in place)
    angles_overridden = any(f"sun.{k}" in overridden for k in explicit)
    if explicit and place_overridden and not angles_overridden:
        for k in explicit:  # the overrides' place wins over the file's angles
            del sun[k]
        explicit = []
    if explicit and angles_overridden and not place_overridden:
        for k in ("datetime", "latitude_deg", "longitude_deg"):  # and the overrides' angles over its place
            sun.pop(k, None)
        return
    from warpcaustics.optics.solar import parse_datetime, sun_position

    for key, limit in (("latitude_deg", 90.0), ("longitude_deg", 180.0)):
        if isinstance(sun[key], bool) or not isinstance(sun[key], (int, float)):
            raise ConfigError(f"sun.{key} = {_describe(sun[key])} has the wrong type; expected a number")
        if not abs(sun[key]) <= limit:  # NaN too
            raise ConfigError(f"sun.{key} = {sun[key]} is out of range; allowed: -{limit:g} <= value <= "
                              f"{limit:g}")
    if isinstance(sun["datetime"], (datetime.datetime, datetime.date)):
        sun["datetime"] = sun["datetime"].isoformat()  # a TOML date-time literal (quoted or not)
    if not isinstance(sun["datetime"], str):
        raise ConfigError(f"sun.datetime = {_describe(sun['datetime'])} must be a string, e.g. "
                          "\"2009-07-14T11:30:00+02:00\"")
    elevation, azimuth = sun_position(parse_datetime(sun["datetime"]), float(sun["latitude_deg"]),
                                      float(sun["longitude_deg"]))
    if elevation <= 0.0:
        raise ConfigError(f"sun.datetime = {sun['datetime']!r}: the sun is {-elevation:.1f}° below the "
                          f"horizon at latitude {sun['latitude_deg']}°, longitude {sun['longitude_deg']}°; "
                          "pick a daytime")
    if explicit:
        # both in one layer: accepted when they agree (a resolved config, e.g. run.json's, read back)
        given = {"elevation_deg": elevation, "azimuth_deg": azimuth}
        if any(isinstance(sun[k], bool) or not isinstance(sun[k], (int, float))
               or abs((float(sun[k]) - given[k] + 180.0) % 360.0 - 180.0) > 1e-6 for k in explicit):
            raise ConfigError(f"sun.{explicit[0]} and sun.datetime both set the sun's position; give one "
                              "of them")
    sun["elevation_deg"] = elevation
    sun["azimuth_deg"] = azimuth


def read_toml(path: str | Path) -> dict:
    """Read a TOML file, turning a missing or malformed file into a one-line ConfigError."""
    path = Path(path)
    try:
        if path.is_char_device() or path.is_block_device():  # reading would never end (a pipe may)
            raise ConfigError(f"config file {_describe(str(path))} is a device, not a file; give the path "
                              "of a .toml file")
        text = path.read_text(encoding="utf-8").removeprefix("\ufeff")  # an editor's byte-order mark
    except FileNotFoundError:
        raise ConfigError(f"config file {_describe(str(path))} does not exist; check the path") from None
    except (OSError, UnicodeDecodeError) as exc:
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        raise ConfigError(f"config file {_describe(str(path))} cannot be read: {reason}") from None
    try:
        table = tomllib.loads(text)
        check_depth(table, f"config file {_describe(str(path))}")
        return table
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"config file {str(path)!r} is not valid TOML: {exc}") from None
    except RecursionError:
        raise ConfigError(f"config file {str(path)!r} nests tables or lists too deeply (at most "
                          f"{MAX_DEPTH} levels)") from None
    except ValueError as exc:  # an integer of more than 4300 digits
        raise ConfigError(f"config file {str(path)!r} holds a value that cannot be read: "
                          f"{str(exc).split(';')[0]}") from None


def config_to_dict(cfg: Any) -> dict:
    """Resolved configuration as plain TOML/JSON-compatible values."""
    out = {}
    for f in dataclasses.fields(cfg):
        value = getattr(cfg, f.name)
        if dataclasses.is_dataclass(value):
            out[f.name] = config_to_dict(value)
        elif isinstance(value, tuple):
            out[f.name] = [config_to_dict(v) if dataclasses.is_dataclass(v) else v for v in value]
        elif isinstance(value, enum.Enum):
            out[f.name] = value.value
        else:
            out[f.name] = value
    return out


def _plain(value: Any) -> Any:
    """A Python override as TOML would give it: numpy's scalars and arrays as the Python numbers and
    lists they hold (np.int64(64) → 64, np.array([450., 550.]) → [450.0, 550.0]), inside tables too."""
    if type(value).__module__ == "numpy" and hasattr(value, "tolist"):
        return value.tolist()
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    return value


def _deepcopy(table: dict) -> dict:
    return {k: _deepcopy(v) if isinstance(v, dict) else v for k, v in table.items()}
