"""Floor caustics by flux ratio (host side): triangle fluxes, then footprint deposits."""

from __future__ import annotations

import numpy as np
import warp as wp

from warpcaustics.kernels.caustics import fluxratio as floor_kernels
from warpcaustics.optics.refraction import Refracted
from warpcaustics.water import Surface


def floor_bytes(n: int, m: int, k: int, groups: int) -> int:
    """Device memory of the refraction and floor stages [bytes]."""
    refraction = groups * n * n * (8 + 4 + 4) + n * n * 4  # hits, paths, T; sun visibility
    triangle_flux = k * 2 * (n + 1) * (n + 1) * 4
    return refraction + triangle_flux + 2 * k * m * m * 4  # accumulation texels + band images


class FloorCaustics:
    """Owns the floor stage's device buffers, reused from frame to frame."""

    def __init__(self, n: int, map_resolution: int, sun_irradiance: np.ndarray,
                 attenuation_per_m: np.ndarray, device: str, *, periodic: bool = True,
                 window: tuple[float, tuple[float, float]] | None = None):
        """``window``: (side W [m], centre (x, y) [m]) of a floor-map window; None: the whole patch."""
        k = len(sun_irradiance)
        m = map_resolution
        self.device = device
        self.sun_irradiance = wp.array(np.asarray(sun_irradiance, np.float32), dtype=wp.float32,
                                       device=device)
        self.attenuation_per_m = wp.array(np.asarray(attenuation_per_m, np.float32), dtype=wp.float32,
                                          device=device)
        quads = n if periodic else n + 1  # a walled surface also has quads reaching its walls
        self.flux = wp.empty((quads, quads, 2, k), dtype=wp.float32, device=device)
        """Flux per triangle and wavelength (Q, Q, 2, K) [W nm^-1], Q quads per side."""
        self.texels = wp.empty((m, m, k), dtype=wp.float32, device=device)
        self.irradiance = wp.empty((k, m, m), dtype=wp.float32, device=device)
        """Floor spectral irradiance (K, M, M) [W m^-2 nm^-1]."""
        self.coarse_count = wp.zeros(1, dtype=wp.int32, device=device)
        """Footprints of the last run deposited by area samples (too large to clip texel by texel)."""
        self.window = window
        self.periodic = periodic

    def floor_map(self, extent_m: float) -> floor_kernels.FloorMap:
        """Where the M×M map lies: the whole patch of side ``extent_m``, or the window. On a
        periodic sea a window as wide as the patch wraps (it is the patch, shifted), and a window's
        centre is reduced to the period nearest the origin (float32 positions stay small)."""
        m = self.texels.shape[0]
        side, centre = (extent_m, (0.0, 0.0)) if self.window is None else self.window
        centre = np.asarray(centre, np.float64)
        if self.periodic:
            centre = centre - extent_m * np.round(centre / extent_m)
        fm = floor_kernels.FloorMap()
        fm.centre = wp.vec2(*centre.astype(np.float32))
        fm.origin = wp.vec2(*(centre - 0.5 * side).astype(np.float32))
        fm.scale = m / side
        whole = self.window is None or side >= extent_m
        fm.wrap = int(self.periodic and whole)
        fm.max_clipped = floor_kernels.MAX_CLIPPED_TEXELS if whole else m * m
        return fm

    def run(self, surface: Surface, refracted: Refracted, sun_dir: np.ndarray, *,
            clear: bool = True, irradiance: wp.array | None = None) -> wp.array3d:
        """Fill :attr:`irradiance`. On a periodic surface every triangle's flux lands on the floor,
        so per band ``sum(irradiance) * texel_area == sum(flux)`` to rounding; in a walled pool
        the flux that would land beyond the walls is not followed. ``clear = False`` adds to the
        last run's map (the directions of a sun disk, each with its share in ``sun_irradiance``);
        ``irradiance`` (K,) replaces ``sun_irradiance`` for this run (a direction of the sky)."""
        quads = self.flux.shape[0]
        if quads != (surface.resolution if surface.periodic else surface.resolution + 1):
            raise ValueError("FloorCaustics was built for the other kind of surface (periodic/walled)")
        k = self.sun_irradiance.shape[0]
        m = self.texels.shape[0]
        groups = refracted.hit_xy.shape[0]
        per_group = k // groups
        wp.launch(floor_kernels.triangle_flux, dim=(quads, quads, 2),
                  inputs=[surface.positions, refracted.path_m, refracted.transmittance,
                          wp.vec3(*np.asarray(sun_dir, np.float32)),
                          self.sun_irradiance if irradiance is None else irradiance,
                          self.attenuation_per_m, per_group, float(surface.extent_m),
                          int(surface.periodic)],
                  outputs=[self.flux], device=self.device)
        if clear:
            self.texels.zero_()
            self.coarse_count.zero_()
        wp.launch(floor_kernels.deposit_footprints, dim=(groups, quads, quads, 2),
                  inputs=[refracted.hit_xy, self.flux, per_group, float(surface.extent_m),
                          int(surface.periodic), self.floor_map(float(surface.extent_m))],
                  outputs=[self.texels, self.coarse_count], device=self.device)
        wp.launch(floor_kernels.texels_to_bands, dim=(m, m), inputs=[self.texels],
                  outputs=[self.irradiance], device=self.device)
        return self.irradiance
