"""GPU Gems ch. 2 octave waves with their analytic gradient (``kernels/water/procedural.py``)."""

from __future__ import annotations

import numpy as np
import warp as wp

from warpcaustics.config import Config
from warpcaustics.kernels.water import procedural as procedural_kernels
from warpcaustics.scene.heights import DEFAULT_RESOLUTION
from warpcaustics.water.surface import SURFACE_BYTES_PER_VERTEX, Surface, surface_arrays


class ProceduralWater:
    """Octave waves: stateless, open, not tileable.

    The patch is the whole sea: light that leaves it is lost, as under a walled pool but with no
    walls to catch it.
    """

    periodic = False
    """The waves do not repeat: footprints do not wrap."""

    def __init__(self, n: int, extent_m: float, device: str, *, amplitude: float = 0.01,
                 frequency: float = 10.0, factor: float = 1.0, speed_rad_s: float = 2.0, octaves: int = 4,
                 scale_m: float = 0.0):
        self.device = device
        self.extent_m = float(extent_m)
        self.n = int(n)
        self.waves = procedural_kernels.OctaveWaves()
        self.waves.amplitude = float(amplitude)
        self.waves.frequency = float(frequency)
        self.waves.factor = float(factor)
        self.waves.speed_rad_s = float(speed_rad_s)
        self.waves.octaves = int(octaves)
        self.waves.scale_m = float(scale_m) if scale_m > 0.0 else 0.5 * self.extent_m

    @classmethod
    def from_config(cls, cfg: Config, device: str, *, heights: np.ndarray | None = None,
                    floor_relief: np.ndarray | None = None) -> ProceduralWater:
        w = cfg.water
        return cls(w.resolution or DEFAULT_RESOLUTION, w.extent_m, device,
                   amplitude=w.procedural_amplitude, frequency=w.procedural_frequency,
                   factor=w.procedural_factor, speed_rad_s=w.procedural_speed_rad_s,
                   octaves=w.procedural_octaves, scale_m=w.procedural_scale_m)

    @staticmethod
    def device_bytes(n: int, device) -> int:
        return n * n * SURFACE_BYTES_PER_VERTEX  # the waves are a struct of numbers: only the surface

    @property
    def resolution(self) -> int:
        return self.n

    def at(self, time_s: float) -> Surface:
        positions, normals = surface_arrays(self.n, self.device)
        wp.launch(procedural_kernels.octave_surface, dim=(self.n, self.n),
                  inputs=[self.waves, float(time_s), self.extent_m], outputs=[positions, normals],
                  device=self.device)
        return Surface(positions, normals, self.extent_m, periodic=False)
