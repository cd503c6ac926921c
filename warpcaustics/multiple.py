"""Multiple scattering on the host: ``optics.scattering = "multiple"`` (``kernels/multiple.py``).

A reference mode for flux-ratio scenes on a periodic sea: the floor map comes from a Monte Carlo
random walk of photons that scatter on (by the configured phase function) instead of being lost
from the beam; the single-scattering flux-ratio map of the same frame is kept as the comparison.
"""

from __future__ import annotations

import numpy as np
import warp as wp

from warpcaustics.config import Config
from warpcaustics.kernels import multiple as mc_kernels
from warpcaustics.phase import PhaseFunction
from warpcaustics.water import Surface

TALLY_NAMES = ("transmitted", "floor", "escaped", "absorbed", "unscattered", "truncated")
"""The columns of the walk's tallies [W nm⁻¹ per band]."""


def inverse_cdf_table(phase: PhaseFunction, device: str, nodes: int = 2049) -> np.ndarray:
    """θ [rad] at ``nodes`` equally spaced probabilities of the phase function's cumulative
    distribution P(θ) = 2π ∫₀^θ p sinθ' dθ' (the device's own p, on a grid dense near 0 for
    forward peaks; normalised by its total, which is 1 to the table's accuracy)."""
    theta = np.concatenate([[0.0], np.geomspace(1e-5, np.pi, 20000)])
    p = phase.evaluate(np.cos(theta), device).astype(np.float64)
    integrand = 2.0 * np.pi * p * np.sin(theta)
    cdf = np.concatenate([[0.0], np.cumsum(0.5 * (integrand[1:] + integrand[:-1]) * np.diff(theta))])
    cdf /= cdf[-1]
    return np.interp(np.linspace(0.0, 1.0, nodes), cdf, theta)


class MultipleScattering:
    """Owns the walk's floor accumulator, tallies and phase-function table."""

    def __init__(self, cfg: Config, sun_dirs: np.ndarray, ior: float, sun_irradiance: np.ndarray,
                 absorption_per_m: np.ndarray, scattering_per_m: np.ndarray, device: str):
        """``sun_dirs``: (D, 3) the sun's direction, or the directions over its disk, which the
        photons take in turn."""
        self.device = device
        dirs = np.asarray(sun_dirs, np.float32).reshape(-1, 3)
        self.sun_dirs = wp.array(dirs, dtype=wp.vec3, device=device)
        k = len(sun_irradiance)
        m = cfg.caustics.map_resolution
        walk = mc_kernels.Walk()
        walk.eta = 1.0 / float(ior)
        walk.floor_z = -float(cfg.floor.depth_m)
        walk.extent_m = float(cfg.water.extent_m)
        side = float(cfg.caustics.map_extent_m or cfg.water.extent_m)  # a window, or the patch
        walk.map_center = wp.vec2(*(cfg.caustics.map_center_m if cfg.caustics.map_extent_m else (0.0, 0.0)))
        walk.map_extent_m = side
        walk.map_scale = m / side
        walk.samples = cfg.optics.mc_samples
        walk.max_events = cfg.optics.mc_max_events
        walk.seed = cfg.optics.mc_seed
        self.walk = walk
        self.texel_area_m2 = (side / m) ** 2

        def arr(a):
            return wp.array(np.asarray(a, np.float32), dtype=wp.float32, device=device)

        self.sun_irradiance = arr(sun_irradiance)
        self.absorption = arr(absorption_per_m)
        self.scattering = arr(scattering_per_m)
        self.inverse_cdf = arr(inverse_cdf_table(PhaseFunction.from_optics(cfg.optics, device), device))
        self.texels = wp.zeros((m, m, k), dtype=wp.float32, device=device)
        self.tallies = wp.zeros((k, mc_kernels.TALLIES), dtype=wp.float64, device=device)

    def run(self, surface: Surface, visible: wp.array2d) -> tuple[np.ndarray, dict]:
        """(K, M, M) floor irradiance [W m⁻² nm⁻¹] by the walk, and its tallies per band."""
        n = surface.resolution
        k = self.tallies.shape[0]
        self.texels.zero_()
        self.tallies.zero_()
        wp.launch(mc_kernels.random_walk, dim=(k, n, n, self.walk.samples * self.walk.samples),
                  inputs=[self.walk, surface.positions, surface.normals, visible, self.sun_dirs,
                          self.sun_irradiance,
                          self.absorption, self.scattering, self.inverse_cdf],
                  outputs=[self.texels, self.tallies], device=self.device)
        floor = np.moveaxis(self.texels.numpy(), 2, 0) / self.texel_area_m2
        tallies = self.tallies.numpy()
        photons = k * n * n * self.walk.samples**2
        stats = {"photons": photons, **{name: tallies[:, i].tolist() for i, name in enumerate(TALLY_NAMES)}}
        return floor.astype(np.float32), stats
