"""Eikonal caustics on the host: ``caustics.method = "eikonal"`` (``kernels/caustics/eikonal.py``).

Per frame: the refracted front in the frozen layers under the surface, the layer-by-layer
Godunov relaxation of |∇φ| = n_w, Mercier's Laplacian texture, the transport of intensity along
the rays and the floor map. The grid follows the surface's highest crest, so its layer count can
change from frame to frame (the arrays are reallocated when it does).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import warp as wp

from warpcaustics.caustics.fluxratio import ApproximateStage
from warpcaustics.caustics.stage import Frame
from warpcaustics.config import Config
from warpcaustics.errors import WarpcausticsError
from warpcaustics.kernels.caustics import eikonal as eikonal_kernels
from warpcaustics.optics.refraction import still_water_refraction
from warpcaustics.scene.receivers import floor_relief_height
from warpcaustics.water import Surface

MAX_PASSES_PER_LAYER = 512
"""Jacobi passes allowed for one layer before the relaxation is declared stuck (an error)."""


def eikonal_bytes(cfg: Config) -> int:
    """Device memory of the eikonal grid at its deepest (five N×N×nz float arrays) [bytes]."""
    n = cfg.caustics.eikonal_resolution
    h = cfg.water.extent_m / n
    layers = math.ceil(cfg.floor.depth_m / h) + 3 + max(1, math.ceil(0.1 * n))  # crests: ≤ 10 % of L
    return 5 * 4 * n * n * layers + 8 * n * n


@dataclass
class EikonalStats:
    layers: int = 0
    passes: int = 0
    """Jacobi passes over all layers of the last frame."""
    max_passes: int = 0
    """Most passes one layer needed."""


def relax(grid: eikonal_kernels.EikonalGrid, top: wp.array2d, psi: wp.array3d, device: str, *,
          scratch: wp.array2d | None = None, changed: wp.array | None = None) -> EikonalStats:
    """Solve |∇φ| = n_w below the frozen layers (``k <= top[j, i]``) of ``psi``, in place: layer
    by layer from the top, Jacobi passes of the Godunov update until no node moves by more than
    1e-6 h. Returns the number of passes."""
    n = grid.n
    scratch = scratch if scratch is not None else wp.empty((n, n), dtype=wp.float32, device=device)
    changed = changed if changed is not None else wp.zeros(1, dtype=wp.int32, device=device)
    tolerance = 1.0e-6 * grid.h
    stats = EikonalStats(layers=grid.layers)
    for k in range(1, grid.layers):
        for passes in range(1, MAX_PASSES_PER_LAYER + 1):  # noqa: B007 - counted after the loop
            changed.zero_()
            wp.launch(eikonal_kernels.relax_layer, dim=(n, n), inputs=[grid, k, top, psi, tolerance],
                      outputs=[scratch, changed], device=device)
            wp.launch(eikonal_kernels.store_layer, dim=(n, n), inputs=[k, scratch], outputs=[psi],
                      device=device)
            if not changed.numpy()[0]:
                break
        else:
            raise WarpcausticsError(f"the eikonal relaxation of layer {k} did not settle in "
                                    f"{MAX_PASSES_PER_LAYER} passes; lower caustics.eikonal_resolution")
        stats.passes += passes
        stats.max_passes = max(stats.max_passes, passes)
    return stats


def make_grid(n: int, extent_m: float, highest_m: float, floor_z: float, layers_below: int, periodic: bool,
              ior: float, sun_dir: np.ndarray) -> eikonal_kernels.EikonalGrid:
    """The grid over the patch: N columns per side, layers h apart from one spacing above the
    highest crest to ``layers_below`` spacings below the floor."""
    grid = eikonal_kernels.EikonalGrid()
    h = extent_m / n
    grid.n = n
    grid.h = h
    grid.extent_m = extent_m
    grid.z_top = float(highest_m) + h
    grid.layers = math.ceil((grid.z_top - floor_z) / h) + layers_below
    grid.periodic = int(periodic)
    grid.slowness = ior
    grid.gradient = wp.vec3(*(ior * still_water_refraction(sun_dir, ior)).astype(np.float32))
    grid.sun_dir = wp.vec3(*np.asarray(sun_dir, np.float32))
    grid.eta = 1.0 / ior
    return grid


def all_lit(surface: Surface, device: str) -> wp.array2d:
    """A visibility grid of ones for the surface's vertices."""
    n = surface.resolution
    return wp.full((n, n), 1.0, dtype=wp.float32, device=device)


