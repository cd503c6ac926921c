"""The sky's cells: what a continuum of sky directions does to the floor's caustics that a few
directions do not (``sky.sampling = "cones"``, issue 32 item 3).

Each of the sky's K stratified directions (:func:`~warpcaustics.optics.sky.stratified_hemisphere`)
stands for a cell of the sky: the directions nearest it in the projected disk p = (sinθ cosφ,
sinθ sinφ), where cosine-weighted directions are uniform, so the K cells share the disk's area π
equally. Rendered as a point, each direction draws a caustic pattern of its own, and a few such
patterns add to the floor's variance like noise, falling only as 1/K (docs/validation.md); a real
sky's continuum washes them out.

Light from a direction p of a cell refracts into the water at θ_w, sinθ_w = |p|/n, and reaches the
floor D below where it entered displaced by −D t(p), t(p) = (p/n) / √(1 − |p|²/n²). To first order
the surface focuses every direction of a cell alike, so the cell's light is its own direction p_j's
pattern moved by −D (t(p) − t(p_j)) for each p, weighted by the sky's radiance there and the flat
surface's Fresnel transmittance: p_j's pattern convolved with the distribution of those
displacements, whose Fourier transform (numpy's sign, F[f](k) = Σ f(x) e^{−ik·x}) is

    B̂_j(k) = Σ_s w_s exp(i D k·(t(p_s) − t(p_j)) − ½ kᵀ Σ_s k) / Σ_s w_s,

over S points p_s of a dense stratified set in the cell. Each point stands for a small disc of the
projected disk, radius r = 1/√(K S), which t stretches into an ellipse by its Jacobian,
J = [I + p pᵀ / (n² c²)] / (n c) with c = √(1 − |p|²/n²) (1/(n c³) along the azimuth, 1/(n c)
across); it is taken as a Gaussian of the same second moments, Σ_s = D² (r²/4) J Jᵀ, so the
multiplier is smooth at every frequency rather than a sum of S point shifts. B̂_j(0) = 1: the mean
is unchanged.

What the first order leaves out: a cell's directions meet the waves at different obliquities, so
their patterns differ in shape as well as in place; the attenuation along their paths differs too.
Both are measured against many point directions (docs/validation.md, ``benchmarks/sky_directions``).
"""

from __future__ import annotations

import functools
import math

import numpy as np

from warpcaustics.optics.sky import cie_relative_radiance, stratified_hemisphere
from warpcaustics.optics.snell import fresnel_transmittance

POINTS_PER_CELL = 256
"""Points of the dense stratified set each cell holds on average (S): the set cuts the cells' edges
coarsely, so that B̂ is off the continuum's by up to 0.016 at the horizon's cell (0.008 with 1024
points; against a Monte Carlo of 3 million directions, ``tests/test_sky_cones.py``), and 64 points
put the cells' centroids off by 1/6 of a point's disc radius."""

NEGLIGIBLE_EXPONENT = 30.0
"""Frequencies where every point's Gaussian is below e^{−30} (1e-13) are left at zero."""

SPLAT_ABOVE = 1 << 24
"""Past this many (frequency, point) terms — points' discs under a few texels, so that few
frequencies are negligible — the multiplier is the FFT of the points splatted on the map's grid
(bilinear) times the Gaussian of their mean disc: within 0.04 of the sum (rms 0.003–0.009) on 16
cells 0.3–3 m deep (``tests/test_sky_cones.py``), the bilinear splat's smoothing and one disc for
all, and ~100–1000× faster."""

NEGLIGIBLE_VALUE = 1e-6
"""A splatted multiplier's values below this are left at zero (kept sparse)."""


def floor_offsets(directions: np.ndarray, ior: float) -> tuple[np.ndarray, np.ndarray]:
    """(t (…, 2), J (…, 2, 2)): light from unit ``directions`` (…, 3, towards the sky) reaches the
    floor D below where it entered displaced by −D t; J = ∂t/∂p, p the direction's horizontal part."""
    p = np.asarray(directions, np.float64)[..., :2]
    c = np.sqrt(1.0 - np.sum(p * p, axis=-1) / ior**2)
    t = p / (ior * c[..., None])
    outer = p[..., :, None] * p[..., None, :] / (ior * c[..., None, None]) ** 2
    jacobian = (np.eye(2) + outer) / (ior * c[..., None, None])
    return t, jacobian


