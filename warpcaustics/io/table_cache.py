"""A cache on disk of numeric tables the package computes from its own inputs, kept between processes.

Some tables cost seconds to compute and are the same in every process that needs them: the phase
function's Hankel transform behind the small-angle transfer (``optics/small_angle.py``) takes about
4 s of float64 Bessel functions, once per phase function in each process, so each worker of a sweep
and each field comparison's pool paid it again. Here a table is kept as a ``.npy`` file named by a
SHA-256 of everything it is computed from: the package version, the inputs' bytes, the source of
the functions that compute it and the versions of the libraries they call, so that a changed input,
formula or library is a new file and a stale table is not read. A file that cannot be read as the
table (damaged, of another shape) is computed again and replaced; a folder that cannot be written
only means no cache.

The folder: ``$WARPCAUSTICS_CACHE`` (``off`` for none), else ``$XDG_CACHE_HOME/warpcaustics``, else
``~/.cache/warpcaustics``. The files are small (16 kB a table) and safe to delete.
"""

from __future__ import annotations

import contextlib
import hashlib
import inspect
import os
from collections.abc import Callable
from pathlib import Path

import numpy as np

from warpcaustics import __version__

CACHE_ENV = "WARPCAUSTICS_CACHE"
"""The environment variable naming the cache's folder (``off``, ``0`` or empty: no cache)."""


def cache_folder() -> Path | None:
    """Where the tables are kept, or None where the cache is off."""
    value = os.environ.get(CACHE_ENV)
    if value is not None:
        return None if value.strip().lower() in ("", "0", "off") else Path(value).expanduser()
    base = os.environ.get("XDG_CACHE_HOME")
    if not base:
        try:
            base = str(Path.home() / ".cache")
        except (RuntimeError, KeyError):  # no home folder to be found: no cache
            return None
    return Path(base) / "warpcaustics"


def table_key(*parts) -> str | None:
    """The SHA-256 (hex) of the package version and ``parts``: arrays (their dtype, shape and bytes),
    functions (their source), strings and numbers (their repr). None where a function's source
    cannot be read (an install without .py files): then nothing can tell a stale table apart."""
    h = hashlib.sha256(__version__.encode())
    for part in parts:
        if isinstance(part, np.ndarray):
            h.update(f"{part.dtype}{part.shape}".encode())
            h.update(np.ascontiguousarray(part).tobytes())
        elif callable(part):
            try:
                h.update(inspect.getsource(part).encode())
            except (OSError, TypeError):
                return None
        else:
            h.update(repr(part).encode())
        h.update(b"\0")
    return h.hexdigest()


def cached_table(name: str, key: str | None, compute: Callable[[], np.ndarray],
                 shape: tuple[int, ...]) -> np.ndarray:
    """The float64 table ``compute()`` gives, read from the cache where a file of this ``name`` and
    ``key`` (:func:`table_key`) holds one of ``shape`` with finite values, else computed and written
    (atomically: a process reading at the same time sees the whole file or none)."""
    folder = cache_folder()
    path = None if folder is None or key is None else folder / f"{name}-{key[:32]}.npy"
    if path is not None:
        try:
            with open(path, "rb") as fh:
                table = np.load(fh, allow_pickle=False)
            if table.dtype == np.float64 and table.shape == shape and np.all(np.isfinite(table)):
                return table
        except (OSError, ValueError, EOFError):
            pass
    table = compute()
    if path is not None:
        tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            with open(tmp, "wb") as fh:
                np.save(fh, table, allow_pickle=False)
            os.replace(tmp, path)
        except OSError:  # a read-only home, a full disk: the table is still right, only not kept
            with contextlib.suppress(OSError):
                tmp.unlink(missing_ok=True)
    return table
