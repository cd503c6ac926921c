"""Directional wave spectra P(k) [m⁴] on the wavenumber plane, ∫P d²k = height variance, each
registered under its ``water.spectrum`` name (:data:`SPECTRA`): Phillips (Tessendorf 2001),
JONSWAP with cos-2s spreading (Hasselmann et al. 1973), and the unified spectrum of Elfouhaily,
Chapron, Katsaros & Vandemark (1997) with its own spreading function
(:mod:`warpcaustics.water.elfouhaily`). All float64 numpy, zero at k = 0."""

from __future__ import annotations

import numpy as np

from warpcaustics.config import Config, WaterSpectrum
from warpcaustics.water.elfouhaily import elfouhaily_spectrum
from warpcaustics.water.surface import GRAVITY_M_S2


def phillips_spectrum(kx: np.ndarray, ky: np.ndarray, *, amplitude: float, wind_speed_m_s: float,
                      wind_direction_deg: float, small_wave_m: float) -> np.ndarray:
    """Phillips spectrum P(k) [m^4] (Tessendorf 2001, eq. 40–41), zero at k = 0.

    ``P = A exp(-1/(k l)^2)/k^4 |k̂·ŵ|^2 exp(-k^2 l_small^2)`` with ``l = V^2/g``; its integral over
    the k-plane is the height variance ``A π l^2 / 2`` (without the small-wave factor).
    """
    k2 = kx**2 + ky**2
    k = np.sqrt(k2)
    big_l = wind_speed_m_s**2 / GRAVITY_M_S2
    w = np.radians(wind_direction_deg)
    with np.errstate(divide="ignore", invalid="ignore"):
        cos_kw = (kx * np.cos(w) + ky * np.sin(w)) / k
        p = amplitude * np.exp(-1.0 / (k2 * big_l**2)) / k2**2 * cos_kw**2 * np.exp(-k2 * small_wave_m**2)
    p[k == 0.0] = 0.0
    return p


def jonswap_spectrum(kx: np.ndarray, ky: np.ndarray, *, wind_speed_m_s: float,
                     wind_direction_deg: float, fetch_m: float, gamma: float, spreading_s: float,
                     depth_m: float, small_wave_m: float) -> np.ndarray:
    """JONSWAP directional wavenumber spectrum P(k) [m^4], zero at k = 0.

    Frequency spectrum (Hasselmann et al. 1973, in the form of Horvath 2015, "Empirical
    directional wave spectra for computer graphics", eq. 28–30):
    ``S(ω) = α g² ω⁻⁵ exp(−5/4 (ω_p/ω)⁴) γ^r``, ``r = exp(−(ω − ω_p)² / (2σ²ω_p²))``,
    σ = 0.07 for ω ≤ ω_p else 0.09, ``α = 0.076 (U²/(F g))^0.22``, ``ω_p = 22 (g²/(U F))^(1/3)``.
    Directional spreading: Longuet-Higgins cos-2s, ``D(θ) ∝ |cos((θ − θ_w)/2)|^{2s}``, normalised
    numerically over (−π, π]. Change of variables to the wavenumber plane with the finite-depth
    dispersion relation: ``P(k) = S(ω(k)) D(θ) (dω/dk) / k`` so that ∫P d²k = ∫S dω.
    """
    g = GRAVITY_M_S2
    k = np.hypot(kx, ky)
    alpha = 0.076 * (wind_speed_m_s**2 / (fetch_m * g)) ** 0.22
    omega_p = 22.0 * (g * g / (wind_speed_m_s * fetch_m)) ** (1.0 / 3.0)
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        th = np.tanh(k * depth_m)
        omega = np.sqrt(g * k * th)
        domega_dk = g * (th + k * depth_m * (1.0 - th * th)) / (2.0 * omega)
        sigma = np.where(omega <= omega_p, 0.07, 0.09)
        r = np.exp(-((omega - omega_p) ** 2) / (2.0 * sigma**2 * omega_p**2))
        s_omega = alpha * g * g / omega**5 * np.exp(-1.25 * (omega_p / omega) ** 4) * gamma**r
        theta = np.arctan2(ky, kx) - np.radians(wind_direction_deg)
        p = s_omega * cos2s_spreading(theta, spreading_s) * domega_dk / k * np.exp(-k * k * small_wave_m**2)
    p[~np.isfinite(p) | (k == 0.0)] = 0.0
    return p


def cos2s_spreading(theta: np.ndarray, s: float) -> np.ndarray:
    """Longuet-Higgins cos-2s directional spreading, normalised so ∫ D dθ = 1 over a full turn."""
    fine = np.linspace(-np.pi, np.pi, 20001)
    norm = np.trapezoid(np.abs(np.cos(fine / 2.0)) ** (2.0 * s), fine)
    return np.abs(np.cos(theta / 2.0)) ** (2.0 * s) / norm


SPECTRA = {
    WaterSpectrum.PHILLIPS: lambda cfg, kx, ky: phillips_spectrum(
        kx, ky, amplitude=cfg.water.phillips_amplitude, wind_speed_m_s=cfg.water.wind_speed_m_s,
        wind_direction_deg=cfg.water.wind_direction_deg, small_wave_m=cfg.water.small_wave_m),
    WaterSpectrum.JONSWAP: lambda cfg, kx, ky: jonswap_spectrum(
        kx, ky, wind_speed_m_s=cfg.water.wind_speed_m_s, wind_direction_deg=cfg.water.wind_direction_deg,
        fetch_m=cfg.water.fetch_m, gamma=cfg.water.jonswap_gamma, spreading_s=cfg.water.spreading_s,
        depth_m=wave_depth_m(cfg), small_wave_m=cfg.water.small_wave_m),
    WaterSpectrum.ELFOUHAILY: lambda cfg, kx, ky: elfouhaily_spectrum(
        kx, ky, wind_speed_m_s=cfg.water.wind_speed_m_s, wind_direction_deg=cfg.water.wind_direction_deg,
        fetch_m=cfg.water.fetch_m, small_wave_m=cfg.water.small_wave_m),
}
"""``water.spectrum`` → P(cfg, kx, ky) [m⁴]."""


def wave_depth_m(cfg: Config) -> float:
    """The depth the ocean's waves feel: ``water.depth_m``, or ``floor.depth_m`` when it is 0."""
    return cfg.water.depth_m or cfg.floor.depth_m


def ocean_spectrum(cfg: Config, kx: np.ndarray, ky: np.ndarray) -> np.ndarray:
    """The directional spectrum P(k) [m⁴] named by ``water.spectrum``, without the waves of
    ``water.shortest_wave_m`` or shorter (k ≥ 2π/λ, to a part in 10⁹ so that a patch of that side's
    own wavenumbers are dropped)."""
    p = SPECTRA[cfg.water.spectrum](cfg, kx, ky)
    shortest = cfg.water.shortest_wave_m
    if shortest:
        p = np.where(np.hypot(kx, ky) >= 2.0 * np.pi / shortest * (1.0 - 1e-9), 0.0, p)
    return p
