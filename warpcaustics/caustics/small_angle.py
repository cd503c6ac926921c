"""Scattered light by the small-angle transfer, on the host: ``optics.scattering = "small_angle"``.

The flux-ratio map of each light pass (the sun, each sky direction) is the unscattered pattern;
:class:`SmallAngleScattering` adds, per pass, its scattered light F⁻¹[Ŝ (e^{b s G(q s)} − 1)]
(:mod:`warpcaustics.optics.small_angle`: Wells 1973's transfer of the water column, with the
beam's path s = D / cos θ_w to the floor and its obliquity), then scales the scattered light of all
passes so that its mean over the patch is the random walk's: the walk's floor flux less the
single-scattering map's. The map is the single-scattering map plus that scattered light — the
unscattered pattern exact, the scattered light with the structure of the small-angle approximation
and the amount of the walk, free of the walk's noise. With ``optics.beam_spread = "walk"`` the
transfer is the column's beam spread function measured by a walk of a pencil beam
(:mod:`warpcaustics.optics.beam_spread`), with the scattered light's first-order response to the
surface's focusing and to each texel's own path (:meth:`SmallAngleScattering.terms`).
"""

from __future__ import annotations

import math

import numpy as np

from warpcaustics.caustics.cache import BoundedCache
from warpcaustics.caustics.window import MapWindow
from warpcaustics.config import BeamSpread, Config
from warpcaustics.errors import ConfigError
from warpcaustics.optics.beam_spread import column_spread, spread_multiplier
from warpcaustics.optics.small_angle import transferred, wells_multiplier
from warpcaustics.optics.snell import refract
from warpcaustics.scene.receivers import periodic_bilinear

DEPTH_STEP = 0.05
"""The walked spread's derivative by the path comes from central differences: two more walks this
much (relatively) shallower and deeper."""

MULTIPLIER_CACHE_BYTES = 1 << 30
"""The most memory the transfer's multipliers keep between frames and renderers of a process
(1 GiB): a sweep renders each frame with a renderer of its own."""

_MULTIPLIERS = BoundedCache(MULTIPLIER_CACHE_BYTES, size=lambda entry: entry[2])
"""The transfer's multipliers by (the water, its depth, the spread, the beam, texel, M, derivative):
(by band, k = 0 values, bytes)."""


MAX_ATTENUATION_LENGTHS = 80.0
"""The most attenuation lengths, c s, along the most slanted path in the water (s = D n/√(n² − 1), past
the critical angle none is steeper) that the transfer takes: it scales the unscattered map, e^{−c s}
in float32, by up to e^{c s}, and past about 87 the map underflows. (A bound on the numbers, not on
the physics: the transfer is checked against the random walk up to b s ≈ 6, docs/physics.md.)"""


def check_column(cfg: Config, ior: float, extinction_per_m: np.ndarray) -> None:
    """Refuse, before anything renders, a water column too deep for the transfer's numbers."""
    slant = cfg.floor.depth_m * ior / np.sqrt(ior * ior - 1.0) if ior > 1.0 else math.inf
    lengths = np.asarray(extinction_per_m, np.float64) * slant
    k = int(np.argmax(lengths))
    if lengths[k] > MAX_ATTENUATION_LENGTHS:
        raise ConfigError(
            f"floor.depth_m = {cfg.floor.depth_m:g} is {lengths[k]:.3g} attenuation lengths of this water "
            f"along the most slanted path in it (c = {extinction_per_m[k]:.3g} 1/m in band {k}), past the "
            f"{MAX_ATTENUATION_LENGTHS:g} that optics.scattering = 'small_angle' can carry; use a shallower "
            "floor, clearer water or optics.scattering = 'multiple'")


