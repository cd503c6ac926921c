"""The wave-equation pool (host side): Mercier's Gaussian bump, the webgl-water kind of pool.

A damped linear wave equation on the surface elevation η (``kernels/water/pool.py:wave_equation_step``)
with reflecting walls; drops add Gaussian bumps. Like the shallow-water pool it is stateful: each
frame steps on from the previous one.
"""

from __future__ import annotations

import math

import numpy as np
import warp as wp

from warpcaustics.config import Config, DropConfig
from warpcaustics.errors import WarpcausticsError
from warpcaustics.kernels.water import pool as pool_kernels
from warpcaustics.water.pool import MAX_SUBSTEPS_PER_CALL, WalledPool
from warpcaustics.water.surface import FLOAT32_BYTES, GRAVITY_M_S2, SURFACE_BYTES_PER_VERTEX, Surface


class WaveEquationPool(WalledPool):
    """η_tt = c² ∇²η − γ η_t in a square pool with walls; c = √(g·depth) unless given."""

    STATE_FIELDS = ("eta", "eta_prev")

    def __init__(self, n: int, extent_m: float, depth_m: float, device: str, *,
                 wave_speed_m_s: float = 0.0, damping_per_s: float = 0.5, cfl: float = 0.4,
                 drops: tuple[DropConfig, ...] = ()):
        self.device = device
        self.extent_m = float(extent_m)
        self.cell_m = self.extent_m / n
        self.depth_m = float(depth_m)
        self.speed = wave_speed_m_s if wave_speed_m_s > 0 else math.sqrt(GRAVITY_M_S2 * depth_m)
        self.damping = float(damping_per_s)
        # Leapfrog stability in 2-D: c Δt / Δ ≤ 1/√2 (the config caps cfl at 0.7).
        self.dt = min(cfl, 0.7) * self.cell_m / self.speed
        self.eta = wp.zeros((n, n), dtype=wp.float32, device=device)
        self.eta_prev = wp.zeros((n, n), dtype=wp.float32, device=device)
        self._next = wp.zeros((n, n), dtype=wp.float32, device=device)
        self._zero_depth = wp.zeros((n, n), dtype=wp.float32, device=device)
        self._init_drops(drops)
        self._drop_bumps(0.0)

    @classmethod
    def from_config(cls, cfg: Config, device: str, *, heights: np.ndarray | None = None,
                    floor_relief: np.ndarray | None = None) -> WaveEquationPool:
        w = cfg.water
        return cls(w.resolution, w.extent_m, cfg.floor.depth_m, device, wave_speed_m_s=w.wave_speed_m_s,
                   damping_per_s=w.damping_per_s, cfl=w.cfl, drops=w.drops)

    @staticmethod
    def device_bytes(n: int, device) -> int:
        return n * n * (4 * FLOAT32_BYTES + SURFACE_BYTES_PER_VERTEX)  # η, η⁻, η⁺, zero depth; the surface

    @property
    def resolution(self) -> int:
        return self.eta.shape[0]

    def step(self) -> None:
        n = self.resolution
        courant2 = (self.speed * self.dt / self.cell_m) ** 2
        wp.launch(pool_kernels.wave_equation_step, dim=(n, n),
                  inputs=[self.eta, self.eta_prev, courant2, self.damping * self.dt],
                  outputs=[self._next], device=self.device)
        self.eta_prev, self.eta, self._next = self.eta, self._next, self.eta_prev
        self.time_s += self.dt

    def advance(self, time_s: float) -> None:
        """Step to the last multiple of the fixed Δt not after ``time_s`` (frames snap to it)."""
        self._check_forward(time_s)
        # counted once, to within a millionth of a step (a tolerance in seconds looped forever once
        # Δt fell below it: a 1e-6 m pool has Δt ~ 1e-9 s)
        steps = math.floor((time_s - self.time_s) / self.dt + 1e-6)
        if steps > MAX_SUBSTEPS_PER_CALL:
            raise WarpcausticsError(
                f"the wave pool needs {steps:.3g} steps of Δt = {self.dt:.3g} s to reach t = {time_s:g} s "
                f"(more than {MAX_SUBSTEPS_PER_CALL:.0e}); lower water.resolution, enlarge water.extent_m "
                "or render an earlier time")
        for _ in range(steps):
            self.step()
            self._drop_bumps(self.time_s)

    def _drop_bumps(self, time_s: float) -> None:
        # a bump released at rest: raise η and η⁻ alike, so there is no initial velocity
        self._apply_drops_until(time_s, pool_kernels.add_bump, [self.eta, self.eta_prev])

    def at(self, time_s: float) -> Surface:
        self.advance(time_s)
        return self._surface(self.eta, self._zero_depth)

    def energy(self) -> float:
        """Discrete wave energy ½Σ(η_t² + c²|∇η|²)Δ² [m⁴/s²·…], for checking the damping rate."""
        eta = self.eta.numpy().astype(np.float64)
        prev = self.eta_prev.numpy().astype(np.float64)
        eta_t = (eta - prev) / self.dt
        gx = np.diff(eta, axis=1) / self.cell_m
        gy = np.diff(eta, axis=0) / self.cell_m
        return 0.5 * (np.sum(eta_t**2) + self.speed**2 * (np.sum(gx**2) + np.sum(gy**2))) * self.cell_m**2
