"""Multiple scattering on the host: ``optics.scattering = "multiple"`` (``kernels/caustics/multiple.py``).

A reference mode for flux-ratio scenes on a periodic sea: the floor map comes from a Monte Carlo
random walk of photons that scatter on (by the configured phase function) instead of being lost
from the beam; the single-scattering flux-ratio map of the same frame is kept as the comparison.
The sky, when there is one, is walked apart from the sun (its own floor map and tallies), its
photons taking the sky's directions in turn. The walk's boundaries are the moving surface (Fresnel
reflection and transmission at its local normal, total internal reflection) and the floor
(``floor.albedo``, Lambertian); the map is the irradiance incident on the floor.
"""

from __future__ import annotations

import numpy as np
import warp as wp

from warpcaustics.config import Config, OpticsConfig
from warpcaustics.kernels.caustics import multiple as mc_kernels
from warpcaustics.optics.phase import quadrature_for
from warpcaustics.water import Surface

TALLY_NAMES = ("transmitted", "floor", "escaped", "absorbed", "unscattered", "truncated", "roulette",
               "floor_reflected", "surface_reflected")
"""The columns of the walk's tallies [W nm⁻¹ per band]. ``floor``: every arrival on the floor (a photon
reflected back down counts again), ``floor_reflected``: what the floor's albedo sent back up,
``surface_reflected``: what the surface reflected back into the water (Fresnel and total internal
reflection; it stays in the walk), ``unscattered``: the floor's light that came straight from the
surface; ``roulette``: the weight of the photons that Russian roulette ended less what its survivors
gained (zero on average). So transmitted = floor − floor_reflected + escaped + absorbed + truncated +
roulette exactly (:func:`balance`)."""


def balance(stats: dict) -> np.ndarray:
    """(K,) the walk's books per band: what they account for over what entered the water (1 when
    every watt is found: on the floor, escaped, absorbed, truncated or in the roulette)."""
    kept = (np.asarray(stats["floor"]) - np.asarray(stats["floor_reflected"]) + np.asarray(stats["escaped"])
            + np.asarray(stats["absorbed"]) + np.asarray(stats["truncated"]) + np.asarray(stats["roulette"]))
    return kept / np.asarray(stats["transmitted"])

TURN_STREAM = 0x2545F491
"""Added to a walk's seed for the random turn of the directions over each cell's photons."""

SKY_STREAM = 0x5851F42D
"""Added to ``optics.mc_seed`` for the sky's walk, so its photons draw other random numbers than the
sun's."""


def inverse_cdf_table(optics: OpticsConfig, nodes: int = 2049) -> np.ndarray:
    """θ [rad] at ``nodes`` equally spaced probabilities of the phase function's cumulative
    distribution P(θ) = 2π ∫₀^θ p sinθ' dθ', from its float64 quadrature
    (:func:`~warpcaustics.optics.phase.quadrature_for`: the power-law cone of Petzold's tables
    included, which a float32 cos θ could not resolve)."""
    theta, weight = quadrature_for(optics)
    cdf = np.cumsum(weight) - 0.5 * weight
    cdf /= weight.sum()
    return np.interp(np.linspace(0.0, 1.0, nodes), cdf, theta)


