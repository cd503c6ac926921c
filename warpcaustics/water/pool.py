"""The shallow-water pool (host side): a stateful surface that steps forward in time.

Sandberg's "Navier–Stokes water" dynamic pool: depth-averaged mass and momentum with gravity and
viscosity (``kernels/water/pool.py``), reflecting walls at ±L/2, drops at given times and places, and a
disc-shaped body moving on a circular path that drags the water under it towards its velocity. Each
call to :meth:`ShallowWaterPool.at` advances the state to the asked time with CFL-limited
substeps, so an animation steps frame k from frame k−1 instead of re-simulating from t = 0.
"""

from __future__ import annotations

import math

import numpy as np
import warp as wp

from warpcaustics.config import BodyConfig, Config, DropConfig, FloorShape
from warpcaustics.errors import ConfigError, WarpcausticsError
from warpcaustics.kernels.water import pool as pool_kernels
from warpcaustics.scene.receivers import floor_relief_height
from warpcaustics.water.surface import FLOAT32_BYTES, SURFACE_BYTES_PER_VERTEX, Surface, surface_arrays

MAX_SUBSTEPS_PER_CALL = 1_000_000
SPEED_REFRESH_SUBSTEPS = 4
"""Substeps between measurements of the maximum wave speed (the CFL limit); the configured
Courant number (default 0.4) leaves room for the speed to grow in between."""


class WalledPool:
    """What the walled, stateful pools share: drops due at given times, the check that frames go
    forward, and the surface built from a height field (``pool_surface``)."""

    periodic = False
    """Walled: light beyond the walls is not followed."""

    def _init_drops(self, drops: tuple[DropConfig, ...]) -> None:
        self.time_s = 0.0
        self._drops = sorted(drops, key=lambda d: d.time_s)

    STATE_FIELDS: tuple[str, ...] = ()
    """Names of the device arrays that hold the pool's state (with its time, drops and substeps)."""

    def state(self) -> dict:
        """The pool's state as numpy arrays and numbers: enough to continue exactly (a checkpoint)."""
        out = {name: getattr(self, name).numpy().copy() for name in self.STATE_FIELDS}
        out.update(time_s=self.time_s, drops_left=len(self._drops), substeps=getattr(self, "substeps", 0))
        return out

    def load_state(self, state: dict) -> None:
        """Continue from a :meth:`state` of a pool built from the same config."""
        for name in self.STATE_FIELDS:
            array = getattr(self, name)
            if tuple(state[name].shape) != tuple(array.shape):
                raise WarpcausticsError(f"pool checkpoint has {name} of shape {state[name].shape}, the pool "
                                        f"{tuple(array.shape)}: it belongs to another scene")
            array.assign(np.ascontiguousarray(state[name], dtype=np.float32))
        self.time_s = float(state["time_s"])
        left = int(state["drops_left"])
        self._drops = self._drops[len(self._drops) - left:] if left else []
        if hasattr(self, "substeps"):
            self.substeps = int(state["substeps"])

    def _check_forward(self, time_s: float) -> None:
        if time_s < self.time_s - 1e-9:
            raise WarpcausticsError(
                f"the pool is stateful: time_s = {time_s:g} s comes before its current time "
                f"{self.time_s:g} s; render its frames in increasing time")

    def _apply_drops_until(self, time_s: float, kernel, fields) -> bool:
        """Launch ``kernel`` on each of ``fields`` for every drop due by ``time_s``; True if any."""
        n = fields[0].shape[0]
        dropped = False
        while self._drops and self._drops[0].time_s <= time_s + 1e-12:
            d = self._drops.pop(0)
            dropped = True
            for field in fields:
                wp.launch(kernel, dim=(n, n),
                          inputs=[field, self.extent_m, d.x_m, d.y_m, d.radius_m, d.height_m],
                          device=self.device)
        return dropped

    def _surface(self, height: wp.array2d, floor_depth: wp.array2d) -> Surface:
        """Surface of elevation ``height − floor_depth`` at the cell centres, walled."""
        n = height.shape[0]
        positions, normals = surface_arrays(n, self.device)
        wp.launch(pool_kernels.pool_surface, dim=(n, n), inputs=[height, floor_depth, self.extent_m],
                  outputs=[positions, normals], device=self.device)
        return Surface(positions, normals, self.extent_m, periodic=False)


def floor_depth_map(cfg: Config, floor_relief: np.ndarray | None) -> np.ndarray | float:
    """Water depth at rest at the pool's cell centres [m]: ``floor.depth_m`` on a flat floor, else
    minus the floor relief's height there. Raises a ConfigError where the floor reaches the water."""
    if cfg.floor.shape is FloorShape.FLAT:
        return cfg.floor.depth_m
    n, extent = cfg.water.resolution, cfg.water.extent_m
    x = (np.arange(n) + 0.5) * extent / n - extent / 2
    depth = -floor_relief_height(cfg.floor, floor_relief, extent, *np.meshgrid(x, x))
    if depth.min() <= 0.0:
        iy, ix = np.unravel_index(np.argmin(depth), depth.shape)
        raise ConfigError(f"floor.shape = {cfg.floor.shape.value!r} reaches the water surface at "
                          f"(x, y) = ({x[ix]:.2f}, {x[iy]:.2f}) m (depth {depth.min():.3f} m); the pool "
                          "needs water everywhere: make floor.depth_m larger or the relief gentler")
    return depth


