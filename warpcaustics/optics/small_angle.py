"""The water column's small-angle transfer: scattered light with its spatial structure (issue 32).

``optics.scattering = "small_angle"``. Light scattered by a few degrees keeps travelling almost with
the beam and lands beside the ray it left: a ray that scatters at path length s' with angle θ lands
θ (s − s') from where it would have, s being its path to the floor. In the small-angle approximation
the scatterings along a path are a Poisson process of rate b, each one displacing the ray by an
independent angle drawn from the phase function, so the floor's irradiance is the unscattered
pattern convolved with the beam spread function, whose Fourier transform at spatial frequency q
(rad m⁻¹) is

    B̃(q, s) = exp(−c s + b ∫₀^s p̃(q u) du),      p̃(ν) = 2π ∫₀^π p(θ) J₀(ν θ) sin θ dθ,

Wells (1973)'s transfer of the water column (the modulation transfer function of Zaneveld &
Beardsley 1969 and of Mertens & Replogle 1977; Zaneveld et al. 2001 used it for wave focusing).
The single-scattering map S is already the unscattered pattern, attenuated by e^{−c s}, so the
scattered light is F⁻¹[Ŝ (e^{b s G(q s)} − 1)], with G(x) = (1/x) ∫₀^x p̃(v) dv (G(0) = 1).

A beam at θ_w from the vertical meets the floor obliquely: a displacement perpendicular to the
beam in its vertical plane is stretched by 1/cos θ_w on the floor, so the transfer at a floor
frequency (k_a along the beam's azimuth, k_p across) is the one at q = √((k_a/cos θ_w)² + k_p²).

The approximation keeps every scattered photon going forward, so its mean, S̄ e^{b s}, is too high
(light scattered backwards or far sideways, paths lengthened by scattering, are missed); the mode
takes the mean of the scattered light from the random walk (``kernels/caustics/multiple.py``) and
scales the transferred scattered light to it: the unscattered pattern stays exact, the scattered
light keeps the small-angle structure and the walk's amount, without the walk's noise.
"""

from __future__ import annotations

import functools

import numpy as np

from warpcaustics.config import OpticsConfig, PhaseFunctionKind
from warpcaustics.optics.phase import phase_quadrature

SPREAD_NODES = 2000
"""Points of the G(x) table, log-spaced in x = q s from 1e-3 to 1e7 (rad)."""


def phase_hankel(theta: np.ndarray, weight: np.ndarray, nu: np.ndarray) -> np.ndarray:
    """p̃(ν) = 2π ∫ p(θ) J₀(ν θ) sin θ dθ on a quadrature (θ, w) of the phase function
    (:func:`~warpcaustics.optics.phase.phase_quadrature`), 1 at ν = 0."""
    from scipy.special import j0

    out = np.empty(len(nu))
    for i in range(0, len(nu), 64):  # (64, grid) blocks keep memory small
        out[i : i + 64] = j0(np.outer(nu[i : i + 64], theta)) @ weight
    return out / weight.sum()


def spread_from_phase(theta: np.ndarray, weight: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(x, G(x)) on the table's nodes for a phase function given by a quadrature (θ, w): p̃ by
    :func:`phase_hankel`, its running integral by trapezoids, G(0) = 1. Kept on disk between
    processes (:mod:`warpcaustics.io.table_cache`: about 4 s of Bessel functions a phase function)."""
    from warpcaustics.io.table_cache import cached_table, table_key

    x = np.concatenate([[0.0], np.geomspace(1e-3, 1e7, SPREAD_NODES)])

    def compute() -> np.ndarray:
        pt = phase_hankel(theta, weight, x)
        cumulative = np.concatenate([[0.0], np.cumsum(0.5 * (pt[1:] + pt[:-1]) * np.diff(x))])
        g = np.empty_like(x)
        g[0] = 1.0
        g[1:] = cumulative[1:] / x[1:]
        return g

    import scipy

    key = table_key(theta, weight, x, phase_hankel, spread_from_phase, f"scipy {scipy.__version__}")
    return x, cached_table("spread", key, compute, x.shape)


@functools.cache
def _spread_table(kind: PhaseFunctionKind, hg_g: float | None, station: str) -> tuple[np.ndarray, np.ndarray]:
    return spread_from_phase(*phase_quadrature(kind, hg_g, station))


def spread_table(optics: OpticsConfig) -> tuple[np.ndarray, np.ndarray]:
    """(x, G(x)): G(x) = (1/x) ∫₀^x p̃(v) dv of the configured phase function, so that
    ∫₀^s p̃(q u) du = s G(q s). Cached per phase function."""
    return _spread_table(optics.phase_function, optics.hg_g, optics.petzold_station.value)


def spread(optics: OpticsConfig, x: np.ndarray) -> np.ndarray:
    """G(x) at x = q s ≥ 0; past the table's end ∫₀^x p̃ has converged, so G falls as 1/x."""
    xs, table = spread_table(optics)
    x = np.asarray(x, np.float64)
    return np.where(x <= xs[-1], np.interp(x, xs, table), table[-1] * xs[-1] / np.maximum(x, xs[-1]))


def forward_path(optics: OpticsConfig, kx: np.ndarray, ky: np.ndarray, path_m: float,
                 direction: np.ndarray) -> np.ndarray:
    """∫₀^s p̃(q u) du = s G(q s) [m] on the floor frequencies (kx, ky) [rad m⁻¹] for a beam with unit
    direction ``direction`` (in the water, pointing down) and path s = ``path_m`` to the floor; the
    scattered light's transfer is e^{b s G(q s)} − 1, for every band's b."""
    d = np.asarray(direction, np.float64)
    cos_w = abs(d[2])
    horizontal = np.hypot(d[0], d[1])
    if horizontal > 1e-12:
        ax, ay = d[0] / horizontal, d[1] / horizontal
    else:
        ax, ay = 1.0, 0.0
    along = (kx * ax + ky * ay) / cos_w
    across = -kx * ay + ky * ax
    q = np.hypot(along, across)
    return path_m * spread(optics, q * path_m)


def wells_multiplier(optics: OpticsConfig, texel_m: float, m: int, path_m: float,
                     scattering_per_m: np.ndarray, direction: np.ndarray):
    """The closed form's multiplier of a single-scattering map's spectrum, e^{b s G(q s)} − 1, on an
    M × M periodic grid of ``texel_m`` texels (numpy's FFT order): a function of the band giving
    (M, M), and its k = 0 values (K,) (e^{b s} − 1)."""
    k = 2.0 * np.pi * np.fft.fftfreq(m, d=texel_m)
    kx, ky = np.meshgrid(k, k)  # [iy, ix]
    forward = forward_path(optics, kx, ky, path_m, direction)
    b = np.asarray(scattering_per_m, np.float64)
    return (lambda band: np.expm1(b[band] * forward)), np.expm1(b * path_m)


def transferred(single: np.ndarray, multiplier) -> np.ndarray:
    """(K, M, M) F⁻¹[Ŝ × multiplier(band)] per band: the scattered light of a single-scattering map
    ``single`` (K, M, M) taken as periodic (``multiplier`` as :func:`wells_multiplier` gives it)."""
    spectrum = np.fft.fft2(np.asarray(single, np.float64), axes=(-2, -1))
    out = np.empty(single.shape, np.float64)
    for band in range(len(out)):
        out[band] = np.fft.ifft2(spectrum[band] * multiplier(band)).real
    return out