def texel_floor(cfg: Config, relief: np.ndarray | None) -> tuple[np.ndarray, np.ndarray]:
    """(M, M) floor heights at the map's texel centres [m] and (M, M, 3) unit floor normals there
    (float64): the mean and the slope of the texel's four corner heights (``floor.shape``; exact on
    a plane, and exactly −depth_m and straight up on a flat floor)."""
    m = cfg.caustics.map_resolution
    extent = float(cfg.water.extent_m)
    texel = extent / m
    corners = np.arange(m + 1) * texel - 0.5 * extent
    cx, cy = np.meshgrid(corners, corners)
    z = floor_relief_height(cfg.floor, relief, extent, cx, cy)
    a, b, c, d = z[:-1, :-1], z[:-1, 1:], z[1:, :-1], z[1:, 1:]
    gx = ((b - a) + (d - c)) / (2.0 * texel)
    gy = ((c - a) + (d - b)) / (2.0 * texel)
    normal = np.stack([-gx, -gy, np.ones_like(gx)], -1)
    return (a + b + c + d) / 4.0, normal / np.linalg.norm(normal, axis=-1, keepdims=True)


class GridCaustics:
    """What the eikonal and wave methods share: their N×N columns over the patch, the sun and the
    water, the floor map they fill (on the floor's relief: each texel's centre height and normal)
    and the frozen layers' depth per column."""

    def __init__(self, cfg: Config, n: int, sun_dir: np.ndarray, ior: float, sun_irradiance: np.ndarray,
                 attenuation_per_m: np.ndarray, device: str, *, periodic: bool,
                 relief: np.ndarray | None = None):
        self.cfg = cfg
        self.device = device
        self.n = n
        self.extent_m = float(cfg.water.extent_m)
        self.h = self.extent_m / self.n
        texel_z, texel_normal = texel_floor(cfg, relief)
        self.floor_z = float(texel_z.min())
        """The floor's lowest texel centre [m] (the grid reaches below it)."""
        self.mean_depth_m = float(-texel_z.mean())
        self.texel_z = wp.array(texel_z.astype(np.float32), dtype=wp.float32, device=device)
        self.texel_normal = wp.array(texel_normal.astype(np.float32), dtype=wp.vec3, device=device)
        self.map_resolution = cfg.caustics.map_resolution
        self.periodic = periodic
        self.ior = float(ior)
        self.sun_irradiance = wp.empty(len(sun_irradiance), dtype=wp.float32, device=device)
        self.set_light(sun_dir, sun_irradiance)
        self.attenuation_per_m = wp.array(np.asarray(attenuation_per_m, np.float32), dtype=wp.float32,
                                          device=device)
        m = self.map_resolution
        self.irradiance = wp.empty((len(sun_irradiance), m, m), dtype=wp.float32, device=device)
        """Floor spectral irradiance (K, M, M) [W m^-2 nm^-1]."""
        self.top = wp.empty((self.n, self.n), dtype=wp.int32, device=device)
        self.layers = 0

    def set_light(self, direction: np.ndarray, irradiance: np.ndarray) -> None:
        """Light the next solves from ``direction`` (towards the light) with ``irradiance`` (K,) on
        a plane perpendicular to it [W m⁻² nm⁻¹]: the sun, or one direction of the sky."""
        s = np.asarray(direction, np.float64)
        self.sun_dir = s / np.linalg.norm(s)
        self.sun_irradiance.assign(np.asarray(irradiance, np.float32))

    def disk_average(self, floor: np.ndarray, disk_dirs: np.ndarray) -> np.ndarray:
        """The sun's disk for this grid method's map: :func:`parallax_disk_average`."""
        return parallax_disk_average(floor, self.sun_dir, disk_dirs, self.ior, self.mean_depth_m,
                                     self.extent_m, self.periodic)


def parallax_disk_average(floor: np.ndarray, sun_dir: np.ndarray, disk_dirs: np.ndarray, ior: float,
                          depth_m: float, extent_m: float, periodic: bool) -> np.ndarray:
    """The sun's disk for a map made for its centre: the (K, M, M) map moved by each direction's
    still-water parallax at the floor, D·(t_xy/|t_z| − t0_xy/|t0_z|) with t the refracted direction,
    and averaged over the directions. Each direction's pattern is taken to be the centre's,
    displaced as still water would displace it: the first-order effect of a 0.27° tilt, not a new
    solve. Moves are bilinear (periodic maps wrap and keep their flux; on a pool or an open patch
    what leaves the map is lost)."""
    if len(disk_dirs) < 2:
        return floor
    t0 = still_water_refraction(sun_dir, ior)
    texel = extent_m / floor.shape[-1]
    out = np.zeros(floor.shape, np.float64)
    for d in disk_dirs:
        t = still_water_refraction(d, ior)
        shift = depth_m * (t[:2] / abs(t[2]) - t0[:2] / abs(t0[2])) / texel  # texels, (x, y)
        whole = np.floor(shift).astype(int)
        frac = shift - whole
        for dy, wy in ((0, 1.0 - frac[1]), (1, frac[1])):
            for dx, wx in ((0, 1.0 - frac[0]), (1, frac[0])):
                out += wx * wy * _moved(floor, int(whole[0]) + dx, int(whole[1]) + dy, periodic)
    return (out / len(disk_dirs)).astype(floor.dtype)


