"""What every water model shares: the :class:`Surface` it yields, the interface it implements and
the sizes its memory estimate counts in."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np
import warp as wp

from warpcaustics.config import Config

GRAVITY_M_S2 = 9.81

FLOAT32_BYTES = 4
VEC2_BYTES = 8
"""A complex value as ``wp.vec2``: the FFT ocean's spectra."""
VEC3_BYTES = 12
SURFACE_BYTES_PER_VERTEX = 2 * VEC3_BYTES
"""Positions and normals, the arrays :func:`surface_arrays` allocates for every Surface."""


@dataclass
class Surface:
    """The water surface at one instant, on the device."""

    positions: wp.array2d
    """(N, N) vertex positions [m], ``positions[iy, ix]``."""
    normals: wp.array2d
    """(N, N) unit normals pointing up, out of the water."""
    extent_m: float
    """Side L of the periodic patch [m]."""
    jacobian: wp.array2d | None = None
    """(N, N) Jacobian of the choppy horizontal map (≤ 0 where the surface folds), if any."""
    periodic: bool = True
    """True for a tileable patch (footprints wrap); False for a pool or the procedural waves."""

    @property
    def resolution(self) -> int:
        return self.positions.shape[0]


def surface_arrays(n: int, device) -> tuple[wp.array2d, wp.array2d]:
    """Uninitialised (N, N) positions and normals for a Surface (:data:`SURFACE_BYTES_PER_VERTEX`)."""
    return (wp.empty((n, n), dtype=wp.vec3, device=device),
            wp.empty((n, n), dtype=wp.vec3, device=device))


def is_cuda(device) -> bool:
    """Whether ``device`` (a ``wp.Device`` or a name such as ``"cuda:0"``) is a GPU. A name is read
    without asking Warp, so memory estimates for CUDA work on a machine without one."""
    return str(device).split(":")[0] == "cuda"


class Water(Protocol):
    """A water model, registered by its ``water.model`` name in ``warpcaustics.water.WATER_MODELS``."""

    device: str
    extent_m: float
    periodic: bool
    """Whether the patch tiles (floor footprints wrap) or is the whole, walled or open, water."""

    @classmethod
    def from_config(cls, cfg: Config, device: str, *, heights: np.ndarray | None = None,
                    floor_relief: np.ndarray | None = None) -> Water:
        """The model of ``cfg`` (``heights``: ``water.file``'s array; ``floor_relief``: ``floor.file``'s)."""

    @staticmethod
    def device_bytes(n: int, device) -> int:
        """Bytes of every device array the model holds at N×N vertices plus the Surface one
        :meth:`at` returns, on ``device`` (a name or a ``wp.Device``)."""

    @property
    def resolution(self) -> int:
        """Vertices per side, N."""

    def at(self, time_s: float) -> Surface:
        """The surface at ``time_s`` [s]."""
