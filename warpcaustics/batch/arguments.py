"""One-line checks of the batch functions' arguments from Python (studies, sweeps, comparisons, the
field data sets): a path, an overrides dict, a worker count, a list of names, an output folder.

The command line hands these functions well-formed values; a caller from Python may not, and a
wrong type had surfaced as a TypeError or AttributeError from pathlib, difflib or multiprocessing,
some only after every render had run. Each check here names the function, the argument and what it
takes, as :func:`warpcaustics.load_scene` does for its own.
"""

from __future__ import annotations

import numbers
import os
from collections.abc import Mapping
from pathlib import Path

from warpcaustics.errors import ConfigError, WarpcausticsError


def _got(value) -> str:
    return f"got {type(value).__name__} {value!r:.60}"


def path_argument(function: str, name: str, value, what: str) -> Path:
    """``value`` as a Path: a str or os.PathLike naming ``what`` (not bytes, empty or with a NUL)."""
    if isinstance(value, (str, os.PathLike)) and not isinstance(value, bytes):
        text = os.fspath(value)
        if isinstance(text, str) and text and "\0" not in text:
            return Path(text)
    raise ConfigError(f"{function}() {name} must be the path of {what} (a str or a Path); {_got(value)}")


def overrides_argument(function: str, value) -> dict:
    """``value`` (None for none) as a dict of dotted config keys (strings) to values."""
    if value is None:
        return {}
    if not isinstance(value, Mapping):
        raise ConfigError(f"{function}() overrides must be a dict of dotted keys, e.g. "
                          f"{{'water.resolution': 64}}; {_got(value)}")
    bad = next((k for k in value if not isinstance(k, str)), None)
    if bad is not None:
        raise ConfigError(f"{function}() overrides key {bad!r} must be a dotted config key (a str), e.g. "
                          "'water.resolution'")
    return dict(value)


def workers_argument(value) -> int:
    """``value`` as a count of worker processes (a whole number ≥ 1; not a bool)."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise WarpcausticsError(f"--workers = {value!r:.60} must be a whole number of processes, e.g. 2")
    if value < 1:
        raise WarpcausticsError(f"--workers = {value} must be at least 1")
    return int(value)


def names_argument(name: str, value, allowed: tuple[str, ...]) -> tuple[str, ...]:
    """``value`` as a tuple of names from ``allowed`` (a bare string had been split into its letters)."""
    if isinstance(value, str) or not isinstance(value, (list, tuple)) \
            or not all(isinstance(v, str) for v in value):
        raise ConfigError(f"{name} = {value!r:.60} must be a list of names, e.g. ({allowed[0]!r},); "
                          f"allowed: {', '.join(allowed)}")
    return tuple(value)


def output_folder(name: str, path: Path) -> Path:
    """Make the folder ``path`` (given as argument ``name``) before anything renders, or say in one line
    why it cannot be: a file there, no permission."""
    if path.exists() and not path.is_dir():
        raise WarpcausticsError(f"{name} {str(path)!r} is a file; give a folder")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise WarpcausticsError(f"{name} {str(path)!r} cannot be created: {exc.strerror or exc}") from None
    return path