def _moved(a: np.ndarray, sx: int, sy: int, periodic: bool) -> np.ndarray:
    """(K, M, M) ``a`` with its content moved by ``sx`` texels along +x (columns) and ``sy`` along
    +y (rows): wrapped, or with zeros coming in."""
    if periodic:
        return np.roll(a, (sy, sx), axis=(-2, -1))
    out = np.zeros_like(a, dtype=np.float64)
    m = a.shape[-1]
    if abs(sx) >= m or abs(sy) >= m:
        return out
    src_y = slice(max(-sy, 0), m - max(sy, 0))
    dst_y = slice(max(sy, 0), m - max(-sy, 0))
    src_x = slice(max(-sx, 0), m - max(sx, 0))
    dst_x = slice(max(sx, 0), m - max(-sx, 0))
    out[..., dst_y, dst_x] = a[..., src_y, src_x]
    return out


class EikonalCaustics(GridCaustics):
    """Owns the 3-D grid (ψ, Laplacian, intensity, path, horizontal irradiance) of a scene."""

    def __init__(self, cfg: Config, sun_dir: np.ndarray, ior: float, sun_irradiance: np.ndarray,
                 attenuation_per_m: np.ndarray, device: str, *, periodic: bool,
                 relief: np.ndarray | None = None):
        super().__init__(cfg, cfg.caustics.eikonal_resolution, sun_dir, ior, sun_irradiance,
                         attenuation_per_m, device, periodic=periodic, relief=relief)
        self.scratch = wp.empty((self.n, self.n), dtype=wp.float32, device=device)
        self.changed = wp.zeros(1, dtype=wp.int32, device=device)
        self.stats = EikonalStats()

    @property
    def gradient(self) -> np.ndarray:
        """∇φ of still water's refracted front, n_w t0 (the light's direction)."""
        return self.ior * still_water_refraction(self.sun_dir, self.ior)

    def _grid(self, highest_m: float) -> eikonal_kernels.EikonalGrid:
        grid = make_grid(self.n, self.extent_m, highest_m, self.floor_z, 2, self.periodic, self.ior,
                         self.sun_dir)
        if grid.layers != self.layers:
            shape = (grid.layers, self.n, self.n)
            self.psi, self.lap, self.intensity, self.path, self.horizontal = (
                wp.empty(shape, dtype=wp.float32, device=self.device) for _ in range(5))
            self.layers = grid.layers
        return grid

    def run(self, surface: Surface, highest_m: float, visible: wp.array2d | None = None) -> wp.array3d:
        """Fill :attr:`irradiance` for ``surface`` (whose highest point is ``highest_m``);
        ``visible`` (N_w, N_w): the sun's visibility at the surface vertices (default all lit)."""
        grid = self._grid(highest_m)
        visible = visible if visible is not None else all_lit(surface, self.device)
        dev = self.device
        n = self.n
        wp.launch(eikonal_kernels.init_front, dim=(n, n),
                  inputs=[grid, surface.positions, surface.normals, visible, float(surface.extent_m),
                          int(surface.periodic)],
                  outputs=[self.top, self.psi, self.intensity, self.path], device=dev)
        self.stats = relax(grid, self.top, self.psi, dev, scratch=self.scratch, changed=self.changed)
        wp.launch(eikonal_kernels.laplacian, dim=(grid.layers, n, n), inputs=[grid, self.top, self.psi],
                  outputs=[self.lap], device=dev)
        for k in range(grid.layers):
            wp.launch(eikonal_kernels.transport_layer, dim=(n, n),
                      inputs=[grid, k, self.top, self.psi, self.lap],
                      outputs=[self.intensity, self.path, self.horizontal], device=dev)
        self._threshold_post_process(grid)
        k_bands, m = self.irradiance.shape[0], self.map_resolution
        wp.launch(eikonal_kernels.floor_irradiance, dim=(k_bands, m, m),
                  inputs=[grid, self.horizontal, self.path, self.texel_z, self.texel_normal,
                          self.sun_irradiance, self.attenuation_per_m],
                  outputs=[self.irradiance], device=dev)
        self.grid = grid
        return self.irradiance

    def _threshold_post_process(self, grid: eikonal_kernels.EikonalGrid) -> None:
        """Mercier 2013 §3.3 (``caustics.eikonal_threshold_depth_m``): from the first layer at or
        below the threshold depth down, the horizontal irradiance is a wave in the xy plane with
        depth as its time, of speed tan(``eikonal_spread_deg``) per unit depth."""
        c = self.cfg.caustics
        if c.eikonal_threshold_depth_m is None:
            return
        start = max(math.ceil((grid.z_top + c.eikonal_threshold_depth_m) / grid.h - 1e-9), 0)
        courant2 = math.tan(math.radians(c.eikonal_spread_deg)) ** 2  # Δz = Δx = h
        for k in range(start, grid.layers - 1):
            wp.launch(eikonal_kernels.threshold_wave_step, dim=(self.n, self.n),
                      inputs=[grid, self.horizontal, k, courant2, int(k == start)], device=self.device)

    def floor_map(self, surface: Surface, water, time_s: float, highest_m: float, visible: wp.array2d,
                  flux_ratio: np.ndarray) -> tuple[np.ndarray, dict]:
        """(K, M, M) floor irradiance by the eikonal grid (absolute: ``flux_ratio`` is not used),
        and the RenderResult fields it adds (the relaxation's statistics)."""
        floor = self.run(surface, highest_m, visible).numpy().copy()
        return floor, {"eikonal_stats": vars(self.stats).copy()}

    def bytes_held(self) -> int:
        """Device memory of the grid's arrays now [bytes]."""
        arrays = [self.top, self.scratch, self.irradiance] + (
            [self.psi, self.lap, self.intensity, self.path, self.horizontal] if self.layers else [])
        return sum(a.capacity for a in arrays)

    def texture(self) -> np.ndarray:
        """Mercier's caustic texture of the last frame: −Δφ [1/m] on the (nz, N, N) nodes, layer 0
        at the top (positive where the front converges)."""
        return -self.lap.numpy()

    def travel_time(self) -> np.ndarray:
        """φ [m] (optical path) on the (nz, N, N) nodes of the last frame (float64)."""
        g = self.grid
        c = (np.arange(self.n) + 0.5) * self.h - 0.5 * self.extent_m
        z = g.z_top - np.arange(g.layers) * self.h
        gradient = self.gradient
        phi0 = (gradient[0] * c[None, None, :] + gradient[1] * c[None, :, None]
                + gradient[2] * z[:, None, None])
        return self.psi.numpy().astype(np.float64) + phi0


