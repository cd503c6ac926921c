"""The water column's beam spread function from a random walk: ``optics.beam_spread = "walk"``.

The small-angle transfer (:mod:`warpcaustics.optics.small_angle`) spreads the scattered light by
Wells (1973)'s closed form, which takes every scattering as small: a ray turned by θ is displaced by
u θ over the path u left to it (not u tan θ), light scattered sideways or backwards still goes
forward, and a scattered ray's lengthened path is absorbed as if it were the straight one. Against
the full random walk on an FFT sea that leaves +4 to +9 % of power at the largest scales and, in the
strongly absorbed red, −7 to −8 % at 0.5–4 m (docs/physics.md). Here the same transfer is measured
instead: the beam spread function of Mertens & Replogle (1977) — where the light of a pencil beam
entering still water lands on the floor — by a Monte Carlo walk of the homogeneous column, with the
exact geometry of each scattering (the phase function sampled as the random walk of
``kernels/caustics/multiple.py`` samples it), absorption along each photon's own path, and the flat
surface's Fresnel reflection of upwelling light (total past the critical angle). Only photons that
scattered at least once are kept: the unscattered light is the flux-ratio map itself.

One walk serves every band: the photons scatter at the largest b of the bands, b*, and each band
weights a photon that scattered n times over a path L by (b/b*)ⁿ e^{−(a + b − b*) L} — the ratio of
the two Poisson processes' likelihoods times the band's absorption — exact in expectation for each
band's own (a, b). The spread is tallied on a grid finer than the map's over the same period and
Fourier transformed: the transfer's multiplier of the single-scattering map is H̃(k) e^{c s̄}, with
H the tallied light per unit of the beam's power (its k = 0 value is the e^{b s̄} − 1 of the closed
form, corrected for paths and backward light); where the tally is too coarse to resolve a frequency
it blends into the closed form, which holds there (only small angles reach the fine scales).

A convolution lands each scattered photon at its ray's unscattered floor point plus the spread's
offset. Where the surface turns a ray by δ (the focusing), the unscattered point moves by J₀ δ, but
a photon that scattered moves by its own J δ: the walk carries the derivatives of each photon's path
by a turn of the entering direction (the scattering's frame turned with the photon), and a photon's
share of a pattern of wavenumber k is weighted by k̂ᵀ M k̂, M = J J₀⁻¹ (a height field focuses along
its gradient, so the displacement of a pattern of wavenumber k is along k; M = 1 for a photon that never
turned; a turned ray's light fans out further, 1.03–1.07 on average in Darecki's water). With the
path's derivative of the transfer (:class:`~warpcaustics.caustics.small_angle.SmallAngleScattering`)
this is the scattered light to first order in the surface's slopes and heights: on a sinusoidal sea
at 9.58 m it matches an independent Monte Carlo to its noise (``tests/test_beam_spread.py``).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from warpcaustics.optics.phase import phase_quadrature
from warpcaustics.optics.snell import fresnel_transmittance

ROULETTE_BELOW = 1e-3
"""A photon whose largest band weight falls below this plays Russian roulette (survives 1 in 10,
its weight ×10)."""

MAX_EVENTS = 1000
"""Scatterings after which a photon is dropped (its light lost; with the roulette above none has
come near it in the project's waters)."""


@dataclass(frozen=True)
class SpreadSample:
    """The scattered photons that reached the floor, in the beam's frame: offsets [m] from the
    unscattered ray's floor point along the beam's horizontal direction and across it, and each
    one's share of the beam's power per band (K, n), float32."""

    along: np.ndarray
    across: np.ndarray
    weight: np.ndarray
    photons: int
    memory: np.ndarray | None = None
    """(4, n) each photon's focusing memory M (row-major, beam frame): how its landing moves when
    the unscattered ray's landing moves by ξ is M ξ (the identity for a photon that never turned;
    a turned photon's landing moves further: 1.03–1.07 on average in Darecki et al.'s water)."""


def _turn(d: np.ndarray, theta: np.ndarray, phi: np.ndarray) -> np.ndarray:
    """(3, n) unit directions ``d`` turned by polar angles θ at azimuths φ about themselves."""
    helper = np.where(np.abs(d[0]) > 0.9, 0.0, 1.0)
    # e1 = normalise(helper_axis × d), helper_axis = x, or y where d is near x
    hx, hy = helper, 1.0 - helper
    e1 = np.stack([hy * d[2], -hx * d[2], hx * d[1] - hy * d[0]])
    e1 /= np.linalg.norm(e1, axis=0)
    e2 = np.cross(d, e1, axis=0)
    s, c = np.sin(theta), np.cos(theta)
    out = c * d + s * (np.cos(phi) * e1 + np.sin(phi) * e2)
    return out / np.linalg.norm(out, axis=0)


def walk_column(theta: np.ndarray, weight: np.ndarray, absorption: np.ndarray, scattering: np.ndarray,
                cos_w: float, depth_m: float, ior: float, photons: int, seed: int, *,
                fresnel_top: bool = True) -> SpreadSample:
    """Walk ``photons`` photons of a pencil beam entering still water at the origin, going down at
    cos θ_w = ``cos_w`` along +x, through water of ``absorption`` and ``scattering`` (K,) [1/m] with
    the phase function given by its quadrature (θ, w), to the floor at ``depth_m``; upwelling light
    meets the flat surface (Fresnel, index ``ior``; ``fresnel_top=False``: it leaves). Returns the
    photons that scattered at least once and reached the floor (:class:`SpreadSample`)."""
    a = np.asarray(absorption, np.float64)
    b = np.asarray(scattering, np.float64)
    b_star = float(b.max())
    if b_star <= 0.0:  # water that scatters nothing: no photon scatters on its way to the floor
        none = np.zeros(0)
        return SpreadSample(none, none, np.zeros((len(b), 0), np.float32), photons,
                            np.zeros((4, 0), np.float32))
    cdf = (np.cumsum(weight) - 0.5 * weight) / weight.sum()  # as the walk's inverse_cdf_table
    rng = np.random.default_rng(seed)
    sin_w = np.sqrt(max(0.0, 1.0 - cos_w * cos_w))
    hit_x = depth_m * sin_w / cos_w  # where the unscattered ray meets the floor
    pos = np.zeros((3, photons))
    d = np.tile(np.array([[sin_w], [0.0], [-cos_w]]), (1, photons))
    # tangents: the position's and direction's derivatives by a turn of the entering direction in
    # the beam's vertical plane (0) and across it (1)
    t_pos = np.zeros((2, 3, photons))
    t_dir = np.zeros((2, 3, photons))
    t_dir[0] = np.array([[cos_w], [0.0], [sin_w]])
    t_dir[1, 1] = 1.0
    events = np.zeros(photons, np.int64)
    path = np.zeros(photons)
    factor = np.ones(photons)  # Fresnel reflections and the roulette's boosts, every band alike
    alive = np.arange(photons)
    out_idx, out_x, out_y, out_j = [], [], [], []
    while alive.size:
        p, dd = pos[:, alive], d[:, alive]
        tp, td = t_pos[:, :, alive], t_dir[:, :, alive]
        step = -np.log1p(-rng.random(alive.size)) / b_star
        z_new = p[2] + step * dd[2]
        floor = (dd[2] < 0) & (z_new <= -depth_m)
        top = (dd[2] > 0) & (z_new >= 0.0) & ~floor
        inside = ~(floor | top)
        dz = np.where(inside, 1.0, dd[2])
        t = np.where(floor, (-depth_m - p[2]) / dz, np.where(top, -p[2] / dz, step))
        # a step to a plane ends on it however the direction turns: its length moves with the tangent
        dt = np.where(inside, 0.0, -(tp[:, 2] + t * td[:, 2]) / dz)
        tp = tp + t * td + dd[None] * dt[:, None]
        p = p + t * dd
        path[alive] += t
        arrived = floor & (events[alive] > 0)
        out_idx.append(alive[arrived])
        out_x.append(p[0, arrived] - hit_x)
        out_y.append(p[1, arrived])
        out_j.append(tp[:, :2, arrived])
        # the surface: reflected back down with R (every band alike), the rest leaves
        factor[alive[top]] *= 1.0 - fresnel_transmittance(dd[2, top], ior) if fresnel_top else 0.0
        dd[2, top] = -dd[2, top]
        td[:, 2, top] = -td[:, 2, top]
        p[2, top] = 0.0
        # scatter the rest: the new direction turned with the old (the scattering's frame carried
        # along), so a tangent keeps cos θ of itself and loses its part along the new direction
        n_in = int(inside.sum())
        if n_in:
            u = rng.random(n_in)
            angle = np.interp(u, cdf, theta)
            new = _turn(dd[:, inside], angle, 2.0 * np.pi * rng.random(n_in))
            old_t = td[:, :, inside]
            td[:, :, inside] = (np.cos(angle) * old_t
                                - dd[None, :, inside] * np.einsum("tkn,kn->tn", old_t, new)[:, None])
            dd[:, inside] = new
            events[alive[inside]] += 1
        pos[:, alive], d[:, alive] = p, dd
        t_pos[:, :, alive], t_dir[:, :, alive] = tp, td
        keep = ~floor
        alive = alive[keep]
        # Russian roulette on the largest band weight
        w_max = factor[alive] * np.max(_band_weights(a, b, b_star, events[alive], path[alive]), axis=0)
        low = w_max < ROULETTE_BELOW
        if low.any():
            survive = rng.random(int(low.sum())) < 0.1
            low_idx = alive[low]
            factor[low_idx[survive]] *= 10.0
            alive = np.concatenate([alive[~low], low_idx[survive]])
        alive = alive[events[alive] < MAX_EVENTS]
    idx = np.concatenate(out_idx)
    w = (factor[idx] * _band_weights(a, b, b_star, events[idx], path[idx]) / photons).astype(np.float32)
    # the focusing each photon keeps: its landing's derivatives over the unscattered ray's,
    # D / cos² θ_w in the beam's plane and D / cos θ_w across it
    j = np.concatenate(out_j, axis=-1)  # (tangent, x/y, n)
    unscattered = np.array([depth_m / cos_w**2, depth_m / cos_w])
    memory = (j / unscattered[:, None, None]).transpose(1, 0, 2).reshape(4, -1).astype(np.float32)
    return SpreadSample(np.concatenate(out_x), np.concatenate(out_y), w, photons, memory)


def _band_weights(a: np.ndarray, b: np.ndarray, b_star: float, events: np.ndarray, path: np.ndarray
                  ) -> np.ndarray:
    """(K, n) each band's weight of photons walked at b*: (b/b*)ⁿ e^{−(a + b − b*) L}."""
    log_ratio = np.log(np.maximum(b, 1e-300) / b_star)
    return np.exp(log_ratio[:, None] * events[None, :] - (a + b - b_star)[:, None] * path[None, :])


SPREAD_CACHE = 20
"""Walks :func:`column_spread` keeps (the last directions' and depths')."""


@functools.lru_cache(maxsize=SPREAD_CACHE)
def column_spread(kind, hg_g, station, absorption: tuple, scattering: tuple, cos_w: float, depth_m: float,
                  ior: float, photons: int, seed: int) -> SpreadSample:
    """:func:`walk_column` for a phase function named as the config names it, cached (the last 20
    directions: the multipliers made from them are cached apart, so a fixed sky walks once)."""
    theta, weight = phase_quadrature(kind, hg_g, station)
    return walk_column(theta, weight, np.asarray(absorption), np.asarray(scattering), cos_w, depth_m, ior,
                       photons, seed)


OVERSAMPLE = 8
"""The spread is tallied on texels this many times finer than the map's (the tally at most
``TALLY_MAX`` across), so that its nearest-texel tally resolves the map's frequencies."""

TALLY_MAX = 1024

EXACT_BELOW = 1 / 16
"""Up to this frequency [cycles per tally texel] the tally's spectrum is taken as it is (its nearest-
texel response, sinc, is within 0.7 % of 1); above it the multiplier blends, by ``BLEND_TO``, into
Wells's closed form — the fine scales, which only small angles reach, where the closed form holds."""

BLEND_TO = 1 / 8


def spread_multiplier(sample: SpreadSample, azimuth: tuple[float, float], texel_m: float, m: int,
                      extinction: np.ndarray, path_m: float, fine):
    """The transfer's multiplier of the single-scattering map's spectrum on an M × M periodic grid of
    ``texel_m`` texels (numpy's FFT order), as :func:`~warpcaustics.optics.small_angle.wells_multiplier`
    gives its own: a function of the band giving (M, M), and its k = 0 values (K,). The spread is
    tallied at the nearest texel of a grid ``OVERSAMPLE`` times finer over the same period (at most
    ``TALLY_MAX`` across), Fourier transformed and taken at the map's frequencies, times e^{c s̄}
    (``extinction`` c (K,), the mean path ``path_m``) so that it multiplies a map already attenuated
    by e^{−c s̄}; past ``EXACT_BELOW`` of the tally's texels it blends into ``fine`` (a function of the
    band, Wells's multiplier on the same grid). With the sample's ``memory`` each photon counts
    k̂ᵀ M k̂ of its weight at k ≠ 0 (M turned to the floor's axes). ``azimuth``: the beam's horizontal
    direction (unit x, y) on the floor."""
    ax, ay = azimuth
    x = sample.along * ax - sample.across * ay
    y = sample.along * ay + sample.across * ax
    r = max(1, min(OVERSAMPLE, TALLY_MAX // m))
    mt, tally_texel = m * r, texel_m / r
    flat = ((np.rint(y / tally_texel).astype(np.int64) % mt) * mt
            + np.rint(x / tally_texel).astype(np.int64) % mt)
    j = np.fft.fftfreq(m, 1.0 / m).astype(np.int64)  # the map's frequencies, in cycles per period
    ft = np.abs(j) / mt  # [cycles per tally texel]
    blend = np.clip((BLEND_TO - ft) / (BLEND_TO - EXACT_BELOW), 0.0, 1.0)
    blend = 0.5 - 0.5 * np.cos(np.pi * blend)
    weight = blend[:, None] * blend[None, :]  # [iy, ix]
    gain = np.exp(np.asarray(extinction, np.float64) * path_m)
    rows = j % mt
    if sample.memory is None:
        parts = [(1.0, None)]
    else:  # k̂ᵀ M k̂ of each photon's memory, M turned to the floor's axes
        turn = np.array([[ax, -ay], [ay, ax]])
        mem = np.einsum("ab,bcn,dc->adn", turn, sample.memory.reshape(2, 2, -1).astype(np.float64), turn)
        kx, ky = np.meshgrid(j.astype(np.float64), j.astype(np.float64))  # [iy, ix]
        k2 = np.where(kx * kx + ky * ky > 0, kx * kx + ky * ky, 1.0)
        parts = [(kx * kx / k2, mem[0, 0]), (kx * ky / k2, mem[0, 1] + mem[1, 0]), (ky * ky / k2, mem[1, 1])]

    def multiplier(band: int) -> np.ndarray:
        measured = np.zeros((m, m), np.complex128)
        for shape, memory in parts:
            w = sample.weight[band] if memory is None else sample.weight[band] * memory
            tally = np.bincount(flat, weights=w, minlength=mt * mt).reshape(mt, mt)
            measured += shape * np.fft.fft2(tally)[np.ix_(rows, rows)]
        measured[0, 0] = float(sample.weight[band].sum(dtype=np.float64))
        measured *= gain[band]
        if weight.min() == 1.0:
            return measured
        return weight * measured + (1.0 - weight) * fine(band)

    return multiplier, sample.weight.sum(axis=1, dtype=np.float64) * gain