class MultipleScattering:
    """Owns the walk's floor accumulator, tallies and phase-function table."""

    def __init__(self, cfg: Config, sun_dirs: np.ndarray, ior: float, sun_irradiance: np.ndarray,
                 absorption_per_m: np.ndarray, scattering_per_m: np.ndarray, device: str, *,
                 floor_albedo: np.ndarray | None = None, surface_reflects: bool = True,
                 sky_dirs: np.ndarray | None = None, sky_irradiance: np.ndarray | None = None):
        """``sun_dirs``: (S, 3) the sun's direction, or the directions over its disk, which the
        photons take in turn, sharing ``sun_irradiance`` (K,) equally. ``sky_dirs`` (D, 3) and
        ``sky_irradiance`` (D, K): the sky's directions and each one's irradiance on a plane
        perpendicular to it [W m⁻² nm⁻¹], for :meth:`run_sky`. ``floor_albedo`` (K,): the floor's
        Lambertian albedo per band (None: a black floor, which ends every photon reaching it).
        ``surface_reflects=False`` lets all upwelling light through the surface (no Fresnel
        reflection, no total internal reflection): only for comparisons with solvers that have no
        reflecting top."""
        self.device = device
        dirs = np.asarray(sun_dirs, np.float32).reshape(-1, 3)
        self.sun_dirs = wp.array(dirs, dtype=wp.vec3, device=device)
        k = len(sun_irradiance)
        share = np.asarray(sun_irradiance, np.float64) / len(dirs)  # each disk direction's
        self.sun_irradiance = wp.array(np.tile(share, (len(dirs), 1)).astype(np.float32), dtype=wp.float32,
                                       device=device)
        self.sky_dirs = self.sky_irradiance = None
        if sky_dirs is not None:
            self.set_sky(sky_dirs, sky_irradiance)
        m = cfg.caustics.map_resolution
        side, centre = cfg.map_window  # a window, or the patch

        def walk(seed: int) -> mc_kernels.Walk:
            w = mc_kernels.Walk()
            w.eta = 1.0 / float(ior)
            w.floor_z = -float(cfg.floor.depth_m)
            w.extent_m = float(cfg.water.extent_m)
            w.map_center = wp.vec2(*centre)
            w.map_extent_m = side
            w.map_scale = m / side
            w.samples = cfg.optics.mc_samples
            w.max_events = cfg.optics.mc_max_events
            w.surface_reflects = int(surface_reflects)
            w.seed = seed
            w.turn_seed = (seed + TURN_STREAM) % 2**31
            return w

        self.walk = walk(cfg.optics.mc_seed)
        self.sky_walk = walk((cfg.optics.mc_seed + SKY_STREAM) % 2**31)
        self.texel_area_m2 = (side / m) ** 2
        self.extent_m = float(cfg.water.extent_m)

        def arr(a):
            return wp.array(np.asarray(a, np.float32), dtype=wp.float32, device=device)

        self.absorption = arr(absorption_per_m)
        self.scattering = arr(scattering_per_m)
        self.inverse_cdf = arr(inverse_cdf_table(cfg.optics))
        self.floor_albedo = arr(np.zeros(k) if floor_albedo is None else np.broadcast_to(floor_albedo, (k,)))
        self.texels = wp.zeros((m, m, k), dtype=wp.float32, device=device)
        self.tallies = wp.zeros((k, mc_kernels.TALLIES), dtype=wp.float64, device=device)

    def set_sky(self, sky_dirs: np.ndarray, sky_irradiance: np.ndarray) -> None:
        """The sky's directions (D, 3) and each one's irradiance (D, K) for :meth:`run_sky` (again
        each frame with ``sky.sampling = "halves"``, whose directions are drawn anew)."""
        sky_dirs = np.asarray(sky_dirs, np.float32).reshape(-1, 3)
        self.sky_dirs = wp.array(sky_dirs, dtype=wp.vec3, device=self.device)
        self.sky_irradiance = wp.array(np.asarray(sky_irradiance, np.float32).reshape(len(sky_dirs), -1),
                                       dtype=wp.float32, device=self.device)

    def run(self, surface: Surface, visible: wp.array2d) -> tuple[np.ndarray, dict]:
        """The sun's walk: (K, M, M) floor irradiance [W m⁻² nm⁻¹] and the tallies per band; the
        crests shade every direction of the disk as ``visible`` (N, N), the centre's, does."""
        n = surface.resolution
        return self._walk(surface, visible.reshape((1, n, n)), self.sun_dirs, self.sun_irradiance, self.walk)

    def run_sky(self, surface: Surface, visible: wp.array3d) -> tuple[np.ndarray, dict]:
        """The sky's walk, like :meth:`run`, with ``visible`` (D, N, N) the crests' shading from
        each sky direction."""
        if self.sky_dirs is None:
            raise ValueError("this walk was made without a sky (sky_dirs)")
        return self._walk(surface, visible, self.sky_dirs, self.sky_irradiance, self.sky_walk)

    def _walk(self, surface, visible, dirs, irradiance, walk) -> tuple[np.ndarray, dict]:
        n = surface.resolution
        k = self.tallies.shape[0]
        heights = surface.positions.numpy()[..., 2]
        margin = 1e-5 * (1.0 + float(np.abs(heights).max()))  # the bilinear field stays inside
        walk.surface_low = float(heights.min()) - margin
        walk.surface_high = float(heights.max()) + margin
        cell = self.extent_m / n  # the bilinear field's slope is bounded by its steepest edges
        sx = np.abs(np.roll(heights, -1, axis=1) - heights).max() / cell
        sy = np.abs(np.roll(heights, -1, axis=0) - heights).max() / cell
        walk.surface_slope = wp.vec2(float(sx) * (1.0 + 1e-5), float(sy) * (1.0 + 1e-5))
        self.texels.zero_()
        self.tallies.zero_()
        wp.launch(mc_kernels.random_walk, dim=(k, n, n, walk.samples * walk.samples),
                  inputs=[walk, surface.positions, surface.normals, visible, dirs, irradiance,
                          self.absorption, self.scattering, self.inverse_cdf, self.floor_albedo],
                  outputs=[self.texels, self.tallies], device=self.device)
        floor = np.moveaxis(self.texels.numpy(), 2, 0) / self.texel_area_m2
        tallies = self.tallies.numpy()
        photons = k * n * n * walk.samples**2
        stats = {"photons": photons, **{name: tallies[:, i].tolist() for i, name in enumerate(TALLY_NAMES)}}
        return floor.astype(np.float32), stats
