"""Reading ``water.file`` height fields, an input of the scene like ``floor.file`` (numpy only)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from warpcaustics.config.fields import MAX_LENGTH_M
from warpcaustics.errors import ConfigError
from warpcaustics.io.files import input_file

DEFAULT_RESOLUTION = 256
"""Vertices per side when ``water.resolution`` is not given."""


def load_heights(name: str, base_dir: Path, resolution: int | None) -> np.ndarray:
    """Read ``water.file``: a square 2-D array of finite heights [m], ``h[iy, ix]``."""
    path = input_file("water.file", name, base_dir, "a .npy file of heights")
    try:
        heights = np.load(path, allow_pickle=False)
    except Exception as exc:  # noqa: BLE001 - any unreadable file is the same user error
        raise ConfigError(f"water.file = {str(path)!r} is not a readable .npy array "
                          f"({type(exc).__name__}: {exc}); save heights with numpy.save") from None
    if not isinstance(heights, np.ndarray):
        raise ConfigError(f"water.file = {str(path)!r} is a .npz archive; save one array with "
                          f"numpy.save (.npy)")
    if heights.dtype.kind not in "iuf":
        raise ConfigError(f"water.file = {str(path)!r} holds {heights.dtype} values; heights must be "
                          f"real numbers (float or integer) in metres")
    if heights.ndim != 2 or heights.shape[0] != heights.shape[1] or heights.shape[0] < 4:
        raise ConfigError(f"water.file = {str(path)!r} has shape {heights.shape}; it must be a square "
                          f"2-D array of heights, at least 4×4")
    if not np.all(np.isfinite(heights)):
        raise ConfigError(f"water.file = {str(path)!r} must hold finite numbers (found NaN or inf)")
    if np.abs(heights).max(initial=0.0) > MAX_LENGTH_M:  # as every other length: float32 keeps them finite
        raise ConfigError(f"water.file = {str(path)!r} holds a height of {np.abs(heights).max():.3g} m; "
                          f"heights must lie within ±{MAX_LENGTH_M:g} m")
    if resolution is not None and resolution != heights.shape[0]:
        raise ConfigError(f"water.resolution = {resolution} disagrees with water.file, which is "
                          f"{heights.shape[0]}×{heights.shape[0]}; remove water.resolution or set it "
                          f"to {heights.shape[0]}")
    return heights.astype(np.float32)
