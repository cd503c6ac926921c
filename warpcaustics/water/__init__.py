"""Water surfaces: every model gives device arrays of vertex positions and unit normals.

Vertices sit at cell centres ``(i + 0.5)·L/N − L/2`` of an N×N grid, row index along +y. Each model
is one module (``heightfield``: ``flat`` and ``heightfield``; ``ocean``: ``fft``; ``procedural``;
``pool``; ``wavepool``) implementing :class:`~warpcaustics.water.surface.Water`, and one line of
:data:`WATER_MODELS` under its ``water.model`` name.
"""

from __future__ import annotations

import numpy as np

from warpcaustics.config import Config, WaterModel
from warpcaustics.water.heightfield import FlatWater, HeightfieldWater
from warpcaustics.water.ocean import (
    FFTOcean,
    cuda_fft_block_dim,
    dispersion,
    fft2,
    from_vec2,
    ifft2,
    initial_spectrum,
    to_vec2,
    wavenumbers,
)
from warpcaustics.water.pool import ShallowWaterPool
from warpcaustics.water.procedural import ProceduralWater
from warpcaustics.water.spectra import (
    SPECTRA,
    elfouhaily_spectrum,
    jonswap_spectrum,
    ocean_spectrum,
    phillips_spectrum,
)
from warpcaustics.water.surface import GRAVITY_M_S2, Surface, Water
from warpcaustics.water.wavepool import WaveEquationPool

__all__ = [
    "FFTOcean", "FlatWater", "GRAVITY_M_S2", "HeightfieldWater", "ProceduralWater", "SPECTRA",
    "ShallowWaterPool", "Surface", "WATER_MODELS", "Water", "WaveEquationPool", "cuda_fft_block_dim",
    "dispersion", "elfouhaily_spectrum", "fft2",
    "from_vec2", "ifft2", "initial_spectrum", "jonswap_spectrum", "make_water", "ocean_spectrum",
    "phillips_spectrum", "to_vec2", "water_bytes", "wavenumbers",
]

WATER_MODELS: dict[WaterModel, type[Water]] = {
    WaterModel.FLAT: FlatWater,
    WaterModel.HEIGHTFIELD: HeightfieldWater,
    WaterModel.FFT: FFTOcean,
    WaterModel.POOL: ShallowWaterPool,
    WaterModel.WAVEPOOL: WaveEquationPool,
    WaterModel.PROCEDURAL: ProceduralWater,
}
"""``water.model`` → the model's class (its ``from_config`` builds it, ``device_bytes`` sizes it)."""


def make_water(cfg: Config, device: str, heights: np.ndarray | None = None,
               floor_relief: np.ndarray | None = None) -> Water:
    """Build the surface model named by ``water.model`` (``heights``: ``water.file``'s array;
    ``floor_relief``: ``floor.file``'s, for the shallow-water pool's depth map)."""
    return WATER_MODELS[cfg.water.model].from_config(cfg, device, heights=heights, floor_relief=floor_relief)


def water_bytes(cfg: Config, n: int, device="cuda") -> int:
    """Device memory the water model of ``cfg`` holds at N×N vertices on ``device`` (a name or a
    ``wp.Device``; CUDA, the default, allocates the most), with the surface of one frame [bytes]."""
    return WATER_MODELS[cfg.water.model].device_bytes(n, device)