def cell_key(vectors: np.ndarray) -> tuple:
    """Unit vectors (…, 3) as the cells' cache key: nested tuples rounded to 12 digits, so that the
    same sky from the scene and from the renderer shares one entry."""
    a = np.asarray(vectors, np.float64)
    if a.ndim == 1:
        return tuple(round(float(v), 12) for v in a)
    return tuple(cell_key(v) for v in a)


@functools.lru_cache(maxsize=16)
def _partition(directions: tuple, points_per_cell: int) -> tuple[np.ndarray, np.ndarray]:
    """(the dense stratified set (K × ``points_per_cell``, 3), (…,) the index of the direction of
    ``directions`` nearest each of its points in the projected disk: the cell it falls in)."""
    from scipy.spatial import cKDTree

    d = np.asarray(directions, np.float64)
    points = stratified_hemisphere(len(d) * points_per_cell, 0.5, 0.0)
    _, nearest = cKDTree(d[:, :2]).query(points[:, :2])
    return points, nearest


@functools.lru_cache(maxsize=16)
def _cell_light(directions: tuple, sky_type: int | None, sun_direction: tuple, ior: float,
                points_per_cell: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The partition's points and cells (:func:`_partition`), the sky's relative radiance L at each
    point (CIE type ``sky_type``, None: uniform, 1) and what it transmits into water of ``ior``
    through a flat surface, L T: the one computation behind the cells' spreads and their shares."""
    points, nearest = _partition(directions, points_per_cell)
    radiance = np.ones(len(points))
    if sky_type is not None:
        radiance = cie_relative_radiance(sky_type, points, np.asarray(sun_direction, np.float64))
    return points, nearest, radiance, radiance * fresnel_transmittance(points[:, 2], 1.0 / ior)


@functools.lru_cache(maxsize=16)
def sky_cells(directions: tuple, sky_type: int | None, sun_direction: tuple, ior: float,
              points_per_cell: int = POINTS_PER_CELL) -> tuple:
    """Per direction of ``directions`` (K tuples of 3, cosine-weighted stratified): (its cell's
    points (S_j, 3), their weights (S_j,)): the points of a stratified set of K × ``points_per_cell``
    nearest it in the projected disk, weighted by the sky's relative radiance (CIE type
    ``sky_type``, None: uniform) and the flat surface's Fresnel transmittance into water of ``ior``."""
    points, nearest, _, weight = _cell_light(directions, sky_type, sun_direction, ior, points_per_cell)
    return tuple((points[nearest == j], weight[nearest == j]) for j in range(len(directions)))


def cell_shares(directions: tuple, sky_type: int | None, sun_direction: tuple, ior: float,
                points_per_cell: int = POINTS_PER_CELL) -> np.ndarray:
    """(K,) each direction's share of the sky's horizontal irradiance, such that through still water
    it brings what its cell of the sky transmits: the sky's relative radiance L times the flat
    surface's Fresnel transmittance T summed over the cell's points of the dense stratified set (each
    cosine-weighted point stands for the same part of a uniform sky's horizontal irradiance), over
    the direction's own T and over L summed on the whole sky,

        share_j = Σ_{s ∈ j} L_s T_s / (T_j Σ_s L_s).

    Not its own radiance over the directions' sum (``stratified``): the cells (nearest-direction
    regions of the projected disk) hold 0.53–1.36× the disk's K-th part, and under the CIE clear sky
    with a low sun the radiance at the outermost directions, near the bright horizon round the sun,
    is 2.5–3× their cells' mean while T falls to 0 across the horizon's cells. Over still water the
    cones' mean is then the continuum's, ∫ L cosθ T e^{−cD/cosθ_w} dΩ, but for the path's
    attenuation across a cell (within 0.3–1 % at K = 8–64 and an 80°–85° sun, docs/physics.md)."""
    _, nearest, radiance, transmitted = _cell_light(directions, sky_type, sun_direction, ior, points_per_cell)
    held = np.bincount(nearest, weights=transmitted, minlength=len(directions))
    own = fresnel_transmittance(np.asarray(directions, np.float64)[:, 2], 1.0 / ior)
    return held / (own * radiance.sum())


def cell_multiplier(direction: np.ndarray, points: np.ndarray, weights: np.ndarray, count: int,
                    depth_m: float, ior: float, texel_m: float, m: int,
                    points_per_cell: int = POINTS_PER_CELL, splat_above: int = SPLAT_ABOVE
                    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """B̂_j(k) on the FFT grid of an M × M periodic map of ``texel_m`` texels (numpy's ``fft2``
    order, [ky, kx]) for the direction ``direction`` whose cell of a sky of ``count`` cells holds
    ``points`` (S, 3) weighted by ``weights`` (S,), a floor ``depth_m`` below the water's surface:
    (rows, columns, complex values) where it is not negligible (zero elsewhere; :func:`dense`).
    A cell without points (or weight) leaves the map as it is."""
    w = np.asarray(weights, np.float64)
    if len(w) == 0 or float(np.sum(w)) <= 0.0:
        return np.zeros(1, np.int64), np.zeros(1, np.int64), np.ones(1, np.complex64)
    w = w / float(np.sum(w))
    t_j, _ = floor_offsets(np.asarray(direction, np.float64), ior)
    t_s, jac = floor_offsets(points, ior)
    shift = depth_m * (t_s - t_j)  # (S, 2)
    r = 1.0 / math.sqrt(count * points_per_cell)
    cov = depth_m**2 * 0.25 * r * r * jac @ np.swapaxes(jac, -1, -2)  # (S, 2, 2)
    k = 2.0 * math.pi * np.fft.fftfreq(m, texel_m)
    kx, ky = k[None, :], k[:, None]
    smallest = float(np.linalg.eigvalsh(cov).min())
    keep = 0.5 * (kx * kx + ky * ky) * smallest < NEGLIGIBLE_EXPONENT  # elsewhere every term is ~0
    rows, cols = np.nonzero(keep)
    if len(rows) * len(w) > splat_above:
        return _splatted(shift, cov, w, k, texel_m, m)
    # B̂(−k) = conj B̂(k), the transform of a real distribution: half the frequencies are summed and
    # the rest mirrored (the mask is symmetric). A Nyquist row's or column's mirror on the grid is not
    # −k (fftfreq gives −π/τ both), so those, and k = 0, keep their own sums.
    flat, mirror = rows * m + cols, ((-rows) % m) * m + (-cols) % m
    own = (flat == mirror) | (2 * rows == m) | (2 * cols == m)
    half = own | (flat < mirror)
    qx, qy = k[cols[half]], k[rows[half]]
    total = np.zeros(len(qx), np.complex128)
    for s in range(len(w)):
        exponent = (1j * (qx * shift[s, 0] + qy * shift[s, 1])
                    - 0.5 * (qx * qx * cov[s, 0, 0] + 2.0 * qx * qy * cov[s, 0, 1] + qy * qy * cov[s, 1, 1]))
        total += w[s] * np.exp(exponent)
    values = np.zeros(m * m, np.complex128)
    mirrored = ~own[half]
    values[mirror[half][mirrored]] = np.conj(total[mirrored])
    values[flat[half]] = total
    return rows, cols, values[flat].astype(np.complex64)


def _splatted(shift: np.ndarray, cov: np.ndarray, w: np.ndarray, k: np.ndarray, texel_m: float, m: int
              ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`cell_multiplier` for points' discs under a few texels: the points splatted bilinearly
    at −shift on the periodic M × M grid (the multiplier's e^{ik·shift} is a move by −shift), its
    FFT, times the Gaussian of the points' weighted mean disc."""
    u = (-shift / texel_m) % m  # (S, 2): x, y in texels
    i0 = np.floor(u).astype(np.int64)
    f = u - i0
    image = np.zeros((m, m))
    for dy in (0, 1):
        for dx in (0, 1):
            share = w * np.where(dx, f[:, 0], 1.0 - f[:, 0]) * np.where(dy, f[:, 1], 1.0 - f[:, 1])
            np.add.at(image, ((i0[:, 1] + dy) % m, (i0[:, 0] + dx) % m), share)
    c = np.einsum("s,sij->ij", w, cov)
    kx, ky = k[None, :], k[:, None]
    disc = np.exp(-0.5 * (kx * kx * c[0, 0] + 2.0 * kx * ky * c[0, 1] + ky * ky * c[1, 1]))
    out = np.fft.fft2(image) * disc
    rows, cols = np.nonzero(np.abs(out) > NEGLIGIBLE_VALUE)
    return rows, cols, out[rows, cols].astype(np.complex64)


def dense(sparse: tuple[np.ndarray, np.ndarray, np.ndarray], m: int) -> np.ndarray:
    """(M, M) complex64: a multiplier from :func:`cell_multiplier`'s (rows, columns, values)."""
    out = np.zeros((m, m), np.complex64)
    out[sparse[0], sparse[1]] = sparse[2]
    return out
