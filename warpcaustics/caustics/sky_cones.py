"""``sky.sampling = "cones"``: each sky direction's floor map spread as its cell of the sky would
spread it (:mod:`warpcaustics.optics.sky_cells`), on the host, before the small-angle transfer
takes it. On a window of a periodic sea the spread's large scales come from the whole patch's coarse
map (:class:`~warpcaustics.caustics.window.MapWindow`); the coarse map is spread too, for the
transfer after it."""

from __future__ import annotations

import numpy as np

from warpcaustics.caustics.cache import BoundedCache
from warpcaustics.caustics.window import MapWindow
from warpcaustics.config import Config
from warpcaustics.optics.sky import cie_sky_type
from warpcaustics.optics.sky_cells import cell_key, cell_multiplier, dense, sky_cells
from warpcaustics.optics.small_angle import transferred

CACHE_BYTES = 256 << 20
"""The most memory the cells' multipliers keep between frames and renderers of a process; each is
sparse, usually a few thousand values."""

_CACHE = BoundedCache(CACHE_BYTES, size=lambda sparse: sum(a.nbytes for a in sparse))


def _multiplier(j: int, directions: tuple, sky_type: int | None, sun: tuple, ior: float, depth_m: float,
                texel_m: float, m: int) -> tuple:
    """Direction j's cell multiplier, sparse, kept up to ``CACHE_BYTES``."""

    def make():
        points, weights = sky_cells(directions, sky_type, sun, ior)[j]
        return cell_multiplier(np.asarray(directions[j]), points, weights, len(directions), depth_m, ior,
                               texel_m, m)

    return _CACHE.get((j, directions, sky_type, sun, ior, depth_m, texel_m, m), make)


class SkyCones:
    """Spreads each sky direction's single-scattering map over its cell (:meth:`spread`)."""

    def __init__(self, cfg: Config, directions: np.ndarray, sun_direction: np.ndarray, ior: float):
        sky = cfg.sky
        self.sky_type = cie_sky_type(sky)
        self.directions = cell_key(directions)
        self.sun = cell_key(sun_direction)
        self.ior = float(ior)
        self.depth_m = float(cfg.floor.depth_m)
        self.window = MapWindow(cfg)

    def multiplier(self, j: int, texel_m: float, m: int):
        """Direction j's cell multiplier on an M × M grid of ``texel_m`` texels, as a function of the
        band (the same in every band) for :func:`~warpcaustics.optics.small_angle.transferred`."""
        table = dense(_multiplier(j, self.directions, self.sky_type, self.sun, self.ior, self.depth_m,
                                  float(texel_m), m), m)
        return lambda band: table

    def spread(self, j: int, single: np.ndarray, coarse: np.ndarray | None
               ) -> tuple[np.ndarray, np.ndarray | None]:
        """(direction j's map ``single`` (K, M, M) spread over its cell, its whole patch's coarse map
        ``coarse`` (K, Mc, Mc) spread too, or None where the map is the whole periodic patch)."""
        near = self.multiplier(j, self.window.texel_m, single.shape[-1])
        if coarse is None:
            return transferred(single, near), None
        mc = coarse.shape[-1]
        far = self.multiplier(j, self.window.extent_m / mc, mc)
        return self.window.convolve(single, coarse, far, near)
