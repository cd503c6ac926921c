"""File helpers every writer shares: atomic writes, JSON and CSV, the package versions, pyplot."""

from __future__ import annotations

import csv
import json
import os
import platform
from contextlib import contextmanager
from importlib import metadata
from pathlib import Path

import numpy as np

from warpcaustics import __version__


@contextmanager
def folder_lock(out: Path):
    """Hold an advisory lock on the folder ``out`` itself (``flock`` on the open folder: no file is
    made; released when the command ends, however it ends) while a command writes there: a second run
    into the same folder at the same time is refused in one line, where it had deleted the first run's
    files as its own earlier outputs (a render) or rendered the same tasks into the same temporary
    folders (a sweep). Where the system or the file system has no ``flock``, nothing is locked."""
    from warpcaustics.errors import WarpcausticsError

    try:
        import fcntl
    except ImportError:  # not POSIX
        yield
        return
    try:
        handle = os.open(out, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
    except OSError:  # not a folder one can open: the writes that follow say why themselves
        yield
        return
    try:
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            raise WarpcausticsError(f"--out {str(out)!r} is being written by another warpcaustics run; wait "
                                    "for it to end, or give another --out") from None
        except OSError:  # a file system without locks (some network mounts)
            pass
        yield
    finally:
        os.close(handle)


def input_file(key: str, name: str, base_dir: Path | None, what: str) -> Path:
    """The file a config key names (a relative path starts at ``base_dir``, the config file's
    folder), checked to exist; otherwise a one-line ConfigError naming ``key``: a missing file, a
    folder, a name the file system cannot hold. ``what``: the file it should be ("a .npy array")."""
    from warpcaustics.config.fields import _describe
    from warpcaustics.errors import ConfigError

    path = Path(name)
    if not path.is_absolute() and base_dir is not None:
        path = base_dir / path
    try:
        found = path.is_file()
    except (OSError, ValueError) as exc:  # a name too long for the file system; a NUL byte
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
        raise ConfigError(f"{key} = {_describe(name)} cannot be a file name ({reason}); give the path "
                          f"of {what}") from None
    if not found:
        kind = ("is a folder" if path.is_dir() else "is not a regular file (a device or a pipe)"
                if path.exists() else "does not exist")
        raise ConfigError(f"{key} = {_describe(name)} {kind}; give the path of {what} (relative paths "
                          "start at the config file's folder)")
    return path


def load_npy(key: str, path: Path, what: str):
    """One array from a .npy file a config key names, or a one-line ConfigError naming ``key``: a file
    numpy cannot read (empty, truncated, pickled, a header asking for more memory than there is) or a
    .npz archive. ``what``: what the array holds ("heights")."""
    import numpy as np

    from warpcaustics.errors import ConfigError

    try:
        array = np.load(path, allow_pickle=False)
    except Exception as exc:  # noqa: BLE001 - any unreadable file is the same user error
        raise ConfigError(f"{key} = {str(path)!r} is not a readable .npy array "
                          f"({type(exc).__name__}: {exc}); save the {what} with numpy.save") from None
    if not isinstance(array, np.ndarray):
        array.close()
        raise ConfigError(f"{key} = {str(path)!r} is a .npz archive; save one array of {what} with "
                          "numpy.save (.npy)")
    return array


@contextmanager
def atomic_path(path: Path):
    """Yield a temporary name beside ``path``; rename it onto ``path`` only if the block succeeds."""
    tmp = path.with_name(f".{path.name}.tmp-{os.getpid()}")
    try:
        yield tmp
        os.replace(tmp, path)
    finally:
        if tmp.exists():
            tmp.unlink()


def write_csv(path: Path, rows: list[dict], fieldnames: list[str] | None = None) -> None:
    """Rows as a CSV table, written atomically: the columns ``fieldnames`` (a row without one
    leaves it empty), or the first row's keys."""
    with atomic_path(path) as tmp, open(tmp, "w", newline="", encoding="utf-8") as fh:
        writer = csv.DictWriter(fh, fieldnames=list(rows[0]) if fieldnames is None else fieldnames)
        writer.writeheader()
        writer.writerows(rows)


def pyplot(needs: str):
    """matplotlib's pyplot on the Agg backend, or a one-line ConfigError: ``needs`` says what needs
    it (e.g. "the study's plots need") and the error names the extra to install."""
    from warpcaustics.errors import ConfigError

    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise ConfigError(f"{needs} matplotlib: pip install -e '.[study]'") from None
    return plt


def write_json(path: Path, data: dict) -> None:
    with atomic_path(path) as tmp:
        tmp.write_text(json.dumps(data, indent=2, default=jsonable) + "\n", encoding="utf-8")


def jsonable(value):
    """``json.dumps``'s fallback: numpy arrays become lists, numpy scalars numbers, the rest text."""
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, np.generic):
        return value.item()
    return str(value)


def versions() -> dict[str, str]:
    out = {"warpcaustics": __version__, "python": platform.python_version()}
    for dist in ("warp-lang", "numpy", "colour-science", "openexr"):
        try:
            out[dist] = metadata.version(dist)
        except metadata.PackageNotFoundError:
            out[dist] = "not installed"
    return out
