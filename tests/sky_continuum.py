"""A sky's continuum under a rough sea, in float64, written apart from the package: the irradiance
a sky of radiance L(ω) gives a point of the floor, by integrating over the directions the light
arrives from in the water instead of over the sky's directions.

From a floor point at depth D each upward direction u in the water (cos θ_w = u_z) is followed to
the first crossing of the surface (bilinear between the height samples at the cell centres, taken
as periodic: the flux-ratio surface's vertices), refracted out by Snell's law at the surface's
normal there, and brings

    n² T(θ_i) L(a) e^{−c t}   (n² the radiance's change across the interface, T Fresnel's
                               transmittance in angle form, a the direction in the air, t the path)

— nothing where the light would arrive totally reflected (the sea below is taken as dark) or where
a crest blocks the air direction a (marched over three times the surface's height range). So

    E(x) = Σ_u n² T L(a) e^{−c t} cos θ_w ΔΩ

on a midpoint grid of cos θ_w (0 to 75° from the zenith: past it every direction is totally
reflected for the slopes used) and azimuth. Nothing of the package's sky directions, cells, cones or
deposits is used: the reference integrates the sky's continuum at each point directly.
"""

from __future__ import annotations

import csv
import math

import numpy as np

from helpers import ROOT, fresnel_t_angles

CIE_SKIES = ROOT.parent / "shared" / "data" / "sky" / "cie_standard_general_sky.csv"
"""The CIE standard general skies' parameters (CIE S 011/E:2003), with their source beside them."""