class GridStage(ApproximateStage):
    """A 3-D grid method (eikonal, wave3d): its own sky, a solve per sky direction, and the sun's
    disk by parallax over the centre's solve."""

    keeps_sky_shading = True  # the sky's solves revisit the shading the flux ratio's sky pass made
    grid: type[GridCaustics]
    grid_bytes: staticmethod
    """The grid's device memory for a config [bytes]."""

    @classmethod
    def bytes_needed(cls, scene, k: int, groups: int) -> int:
        m = scene.config.caustics.map_resolution  # + the grid's own (K, M, M) floor map and texels' floor
        return super().bytes_needed(scene, k, groups) + cls.grid_bytes(scene.config) + (k * 4 + 16) * m * m

    def make(self, mean_ior: float) -> GridCaustics:
        light = self.light
        return self.grid(self.scene.config, self.scene.sun_direction, mean_ior, light.sun_irradiance,
                         light.attenuation_per_m, self.device, periodic=self.water.periodic,
                         relief=self.scene.floor_relief)

    def sky_map(self, frame: Frame, flux_ratio: np.ndarray) -> np.ndarray | None:
        """The sky's floor map by the grid: a solve per sky direction, lit with its share of the
        sky and shaded by the crests as seen from it, as the flux ratio's sky pass shaded them this
        frame; solved before the sun, so that the grid holds the sun's solve afterwards
        (texture(), stats), and the sun's light is put back after."""
        light = self.light
        if light.sky_directions is None:
            return None
        grid = self.approximate
        total = None
        with frame.watch.stage("sky"):
            try:
                for i, (direction, irradiance) in enumerate(zip(light.sky_directions,
                                                                light.sky_irradiance_np)):
                    grid.set_light(direction, irradiance)
                    floor, _ = grid.floor_map(frame.surface, self.water, frame.time_s, frame.highest,
                                              light.sky_visible[i], flux_ratio)
                    total = floor.astype(np.float64) if total is None else total + floor
            finally:
                grid.set_light(self.scene.sun_direction, light.sun_irradiance)
        return total.astype(np.float32)

    def finish(self, floor: np.ndarray) -> np.ndarray:
        return self.approximate.disk_average(floor, self.light.sun_directions)


class EikonalStage(GridStage):
    """``eikonal``: Mercier 2013's eikonal caustics on a 3-D grid."""

    name = "eikonal"
    grid = EikonalCaustics
    grid_bytes = staticmethod(eikonal_bytes)
    memory_key = "caustics.eikonal_resolution"
