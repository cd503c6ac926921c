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