class PeriodicHeights:
    """A periodic height field sampled at cell centres ((i + ½) Δ − L/2), bilinear between them:
    ``heights[j, i]`` at (x_i, y_j)."""

    def __init__(self, heights: np.ndarray, extent_m: float):
        self.h = np.asarray(heights, np.float64)
        self.extent = float(extent_m)
        self.cell = self.extent / self.h.shape[0]

    def at(self, x: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(height, ∂h/∂x, ∂h/∂y) at (x, y)."""
        u = (x + 0.5 * self.extent) / self.cell - 0.5
        v = (y + 0.5 * self.extent) / self.cell - 0.5
        i0, j0 = np.floor(u).astype(np.int64), np.floor(v).astype(np.int64)
        fu, fv = u - i0, v - j0
        n = self.h.shape[0]
        i0, j0 = i0 % n, j0 % n
        i1, j1 = (i0 + 1) % n, (j0 + 1) % n
        a, b, c, d = self.h[j0, i0], self.h[j0, i1], self.h[j1, i0], self.h[j1, i1]
        height = a * (1 - fu) * (1 - fv) + b * fu * (1 - fv) + c * (1 - fu) * fv + d * fu * fv
        gx = ((b - a) * (1 - fv) + (d - c) * fv) / self.cell
        gy = ((c - a) * (1 - fu) + (d - b) * fu) / self.cell
        return height, gx, gy


def uniform_sky(a: np.ndarray) -> np.ndarray:
    """L / E_sky of a uniform sky: 1/π in every direction."""
    return np.full(a.shape[1:], 1.0 / math.pi)


def cie_sky(sky_type: int, sun_direction: np.ndarray):
    """L / E_sky of any CIE standard general sky with the sun towards ``sun_direction`` (unit, z up),
    from the shared table's a–e: L ∝ f(χ) φ(Z), φ(Z) = 1 + a e^{b / cos Z}, f(χ) = 1 + c (e^{dχ} −
    e^{dπ/2}) + e cos²χ (χ the angle from the sun), normalised by its own ∫ L cos Z dΩ (midpoint
    rule, 2000 × 4000 in zenith and azimuth)."""
    with open(CIE_SKIES, encoding="utf-8", newline="") as fh:
        row = next(r for r in csv.DictReader(fh) if int(r["sky_type"]) == sky_type)
    a, b, c, d, e = (float(row[k]) for k in "abcde")
    sun = np.asarray(sun_direction, np.float64) / np.linalg.norm(sun_direction)

    def relative(direction: np.ndarray) -> np.ndarray:
        cos_z = np.maximum(direction[2], 1e-12)
        chi = np.arccos(np.clip(sun[0] * direction[0] + sun[1] * direction[1] + sun[2] * direction[2], -1, 1))
        return ((1 + a * np.exp(b / cos_z))
                * (1 + c * (np.exp(d * chi) - math.exp(d * math.pi / 2)) + e * np.cos(chi) ** 2))

    nz, na = 2000, 4000
    z = (np.arange(nz) + 0.5) * (math.pi / 2) / nz
    az = (np.arange(na) + 0.5) * (2 * math.pi) / na
    zz, aa = np.meshgrid(z, az, indexing="ij")
    grid = np.stack([np.sin(zz) * np.cos(aa), np.sin(zz) * np.sin(aa), np.cos(zz)])
    norm = np.sum(relative(grid) * np.cos(zz) * np.sin(zz)) * (math.pi / 2 / nz) * (2 * math.pi / na)

    def radiance(direction: np.ndarray) -> np.ndarray:
        return relative(direction) / norm

    return radiance


def texel_points(texels: int, step: int, extent_m: float) -> tuple[np.ndarray, np.ndarray]:
    """(every ``step``-th texel index of a map ``texels`` wide over a patch ``extent_m`` wide, starting
    half a step in; (P, 2) their centres [m], row (y) by row, as ``map[:, idx][:, :, idx]`` reads them)."""
    idx = np.arange(step // 2, texels, step)
    xs = (idx + 0.5) * extent_m / texels - extent_m / 2
    return idx, np.array([(x, y) for y in xs for x in xs])


def floor_irradiance(heights: PeriodicHeights, points: np.ndarray, depth_m: float, n: float,
                     attenuation_per_m, radiance, rings: int = 160, azimuths: int = 160,
                     air_steps: int = 160) -> np.ndarray:
    """(P, K) E / E_sky at floor points (P, 2) [m] for each attenuation c (K,) [1/m]; ``radiance(a)``:
    the sky's L / E_sky towards air directions a (3, …)."""
    edges = np.linspace(math.cos(math.radians(75.0)), 1.0, rings + 1)
    mu = 0.5 * (edges[1:] + edges[:-1])
    phi = (np.arange(azimuths) + 0.5) * 2 * math.pi / azimuths
    mu, phi = np.meshgrid(mu, phi, indexing="ij")
    weight = (np.diff(edges)[:, None] * (2 * math.pi / azimuths)) * mu  # cos θ_w dΩ
    sin_w = np.sqrt(1 - mu * mu)
    ux, uy, uz = sin_w * np.cos(phi), sin_w * np.sin(phi), mu
    low, high = heights.h.min(), heights.h.max()
    c = np.asarray(attenuation_per_m, np.float64)
    out = np.zeros((len(points), len(c)))
    for p, (x0, y0) in enumerate(np.asarray(points, np.float64)):
        # the first crossing going up: march through the surface's height range, then bisect
        t_start, t_end = (depth_m + low - 1e-6) / uz, (depth_m + high + 1e-6) / uz
        t_lo, t_hi = t_start.copy(), t_end.copy()
        found = np.zeros(uz.shape, bool)
        before = t_start
        for s in range(1, 25):
            t = t_start + (t_end - t_start) * s / 24
            above = (-depth_m + t * uz) >= heights.at(x0 + t * ux, y0 + t * uy)[0]
            new = above & ~found
            t_lo, t_hi = np.where(new, before, t_lo), np.where(new, t, t_hi)
            found |= above
            before = t
        for _ in range(30):
            t = 0.5 * (t_lo + t_hi)
            above = (-depth_m + t * uz) >= heights.at(x0 + t * ux, y0 + t * uy)[0]
            t_hi, t_lo = np.where(above, t, t_hi), np.where(above, t_lo, t)
        t = 0.5 * (t_lo + t_hi)
        x, y = x0 + t * ux, y0 + t * uy
        z, gx, gy = heights.at(x, y)
        norm = np.sqrt(1 + gx * gx + gy * gy)
        nx, ny, nz = -gx / norm, -gy / norm, 1 / norm
        cos_i = ux * nx + uy * ny + uz * nz
        transmitted = fresnel_t_angles(np.arccos(np.clip(cos_i, -1.0, 1.0)), n, 1.0)
        sin2_t = n * n * (1 - cos_i * cos_i)
        k = np.sqrt(np.maximum(0.0, 1 - sin2_t)) - n * cos_i
        a = np.stack([n * ux + k * nx, n * uy + k * ny, n * uz + k * nz])
        out_of_water = (sin2_t < 1) & (a[2] > 0) & (cos_i > 0)
        blocked = np.zeros_like(out_of_water)
        reach = 3.0 * (high - low) / np.maximum(a[2], 0.02)
        for s in np.linspace(1.0 / air_steps, 1.0, air_steps):
            d = s * reach
            blocked |= (z + d * a[2]) < heights.at(x + d * a[0], y + d * a[1])[0] - 1e-9
        light = np.where(out_of_water & ~blocked, n * n * transmitted * radiance(a) * weight, 0.0)
        for j, cj in enumerate(c):
            out[p, j] = np.sum(light * np.exp(-cj * t))
    return out