class ShallowWaterPool(WalledPool):
    """Shallow water in a square pool with walls, over a flat floor or a floor depth map."""

    STATE_FIELDS = ("h", "u", "v")

    def __init__(self, n: int, extent_m: float, floor_depth_m: np.ndarray | float, device: str, *,
                 viscosity_m2_s: float = 1e-4, cfl: float = 0.4, drops: tuple[DropConfig, ...] = (),
                 body: BodyConfig | None = None):
        if n < 2:
            raise WarpcausticsError(f"a shallow-water pool needs at least 2×2 cells (got n = {n}); "
                                    "raise water.resolution")
        self.device = device
        self.extent_m = float(extent_m)
        self.cell_m = self.extent_m / n
        self.viscosity = float(viscosity_m2_s)
        self.cfl = float(cfl)
        depth = np.broadcast_to(np.asarray(floor_depth_m, np.float32), (n, n))
        self.floor_depth = wp.array(np.ascontiguousarray(depth), dtype=wp.float32, device=device)
        self.h = wp.array(np.ascontiguousarray(depth), dtype=wp.float32, device=device)  # at rest
        self.u = wp.zeros((n, n + 1), dtype=wp.float32, device=device)
        self.v = wp.zeros((n + 1, n), dtype=wp.float32, device=device)
        self._h_next = wp.empty_like(self.h)
        self._u_adv = wp.empty_like(self.u)
        self._v_adv = wp.empty_like(self.v)
        self._speed = wp.zeros(1, dtype=wp.float32, device=device)
        # Cells per thread of the substep's kernels: a whole row on the CPU (threads run one after
        # another there), one cell on the GPU.
        self._span = n + 1 if wp.get_device(device).is_cpu else 1
        self._launches: dict = {}
        self.body = body if body is not None and body.radius_m > 0 else None
        self.substeps = 0
        self._init_drops(drops)
        self._drop_water(0.0)

    @classmethod
    def from_config(cls, cfg: Config, device: str, *, heights: np.ndarray | None = None,
                    floor_relief: np.ndarray | None = None) -> ShallowWaterPool:
        """The pool of ``cfg``; its depth map follows ``floor.shape`` (the floor the photons light)."""
        w = cfg.water
        return cls(w.resolution, w.extent_m, floor_depth_map(cfg, floor_relief), device,
                   viscosity_m2_s=w.viscosity_m2_s, cfl=w.cfl, drops=w.drops, body=w.body)

    @staticmethod
    def device_bytes(n: int, device) -> int:
        cells = 3 * n * n  # floor depth, h and the next h
        faces = 4 * n * (n + 1)  # u, v and their advected copies (on the cells' faces)
        speed = 1  # the maximum wave speed, read back for the CFL limit
        return (cells + faces + speed) * FLOAT32_BYTES + n * n * SURFACE_BYTES_PER_VERTEX

    def body_state(self, time_s: float) -> tuple[np.ndarray, np.ndarray]:
        """Centre [m] and velocity [m/s] of the body at ``time_s`` on its circular path."""
        b = self.body
        w = 2.0 * math.pi / b.period_s
        a = w * time_s
        centre = np.array([b.center_x_m + b.path_radius_m * math.cos(a),
                           b.center_y_m + b.path_radius_m * math.sin(a)])
        velocity = b.path_radius_m * w * np.array([-math.sin(a), math.cos(a)])
        return centre, velocity

    @property
    def resolution(self) -> int:
        return self.h.shape[0]

    def volume_m3(self) -> float:
        """Water volume, summed in float64 [m³]."""
        return float(self.h.numpy().astype(np.float64).sum() * self.cell_m**2)

    def max_wave_speed(self) -> float:
        """max(|u| + |v| + √(g h)) over the cells [m/s] (one small read-back)."""
        self._speed.zero_()
        n = self.resolution
        wp.launch(pool_kernels.wave_speed, dim=(n, n), inputs=[self.h, self.u, self.v],
                  outputs=[self._speed], device=self.device)
        return float(self._speed.numpy()[0])

    def _recorded(self) -> tuple[list, wp.Launch]:
        """The substep's launches for the current buffers, recorded once (``wp.Launch``) and replayed
        with the new dt: a recorded launch costs Warp about a fifth of a plain one, which is most of
        a small pool's substep. One set per way round of the depth buffers (they swap every
        substep) and per cells-per-thread ``_span``."""
        key = (self.h.ptr, self._span)
        if key not in self._launches:
            n = self.resolution
            dev = self.device
            span = self._span

            def threads(rows: int, cols: int) -> int:  # rows × runs of `span` cells per row, one thread each
                return rows * -(-cols // span)

            def record(kernel, dim, inputs, outputs):
                return wp.launch(kernel, dim=dim, inputs=inputs, outputs=outputs, device=dev, record_cmd=True)

            args = [self.h, self.floor_depth, 0.0, self.cell_m, self.viscosity, span]
            forces = [
                record(pool_kernels.advect_u, threads(n, n + 1), [self.u, self.v, 0.0, span], [self._u_adv]),
                record(pool_kernels.advect_v, threads(n + 1, n), [self.u, self.v, 0.0, span], [self._v_adv]),
                record(pool_kernels.accelerate_u, threads(n, n + 1), [self._u_adv, *args], [self.u]),
                record(pool_kernels.accelerate_v, threads(n + 1, n), [self._v_adv, *args], [self.v]),
            ]
            depth = record(pool_kernels.update_depth, threads(n, n), [self.h, self.u, self.v, 0.0, span],
                           [self._h_next])
            self._launches[key] = (forces, depth)
        return self._launches[key]

    def step(self, dt: float) -> None:
        """One substep of dt [s] (the caller keeps dt within the CFL limit)."""
        n = self.resolution
        dev = self.device
        k = float(dt / self.cell_m)
        forces, depth = self._recorded()
        for cmd, name, value in zip(forces, ("dt_over_cell", "dt_over_cell", "dt", "dt"), (k, k, dt, dt)):
            cmd.set_param_by_name(name, float(value))
            cmd.launch()
        if self.body is not None:
            centre, velocity = self.body_state(self.time_s + dt)
            push = [self.extent_m, wp.vec2(*centre), self.body.radius_m, wp.vec2(*velocity),
                    min(1.0, dt / self.body.response_s)]
            wp.launch(pool_kernels.push_u, dim=(n, n + 1), inputs=[self.u, *push], device=dev)
            wp.launch(pool_kernels.push_v, dim=(n + 1, n), inputs=[self.v, *push], device=dev)
        depth.set_param_by_name("dt_over_cell", k)
        depth.launch()
        self.h, self._h_next = self._h_next, self.h
        self.substeps += 1

    def advance(self, time_s: float) -> None:
        """Step forward to ``time_s`` [s] with CFL-limited substeps, dropping drops on the way."""
        self._check_forward(time_s)
        # Viscous limit of the explicit Laplacian: ν dt / Δ² ≤ 1/8.
        dt_viscous = self.cell_m**2 / (8.0 * self.viscosity) if self.viscosity > 0 else math.inf
        body_speed = 0.0
        if self.body is not None:
            body_speed = 2.0 * math.pi * self.body.path_radius_m / self.body.period_s

        def cfl_dt(speed: float) -> float:  # the longest stable substep at this wave speed
            return min(self.cfl * self.cell_m / max(speed + body_speed, 1e-6), dt_viscous)

        speed = self.max_wave_speed()
        if math.isfinite(speed) and (time_s - self.time_s) / cfl_dt(speed) > MAX_SUBSTEPS_PER_CALL:
            # Past the guard below at the present speed: refuse now, not after minutes, if it is past
            # it at the slowest speed the pool can reach. The speed may fall as the waves spread, but
            # not below √(g h̄): the walls keep the water and drops only add to it, so the deepest
            # cell is at least the mean depth.
            mean_depth = max(self.volume_m3(), 0.0) / self.extent_m**2
            slowest = cfl_dt(math.sqrt(pool_kernels.GRAVITY * mean_depth))
            needed = (time_s - self.time_s) / slowest
            if needed > MAX_SUBSTEPS_PER_CALL:
                raise WarpcausticsError(
                    f"the pool needs at least {needed:.3g} substeps of {slowest:.3g} s to reach t = "
                    f"{time_s:g} s (at most {MAX_SUBSTEPS_PER_CALL:.0e} a frame); render an earlier time, "
                    "lower water.resolution or raise the frame rate")
        for i in range(MAX_SUBSTEPS_PER_CALL):
            remaining = time_s - self.time_s
            if remaining <= 1e-12:
                break
            if (i and i % SPEED_REFRESH_SUBSTEPS == 0) or not math.isfinite(speed):
                speed = self.max_wave_speed()  # a read-back: not every substep (the first was read above)
            if not math.isfinite(speed):
                raise WarpcausticsError(f"the pool became unstable at t = {self.time_s:g} s; lower "
                                        f"water.cfl (now {self.cfl}) or the drops' height")
            dt = min(remaining, cfl_dt(speed))
            next_drop = next((d.time_s for d in self._drops if d.time_s > self.time_s), math.inf)
            dt = min(dt, max(next_drop - self.time_s, 1e-9))
            self.step(dt)
            self.time_s += dt
            if self._drop_water(self.time_s):
                speed = math.nan  # a drop changes the wave speed: measure again
        else:  # pragma: no cover - a guard, not a code path
            raise WarpcausticsError("the pool needs more than a million substeps for one frame; "
                                    "lower water.resolution or raise --fps")

    def _drop_water(self, time_s: float) -> bool:
        return self._apply_drops_until(time_s, pool_kernels.add_drop, [self.h])

    def at(self, time_s: float) -> Surface:
        self.advance(time_s)
        return self._surface(self.h, self.floor_depth)
