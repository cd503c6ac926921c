"""Floor caustics by flux ratio (host side): triangle fluxes, then footprint deposits."""

from __future__ import annotations

import numpy as np
import warp as wp

from warpcaustics.kernels import floor as floor_kernels
from warpcaustics.refraction import Refracted
from warpcaustics.water import Surface


def floor_bytes(n: int, m: int, k: int, groups: int) -> int:
    """Device memory of the refraction and floor stages [bytes]."""
    refraction = groups * n * n * (8 + 4 + 4)
    triangle_flux = k * 2 * n * n * 4
    return refraction + triangle_flux + k * m * m * 4


def floor_caustics(surface: Surface, refracted: Refracted, sun_dir: np.ndarray,
                   sun_irradiance: np.ndarray, attenuation_per_m: np.ndarray, map_resolution: int,
                   device: str) -> tuple[wp.array3d, wp.array4d]:
    """Floor irradiance (K, M, M) [W m^-2 nm^-1] and the triangle fluxes (K, 2, N, N) [W nm^-1].

    Every triangle's flux lands on the floor: ``sum(floor) * texel_area == sum(flux)`` per band.
    """
    n = surface.resolution
    k = len(sun_irradiance)
    groups = refracted.hit_xy.shape[0]
    per_group = k // groups
    flux = wp.empty((k, 2, n, n), dtype=wp.float32, device=device)
    wp.launch(floor_kernels.triangle_flux, dim=(k, n, n, 2),
              inputs=[surface.positions, refracted.path_m, refracted.transmittance,
                      wp.vec3(*np.asarray(sun_dir, np.float32)),
                      wp.array(np.asarray(sun_irradiance, np.float32), dtype=wp.float32, device=device),
                      wp.array(np.asarray(attenuation_per_m, np.float32), dtype=wp.float32,
                               device=device),
                      per_group, float(surface.extent_m)],
              outputs=[flux], device=device)
    floor = wp.zeros((k, map_resolution, map_resolution), dtype=wp.float32, device=device)
    wp.launch(floor_kernels.deposit_footprints, dim=(groups, n, n, 2),
              inputs=[refracted.hit_xy, flux, per_group, float(surface.extent_m)],
              outputs=[floor], device=device)
    return floor, flux
