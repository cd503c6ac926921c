"""Reading ``water.file`` height fields, an input of the scene like ``floor.file`` (numpy only)."""

from __future__ import annotations

from dataclasses import fields
from pathlib import Path

import numpy as np

from warpcaustics.config import WaterConfig
from warpcaustics.config.fields import MAX_LENGTH_M
from warpcaustics.errors import ConfigError
from warpcaustics.io.files import input_file, load_npy

DEFAULT_RESOLUTION = 256
"""Vertices per side when ``water.resolution`` is not given."""
MAX_FILE_RESOLUTION = next(f for f in fields(WaterConfig) if f.name == "resolution").metadata["range"][1]
"""The largest height field a file may give: ``water.resolution``'s own upper bound."""


def load_heights(name: str, base_dir: Path, resolution: int | None) -> np.ndarray:
    """Read ``water.file``: a square 2-D array of finite heights [m], ``h[iy, ix]``."""
    path = input_file("water.file", name, base_dir, "a .npy file of heights")
    heights = load_npy("water.file", path, "heights")
    if heights.dtype.kind not in "iuf":
        raise ConfigError(f"water.file = {str(path)!r} holds {heights.dtype} values; heights must be "
                          f"real numbers (float or integer) in metres")
    if heights.ndim != 2 or heights.shape[0] != heights.shape[1] or heights.shape[0] < 4:
        raise ConfigError(f"water.file = {str(path)!r} has shape {heights.shape}; it must be a square "
                          f"2-D array of heights, at least 4×4")
    if heights.shape[0] > MAX_FILE_RESOLUTION:  # before any pass over the whole array
        raise ConfigError(f"water.file = {str(path)!r} is {heights.shape[0]}×{heights.shape[0]}; "
                          f"water.resolution allows at most {MAX_FILE_RESOLUTION} (resample it)")
    if not np.all(np.isfinite(heights)):
        raise ConfigError(f"water.file = {str(path)!r} must hold finite numbers (found NaN or inf)")
    highest = float(np.abs(heights.astype(np.float64)).max(initial=0.0))
    if highest > MAX_LENGTH_M:  # as every other length: float32 keeps them finite
        raise ConfigError(f"water.file = {str(path)!r} holds a height of {highest:.3g} m; heights must "
                          f"lie within ±{MAX_LENGTH_M:g} m")
    if resolution is not None and resolution != heights.shape[0]:
        raise ConfigError(f"water.resolution = {resolution} disagrees with water.file, which is "
                          f"{heights.shape[0]}×{heights.shape[0]}; remove water.resolution or set it "
                          f"to {heights.shape[0]}")
    return heights.astype(np.float32)