class SmallAngleScattering:
    """Collects the passes of one frame (:meth:`add`) and returns the scattered light (:meth:`finish`)."""

    SPREAD_STREAM = 0x1B873593
    """Added to ``optics.mc_seed`` for the beam spread functions' walks."""

    def __init__(self, cfg: Config, ior: float, absorption_per_m: np.ndarray, scattering_per_m: np.ndarray):
        self.optics = cfg.optics
        self.depth_m = float(cfg.floor.depth_m)
        self.ior = float(ior)
        self.a = np.asarray(absorption_per_m, np.float64)
        self.b = np.asarray(scattering_per_m, np.float64)
        check_column(cfg, self.ior, self.a + self.b)
        self.window = MapWindow(cfg)
        self.texel_m = self.window.texel_m
        self.extent_m = self.window.extent_m
        self.area = self.extent_m**2
        self.heights = None
        o = self.optics
        self.cache_key = (o.beam_spread, o.phase_function, o.hg_g, o.petzold_station, o.beam_spread_photons,
                          o.mc_seed, tuple(self.a.tolist()), tuple(self.b.tolist()), self.depth_m, self.ior)

    def reset(self, heights: np.ndarray) -> None:
        """Start a frame on a surface of cell-centre ``heights`` (N, N) [m] (periodic)."""
        self.heights = np.asarray(heights, np.float64)
        cell = self.extent_m / self.heights.shape[0]
        self.slopes = [(np.roll(self.heights, -1, axis) - np.roll(self.heights, 1, axis)) / (2.0 * cell)
                       for axis in (1, 0)]  # ∂h/∂x, ∂h/∂y at the cell centres, central differences
        self.scattered = {}
        self.scattered_coarse = {}
        """{group: (K, Mc, Mc)} the passes' scattered light on the whole patch's coarse texels, beside
        a window (unscaled until :meth:`finish`)."""
        self.single_mean = np.zeros_like(self.b)
        self.transferred_mean = np.zeros_like(self.b)
        self.paths = []

    def beam(self, direction: np.ndarray) -> tuple[np.ndarray, float]:
        """(unit direction in the water, path to the floor [m]) of light from ``direction`` (unit,
        towards the light) refracted by still water."""
        d = np.asarray(direction, np.float64)
        h = math.hypot(d[0], d[1])
        sin_w = h / self.ior
        cos_w = math.sqrt(1.0 - sin_w * sin_w)
        horizontal = (-d[0] / h, -d[1] / h) if h > 0 else (0.0, 0.0)
        down = np.array([horizontal[0] * sin_w, horizontal[1] * sin_w, -cos_w])
        return down, self.depth_m / cos_w

    def entry(self, down: np.ndarray, x: np.ndarray | None = None, y: np.ndarray | None = None
              ) -> tuple[np.ndarray, np.ndarray]:
        """(x, y) [m] where the light reaching each texel (x, y) (default: the map's) entered the
        water: back along the beam to the mean level, the still-water refraction's offset."""
        if x is None:
            x, y = self.window.texel_x, self.window.texel_y
        offset = self.depth_m / -down[2]
        return x - down[0] * offset, y - down[1] * offset

    def local_paths(self, down: np.ndarray, x: np.ndarray | None = None, y: np.ndarray | None = None
                    ) -> np.ndarray:
        """The path [m] through the water of the light reaching each texel (x, y) [m] (default: the
        map's): from the surface where it entered (the height there, bilinear, :meth:`entry`) down
        the beam to the floor."""
        height = periodic_bilinear(self.heights, self.extent_m, *self.entry(down, x, y))
        return (self.depth_m + height) / -down[2]

    def refracted_paths(self, light: np.ndarray, down: np.ndarray, x: np.ndarray | None = None,
                        y: np.ndarray | None = None) -> np.ndarray:
        """As :meth:`local_paths`, but down each texel's own ray: the light from ``light`` (unit,
        towards it) refracted at the surface's normal where it entered (the slopes bilinear there),
        so a ray the surface tilted travels its own longer or shorter path — first order in the
        slope for an oblique beam, where :meth:`local_paths` keeps only the height."""
        ex, ey = self.entry(down, x, y)
        height = periodic_bilinear(self.heights, self.extent_m, ex, ey)
        gx, gy = (periodic_bilinear(g, self.extent_m, ex, ey) for g in self.slopes)
        normal = np.stack([-gx, -gy, np.ones_like(gx)], axis=-1)
        normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
        ray = refract(-np.asarray(light, np.float64), normal, 1.0 / self.ior)
        return (self.depth_m + height) / np.maximum(-ray[..., 2], 1e-6)

    def lost(self, down: np.ndarray, path: float, x: np.ndarray | None = None, y: np.ndarray | None = None
             ) -> np.ndarray:
        """(K, …) e^{b s(x)} − 1 over e^{b s̄} − 1 at the texels (x, y) (default: the map's): the light
        each texel's ray lost to scattering on its own path, relative to the mean path's."""
        local = self.local_paths(down, x, y)
        return np.expm1(self.b[:, None, None] * local) / np.expm1(self.b * path)[:, None, None]

    def multiplier(self, texel_m: float, m: int, down: np.ndarray, path: float, derivative: bool = False):
        """The transfer's multiplier of a map's spectrum on an M × M periodic grid of ``texel_m``
        texels for the beam ``down`` with mean path ``path``: a function of the band, and its k = 0
        values (K,) — Wells's closed form, or the walked beam spread function
        (``optics.beam_spread``); with ``derivative`` (walked only) its derivative by the path,
        from two more walks ``DEPTH_STEP`` shallower and deeper. Kept for the next frames of the
        process (the sun's and a fixed sky's directions come back), up to
        ``MULTIPLIER_CACHE_BYTES``."""
        beam = np.round(np.asarray(down, np.float64), 9).tolist()
        key = (self.cache_key, derivative, *beam, float(texel_m), m)
        function, at_zero, _ = _MULTIPLIERS.get(key, lambda: self._make_multiplier(texel_m, m, down, path,
                                                                                   derivative))
        return function, at_zero

    def _make_multiplier(self, texel_m: float, m: int, down: np.ndarray, path: float, derivative: bool):
        """(:meth:`multiplier`'s function of the band, its k = 0 values, the bytes it holds)."""
        if self.optics.beam_spread is not BeamSpread.WALK:
            return (*wells_multiplier(self.optics, texel_m, m, path, self.b, down), 8 * m * m)
        if not derivative:
            return self._walked(texel_m, m, down, path, self.depth_m)
        # e^{c s̄} ∂H̃/∂s by central differences, + c M: H̃ varies slowly, e^{cs} not
        at, zero_at = self.multiplier(texel_m, m, down, path)
        ends = [self._walked(texel_m, m, down, path * f, self.depth_m * f)
                for f in (1.0 - DEPTH_STEP, 1.0 + DEPTH_STEP)]
        c = self.a + self.b
        shallow, deep = (np.exp(-c * path * (f - 1.0)) for f in (1.0 - DEPTH_STEP, 1.0 + DEPTH_STEP))
        step = 2.0 * DEPTH_STEP * path
        table = np.stack([(deep[k] * ends[1][0](k) - shallow[k] * ends[0][0](k)) / step + c[k] * at(k)
                          for k in range(len(self.b))]).astype(np.complex64)
        zero = (deep * ends[1][1] - shallow * ends[0][1]) / step + c * zero_at
        return (lambda band: table[band]), zero, table.nbytes

    def _walked(self, texel_m: float, m: int, down: np.ndarray, path: float, depth_m: float):
        """(the walked spread's multiplier by band, its k = 0 values, the bytes it holds) for a
        floor at ``depth_m``, the beam's mean path ``path`` to it."""
        o = self.optics
        sample = column_spread(o.phase_function, o.hg_g, o.petzold_station.value, tuple(self.a.tolist()),
                               tuple(self.b.tolist()), round(float(-down[2]), 9), depth_m, self.ior,
                               o.beam_spread_photons, (o.mc_seed + self.SPREAD_STREAM) % 2**31)
        horizontal = math.hypot(down[0], down[1])
        azimuth = (down[0] / horizontal, down[1] / horizontal) if horizontal > 1e-12 else (1.0, 0.0)
        fine, _ = wells_multiplier(o, texel_m, m, path, self.b, down)
        measured, at_zero = spread_multiplier(sample, azimuth, texel_m, m, self.a + self.b, path, fine)
        table = np.stack([measured(band) for band in range(len(self.b))]).astype(np.complex64)
        return (lambda band: table[band]), at_zero, table.nbytes

    def terms(self, single: np.ndarray, light: np.ndarray, down: np.ndarray, path: float, x=None, y=None
              ) -> list:
        """[(the map a multiplier acts on (K, M, M), which multiplier: the path's derivative or not)]
        for the single-scattering map ``single`` at the texels (x, y) (default: the map's). Each
        texel's light took its own path s(x). Wells's spread weights the map by the light each
        texel's ray lost to scattering, e^{b s(x)} − 1 over the mean path's (a k = 0 correction; s(x)
        from the height where it entered, :meth:`local_paths`); the walked spread expands the
        transfer to first order in s(x) − s̄ at every frequency, S M(k, s̄) + S (s − s̄) ∂M/∂s, s(x)
        down the texel's own refracted ray (:meth:`refracted_paths`) — a longer path also spreads its
        light wider (on a sinusoidal sea at 9.58 m the weight alone left the 8 m wave's pattern 15 %
        too strong)."""
        if self.optics.beam_spread is BeamSpread.WELLS:
            return [(single * self.lost(down, path, x, y), False)]
        longer = self.refracted_paths(light, down, x, y) - path
        return [(single, False), (single * longer, True)]

    def transfer(self, single: np.ndarray, coarse: np.ndarray | None, light: np.ndarray, down: np.ndarray,
                 path: float) -> tuple[np.ndarray, np.ndarray, np.ndarray | None]:
        """(the pass's scattered light on the map (K, M, M), its transfer's k = 0 term over the patch
        per unit of the pass's mean irradiance (K,), and with ``coarse`` its scattered light on the
        coarse texels (K, Mc, Mc), else None), summed over the :meth:`terms`. Without
        ``coarse`` the map is the whole periodic patch. With ``coarse`` (K, Mc, Mc), the whole
        patch's single-scattering light on coarse texels beside a window, the window's scattered light
        is the whole patch's at the large scales, read bilinearly from the coarse texels, plus the
        window's own detail beyond them taken as periodic: B*C + B_w*(S_w − C_w), C_w the coarse map
        at the window's texels (B the transfer), the detail's mean over the window left out (the
        transfer reaches metres past the window: :meth:`MapWindow.convolve`)."""
        out, at_zero = 0.0, 0.0
        if coarse is None:
            on_map = np.asarray(single, np.float64).mean(axis=(1, 2))
            for term, derivative in self.terms(single, light, down, path):
                multiplier, zero = self.multiplier(self.texel_m, term.shape[-1], down, path, derivative)
                out = out + transferred(term, multiplier)
                at_zero = at_zero + np.divide(term.mean(axis=(1, 2)), on_map, out=np.zeros_like(on_map),
                                              where=on_map > 0) * zero
            return out, at_zero, None
        mc = coarse.shape[-1]
        out_c = 0.0
        whole = coarse.mean(axis=(1, 2))
        centres = self.window.on_coarse(mc)[3]
        for (term, derivative), (term_c, _) in zip(self.terms(single, light, down, path),
                                                   self.terms(coarse, light, down, path, *centres)):
            far_m, zero = self.multiplier(self.extent_m / mc, mc, down, path, derivative)
            near_m, _ = self.multiplier(self.texel_m, term.shape[-1], down, path, derivative)
            on_window, on_coarse = self.window.convolve(term, term_c, far_m, near_m, detail_mean=False)
            out, out_c = out + on_window, out_c + on_coarse
            at_zero = at_zero + np.divide(term_c.mean(axis=(1, 2)), whole, out=np.zeros_like(whole),
                                          where=whole > 0) * zero
        return out, at_zero, out_c

    def add(self, single: np.ndarray, direction: np.ndarray, delivered_flux: np.ndarray,
            group: str = "sun", coarse: np.ndarray | None = None) -> None:
        """One pass: its single-scattering map (K, M, M) [W m⁻² nm⁻¹], the direction of its light
        (towards it), the flux its map holds over the whole patch (K,) [W nm⁻¹], the group its
        scattered light is reported in (``sun``; ``sky_even`` and ``sky``, the sky's two halves), and
        for a window of a periodic sea the whole patch's single-scattering light on coarse texels
        (K, Mc, Mc) (:meth:`transfer`). Each texel's light took its own path (:meth:`terms`); the
        transfer's k = 0 term, so weighted, is what the walk's mean scales."""
        down, path = self.beam(direction)
        light = np.asarray(direction, np.float64) / np.linalg.norm(direction)
        part, weighting, part_c = self.transfer(single, coarse, light, down, path)
        self.scattered[group] = part if group not in self.scattered else self.scattered[group] + part
        if part_c is not None:
            self.scattered_coarse[group] = self.scattered_coarse.get(group, 0.0) + part_c
        mean = np.asarray(delivered_flux, np.float64) / self.area
        self.single_mean += mean
        # the transfer's k = 0 term over the patch, weighted by the local paths, measured on the
        # whole patch (coarse), or on the map (the whole patch, or a window standing for it)
        self.transferred_mean += mean * weighting
        self.paths.append(path)

    def finish(self, walk_floor_flux: np.ndarray) -> tuple[dict, dict]:
        """({group: (K, M, M)} the passes' scattered light scaled to the walk's mean (the walk's floor
        flux over the patch, (K,) [W nm⁻¹], less the single-scattering map's), and what was done:
        the scale per band (the walk's scattered light over the small-angle approximation's, which
        keeps every scattered photon going forward), the passes' paths. Beside a window the coarse
        texels' scattered light is scaled the same (:attr:`scattered_coarse`)."""
        walk_mean = np.asarray(walk_floor_flux, np.float64) / self.area
        wanted = np.maximum(walk_mean - self.single_mean, 0.0)
        scale = np.divide(wanted, self.transferred_mean, out=np.zeros_like(wanted),
                          where=self.transferred_mean > 0)
        scattered = {group: part * scale[:, None, None] for group, part in self.scattered.items()}
        self.scattered_coarse = {group: part * scale[:, None, None]
                                 for group, part in self.scattered_coarse.items()}
        info = {"scale": scale.tolist(), "scattered_mean": wanted.tolist(),
                "single_mean": self.single_mean.tolist(), "paths_m": [float(p) for p in self.paths]}
        return scattered, info
