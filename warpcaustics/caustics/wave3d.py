"""Wave caustic texture on the host: ``caustics.method = "wave3d"`` (``kernels/caustics/wave3d.py``).

Per frame, with the water surface held still (light crosses the pool in nanoseconds): the
refracted front in the frozen layers (shared with the eikonal method), then leapfrog steps of the
3-D wave equation until the front has crossed the floor and settled, then ``wave3d_periods``
periods over which u² is averaged into the intensity, then the floor map.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import warp as wp

from warpcaustics.caustics.eikonal import GridCaustics, GridStage, all_lit, make_grid
from warpcaustics.config import Config
from warpcaustics.kernels.caustics import eikonal as eikonal_kernels
from warpcaustics.kernels.caustics import wave3d as wave_kernels
from warpcaustics.optics.snell import fresnel_transmittance
from warpcaustics.water import Surface

COURANT = 0.5
"""v Δt / h; the 3-D leapfrog is stable up to 1/√3."""

BAND = 16
"""Nodes in the damping band under the floor."""

RAMP_PERIODS = 2.0
"""The drive rises over this many periods (a smooth start sends no sharp front)."""

SETTLE_PERIODS = 2.0
"""Periods allowed after the front crosses the bottom before averaging starts."""


def wave3d_bytes(cfg: Config) -> int:
    """Device memory of the wave grid at its deepest (seven N×N×nz float arrays) [bytes]."""
    n = cfg.caustics.wave3d_resolution
    h = cfg.water.extent_m / n
    layers = math.ceil(cfg.floor.depth_m / h) + 3 + BAND + max(1, math.ceil(0.1 * n))
    return 7 * 4 * n * n * layers + 12 * n * n


@dataclass
class WaveStats:
    layers: int = 0
    steps: int = 0
    """Leapfrog steps of the last frame."""
    averaged_steps: int = 0
    """Steps whose u² went into the average."""
    node_updates: int = 0
    """Node-steps actually computed (only the layers the wave can have reached)."""


class Wave3DCaustics(GridCaustics):
    """Owns the wave grid (frozen front, u at three times, ⟨u²⟩) of a scene."""

    def __init__(self, cfg: Config, sun_dir: np.ndarray, ior: float, sun_irradiance: np.ndarray,
                 attenuation_per_m: np.ndarray, device: str, *, periodic: bool,
                 relief: np.ndarray | None = None):
        c = cfg.caustics
        super().__init__(cfg, c.wave3d_resolution, sun_dir, ior, sun_irradiance, attenuation_per_m, device,
                         periodic=periodic, relief=relief)
        self.cells_per_wavelength = float(c.wave3d_cells_per_wavelength)
        self.periods = float(c.wave3d_periods)
        self.gain = float(c.wave3d_gain)
        self.exponent = float(c.wave3d_exponent)
        self.eta = wp.empty((self.n, self.n), dtype=wp.float32, device=device)
        self.stats = WaveStats()

    def _allocate(self, layers: int) -> None:
        if layers != self.layers:
            shape = (layers, self.n, self.n)
            self.psi, self.intensity, self.path, self.u, self.u_old, self.u_new, self.energy = (
                wp.empty(shape, dtype=wp.float32, device=self.device) for _ in range(7))
            self.layers = layers

    def params(self, grid) -> wave_kernels.WaveParams:
        """Drive and step parameters. The still-water wave vector κ = ω_s G (|κ| = 2π/λ in the
        water); on a periodic grid its horizontal part is rounded to the patch's lattice 2π m/L
        (the beam tilts by at most λ/2L rad), and the temporal frequency solves the leapfrog's
        dispersion relation sin²(ωΔt/2) = C² Σ sin²(κ_i h/2), so the plane wave is an exact mode."""
        p = wave_kernels.WaveParams()
        wavelength = self.cells_per_wavelength * self.h  # in the water [m]
        p.omega_space = 2.0 * math.pi / (self.ior * wavelength)
        g = np.array([grid.gradient[0], grid.gradient[1], grid.gradient[2]], np.float64)
        kappa = p.omega_space * g
        if self.periodic:
            lattice = 2.0 * math.pi / self.extent_m
            kappa[:2] = np.round(kappa[:2] / lattice) * lattice
        self.kappa = kappa
        p.kappa = wp.vec3(*kappa.astype(np.float32))
        p.dt = COURANT * self.h * self.ior
        p.courant2 = COURANT * COURANT
        p.omega = self._discrete_omega(kappa, p.dt)
        # vertical group velocity of that mode [m per m of optical path], for the crossing time
        eps = 1.0e-4 * float(np.linalg.norm(kappa))
        dz = np.array([0.0, 0.0, eps])
        up, down = self._discrete_omega(kappa + dz, p.dt), self._discrete_omega(kappa - dz, p.dt)
        self.group_vz = abs(up - down) / (2.0 * eps)
        p.group_vz = self.group_vz
        p.ramp_time = RAMP_PERIODS * 2.0 * math.pi / p.omega
        p.band = BAND
        cos_i = float(self.sun_dir[2])
        cos_t = abs(float(g[2])) / self.ior  # still water's refracted direction, G = n_w t0
        p.amplitude_flat = math.sqrt(float(fresnel_transmittance(cos_i, 1.0 / self.ior)) * cos_i / cos_t)
        # the quadratic ramp that reflected least of a plane wave at 90°, 40° and 15° suns (measured)
        p.sigma_max = 10.0 / (BAND * p.dt)
        return p

    def _discrete_omega(self, kappa: np.ndarray, dt: float) -> float:
        """ω of the leapfrog's dispersion relation sin²(ωΔt/2) = C² Σ sin²(κ_i h/2)."""
        s2 = float(np.sum(np.sin(kappa * self.h / 2.0) ** 2))
        return 2.0 / dt * math.asin(min(COURANT * math.sqrt(s2), 1.0))

    def run(self, surface: Surface, highest_m: float, visible: wp.array2d | None = None, *,
            steps: int | None = None) -> wp.array3d:
        """Fill :attr:`irradiance` for ``surface``; ``steps`` overrides the number of steps (the
        last ``wave3d_periods`` periods are averaged, or all of them if fewer)."""
        grid = make_grid(self.n, self.extent_m, highest_m, self.floor_z, 2 + BAND, self.periodic,
                         self.ior, self.sun_dir)
        self._allocate(grid.layers)
        dev, n = self.device, self.n
        visible = visible if visible is not None else all_lit(surface, dev)
        wp.launch(eikonal_kernels.init_front, dim=(n, n),
                  inputs=[grid, surface.positions, surface.normals, visible, float(surface.extent_m),
                          int(surface.periodic)],
                  outputs=[self.top, self.psi, self.intensity, self.path], device=dev)
        wp.launch(wave_kernels.surface_heights, dim=(n, n),
                  inputs=[grid, surface.positions, float(surface.extent_m), int(surface.periodic)],
                  outputs=[self.eta], device=dev)
        for a in (self.u, self.u_old, self.u_new, self.energy):
            a.zero_()
        p = self.params(grid)
        period_steps = 2.0 * math.pi / p.omega / p.dt
        average = max(1, round(self.periods * period_steps))
        top_max = int(self.top.numpy().max())
        if steps is None:
            # the front descends at the mode's vertical group velocity (slower than v for a
            # tilted beam, and slower still on the grid): steps until it reaches the bottom band
            crossing = (grid.layers - top_max) * self.h / (self.group_vz * p.dt)
            steps = math.ceil(crossing + (RAMP_PERIODS + SETTLE_PERIODS) * period_steps) + average
        average = min(average, steps)
        stats = WaveStats(layers=grid.layers, steps=steps, averaged_steps=average)
        ramp_t = RAMP_PERIODS * period_steps * p.dt
        for s in range(steps):
            t = (s + 1) * p.dt
            active = min(grid.layers, top_max + s + 2)
            t_now = s * p.dt
            ramp_now = 0.5 * (1.0 - math.cos(math.pi * min(t_now / ramp_t, 1.0)))
            wp.launch(wave_kernels.step, dim=(active, n, n),
                      inputs=[grid, p, self.top, self.u, self.u_old, t_now, ramp_now], outputs=[self.u_new],
                      device=dev)
            ramp = 0.5 * (1.0 - math.cos(math.pi * min(t / ramp_t, 1.0)))
            wp.launch(wave_kernels.drive, dim=(n, n),
                      inputs=[grid, p, self.top, self.psi, self.intensity, t, ramp], outputs=[self.u_new],
                      device=dev)
            self.u_old, self.u, self.u_new = self.u, self.u_new, self.u_old
            stats.node_updates += active * n * n
            if s >= steps - average:
                wp.launch(wave_kernels.accumulate, dim=(grid.layers, n, n), inputs=[self.u],
                          outputs=[self.energy], device=dev)
        k_bands, m = self.irradiance.shape[0], self.irradiance.shape[1]
        wp.launch(wave_kernels.floor_irradiance, dim=(k_bands, m, m),
                  inputs=[grid, self.energy, float(average), self.eta, self.gain, self.exponent,
                          self.texel_z, self.texel_normal, self.sun_irradiance, self.attenuation_per_m],
                  outputs=[self.irradiance], device=dev)
        self.grid = grid
        self.stats = stats
        return self.irradiance

    def floor_map(self, surface: Surface, water, time_s: float, highest_m: float, visible: wp.array2d,
                  flux_ratio: np.ndarray) -> tuple[np.ndarray, dict]:
        """(K, M, M) floor irradiance by the wave texture, and the RenderResult fields it adds."""
        floor = self.run(surface, highest_m, visible).numpy().copy()
        return floor, {"wave3d_stats": vars(self.stats).copy()}

    def texture(self) -> np.ndarray:
        """The wave texture of the last frame: a·(2⟨u²⟩)^b on the (nz, N, N) nodes, layer 0 on top."""
        e = 2.0 * self.energy.numpy().astype(np.float64) / max(self.stats.averaged_steps, 1)
        return self.gain * np.maximum(e, 0.0) ** self.exponent

    def bytes_held(self) -> int:
        arrays = [self.top, self.eta, self.irradiance] + (
            [self.psi, self.intensity, self.path, self.u, self.u_old, self.u_new, self.energy]
            if self.layers else [])
        return sum(a.capacity for a in arrays)


class Wave3DStage(GridStage):
    """``wave3d``: the 3-D wave-equation caustics."""

    name = "wave3d"
    grid = Wave3DCaustics
    grid_bytes = staticmethod(wave3d_bytes)
    memory_key = "caustics.wave3d_resolution"
