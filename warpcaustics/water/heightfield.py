"""Still water: a static periodic height field (``heightfield``, from ``water.file``) and the
``flat`` surface (all heights zero); normals by central differences (``kernels/water/heightfield.py``)."""

from __future__ import annotations

import numpy as np
import warp as wp

from warpcaustics.config import Config
from warpcaustics.kernels.water import heightfield as hf_kernels
from warpcaustics.scene.heights import DEFAULT_RESOLUTION
from warpcaustics.water.surface import FLOAT32_BYTES, SURFACE_BYTES_PER_VERTEX, Surface, surface_arrays


class HeightfieldWater:
    """A static periodic height field."""

    periodic = True
    """A tileable patch: floor footprints wrap."""

    def __init__(self, heights: np.ndarray, extent_m: float, device: str):
        self.device = device
        self.extent_m = extent_m
        self.heights = wp.array(np.ascontiguousarray(heights, dtype=np.float32), dtype=wp.float32,
                                device=device)

    @classmethod
    def from_config(cls, cfg: Config, device: str, *, heights: np.ndarray | None = None,
                    floor_relief: np.ndarray | None = None) -> HeightfieldWater:
        """The heights of ``water.file`` (the scene loaded them) over ``water.extent_m``."""
        return cls(heights, cfg.water.extent_m, device)

    @staticmethod
    def device_bytes(n: int, device) -> int:
        return n * n * (FLOAT32_BYTES + SURFACE_BYTES_PER_VERTEX)  # heights; the surface

    @property
    def resolution(self) -> int:
        return self.heights.shape[0]

    def at(self, time_s: float) -> Surface:
        n = self.resolution
        positions, normals = surface_arrays(n, self.device)
        wp.launch(hf_kernels.heightfield_surface, dim=(n, n),
                  inputs=[self.heights, self.extent_m], outputs=[positions, normals],
                  device=self.device)
        return Surface(positions, normals, self.extent_m)


class FlatWater(HeightfieldWater):
    """Water at rest: a height field of zeros at ``water.resolution``."""

    @classmethod
    def from_config(cls, cfg: Config, device: str, *, heights: np.ndarray | None = None,
                    floor_relief: np.ndarray | None = None) -> FlatWater:
        n = cfg.water.resolution or DEFAULT_RESOLUTION
        return cls(np.zeros((n, n), np.float32), cfg.water.extent_m, device)
