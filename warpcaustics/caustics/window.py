"""A floor-map window of a periodic patch, and convolutions wider than it.

A convolution of the floor's light (the small-angle transfer of the scattered light, the spread of
a sky direction over its cell) reaches past a window: its large scales come from the whole periodic
patch's light on coarse texels, read bilinearly at the window's texels, and only the window's own
detail beyond them is taken as periodic over the window: B*C + B_w*(S_w − C_w), with C_w the coarse
map at the window's texels (:meth:`MapWindow.convolve`).
"""

from __future__ import annotations

import numpy as np

from warpcaustics.optics.small_angle import transferred


def axis_weights(n: int, extent_m: float, coords: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(the grid indices used, (len(coords), used) weights): linear interpolation along one axis of a
    periodic grid of N cell-centre samples over ``extent_m`` at ``coords`` [m] (as
    :func:`~warpcaustics.scene.receivers.periodic_bilinear` does per axis)."""
    u = (np.asarray(coords, np.float64) + 0.5 * extent_m) * n / extent_m - 0.5
    i0 = np.floor(u).astype(np.int64)
    t = u - i0
    i0 = i0 % n
    i1 = (i0 + 1) % n
    used = np.unique(np.concatenate([i0, i1]))
    weights = np.zeros((len(u), len(used)))
    at = np.arange(len(u))
    np.add.at(weights, (at, np.searchsorted(used, i0)), 1.0 - t)
    np.add.at(weights, (at, np.searchsorted(used, i1)), t)
    return used, weights


class MapWindow:
    """The floor map's texels on the periodic water patch: their centres, and where they lie on an
    Mc × Mc coarse map of the whole patch."""

    def __init__(self, cfg):
        m = cfg.caustics.map_resolution
        side, centre = cfg.map_window
        self.texel_m = side / m
        centres = (np.arange(m) + 0.5) * self.texel_m - 0.5 * side
        self.texel_x, self.texel_y = np.meshgrid(centres + centre[0], centres + centre[1])  # [iy, ix]
        self.extent_m = float(cfg.water.extent_m)
        self._coarse = None
        """(Mc, (rows, weights), (columns, weights), (x, y) of the coarse texels' centres)."""

    def coarse_centres(self, mc: int) -> tuple[np.ndarray, np.ndarray]:
        """(x, y) [m] of the whole patch's Mc × Mc coarse texel centres, [iy, ix]."""
        centres = (np.arange(mc) + 0.5) * self.extent_m / mc - 0.5 * self.extent_m
        return np.meshgrid(centres, centres)

    def on_coarse(self, mc: int) -> tuple:
        """(Mc, (rows, weights), (columns, weights), coarse centres): where the map's texels lie on an
        Mc × Mc coarse map of the patch (:func:`axis_weights` per axis)."""
        if self._coarse is None or self._coarse[0] != mc:
            self._coarse = (mc, axis_weights(mc, self.extent_m, self.texel_y[:, 0]),
                            axis_weights(mc, self.extent_m, self.texel_x[0]), self.coarse_centres(mc))
        return self._coarse

    def on_map(self, a: np.ndarray) -> np.ndarray:
        """(K, M, M) the coarse map ``a`` (K, Mc, Mc) read bilinearly at the map's texels, periodic:
        separable, as the map's texels are a grid (the rows and columns it needs, then one matrix
        product per axis)."""
        _, (rows, wy), (cols, wx), _ = self.on_coarse(a.shape[-1])
        return wy @ a[:, rows][:, :, cols] @ wx.T

    def convolve(self, window: np.ndarray, coarse: np.ndarray, far, near, *, detail_mean: bool = True
                 ) -> tuple[np.ndarray, np.ndarray]:
        """(B*S on the window's texels (K, M, M), B*C on the coarse texels (K, Mc, Mc)) for the
        window's map ``window`` (K, M, M) whose whole patch's light is ``coarse`` (K, Mc, Mc): the
        coarse map convolved over the periodic patch (``far``: B's multiplier by band on the coarse
        texels' FFT grid) and read at the texels, plus the window's detail beyond the coarse texels
        convolved as periodic over the window (``near``: on the window's grid).

        ``detail_mean=False`` leaves the detail's mean over the window out of its convolution: for a
        B that reaches far past the window (the scattered light's transfer, over metres), the window
        taken as periodic would spread that mean as if every window around held it, by B's whole
        weight (its k = 0 value: about 440 at 9.58 m in Darecki et al.'s water), where the detail's
        light averages out over B's reach; the coarse map's bilinear reading misses a window's own
        light by 5–19 % when its texels are half the window (``tests/test_small_angle.py``). A
        narrow B (a sky cone's blur) keeps it."""
        whole = transferred(coarse, far)
        detail = window - self.on_map(coarse)
        if not detail_mean:
            detail = detail - detail.mean(axis=(1, 2), keepdims=True)
        return self.on_map(whole) + transferred(detail, near), whole
