"""The unified directional spectrum of wind waves, long and short, of Elfouhaily, Chapron, Katsaros &
Vandemark (1997), "A unified directional spectrum for long and short wind-driven waves", J. Geophys.
Res. 102(C7), 15781–15796 (ECKV): JONSWAP-like long waves and Phillips–Kitaigorodskii short waves
down to capillary lengths, both driven by the wind through a wave age, with a spreading function
that narrows and widens with k.

Equation numbers are the paper's, as cited by independent implementations that agree on them
(E. Bruneton's 2010 ocean-lighting code; ``pakodekker/oceansar``; Elfouhaily's own 1996 Fortran in
``edinnat/Ocean-reference-model-mirror``, ``Ocean/Sea_Spectrum/spectrum_El.f``): the paper's body
was not at hand, so docs/physics.md says which choices rest on which source.

- Omnidirectional elevation spectrum S(k) = k⁻³ (B_l + B_h) [m³] (eq. 30).
- Long waves: B_l = ½ α_p (c_p/c) F_p (31), F_p = L_PM J_p exp(−Ω/√10 (√(k/k_p) − 1)) (32),
  L_PM = exp(−5/4 (k_p/k)²) (2), J_p = γ^Γ, Γ = exp(−(√(k/k_p) − 1)²/(2σ²)), σ = 0.08(1 + 4Ω_c⁻³),
  γ = 1.7 (Ω_c < 1) or 1.7 + 6 log₁₀ Ω_c (3), α_p = 6·10⁻³ √Ω (34), k_p = k_0 Ω_c², k_0 = g/U₁₀².
- Wave age from the fetch x: Ω_c = 0.84 tanh((X/X_0)^0.4)^−0.75, X = k_0 x, X_0 = 2.2·10⁴ (37).
- Phase speed with capillarity: c = √(g/k (1 + (k/k_m)²)), k_m = 370 rad/m, c_m = 0.23 m/s (24).
- Short waves: B_h = ½ α_m (c_m/c) F_m (40), F_m = L_PM J_p exp(−¼ (k/k_m − 1)²) (41: the factor
  L_PM J_p is the one Elfouhaily's own code and Mobley's Ocean Optics Web Book put on B_h as on
  B_l; as printed, eq. 41 lacks it and S then diverges as k → 0), α_m = 10⁻² (1 + ln(u*/c_m)) for
  u* ≤ c_m, 10⁻² (1 + 3 ln(u*/c_m)) above (44), taken as 0 where it would be negative (u* < c_m/e,
  winds under about 2.5 m/s: no short wind waves).
- Friction velocity: u* = κ U₁₀ / ln(10/z_0), κ = 0.41 (60), with the wave-age roughness of
  Donelan et al. (1993), z_0 = 3.7·10⁻⁵ (U₁₀²/g) (U₁₀/c_p)^0.9 (66).
- Spreading: Φ(k, φ) = (1 + Δ(k) cos 2φ)/(2π) (49), Δ = tanh(a_0 + a_p (c/c_p)^2.5 + a_m
  (c_m/c)^2.5), a_0 = ln 2/4, a_p = 4, a_m = 0.13 u*/c_m (57, 59).
- On the wavenumber plane: P(k_x, k_y) = S(k) Φ(k, φ)/k (67), so that ∫P d²k = ∫S dk.
"""

from __future__ import annotations

import math

import numpy as np

from warpcaustics.water.surface import GRAVITY_M_S2

K_M = 370.0
"""Wavenumber of the phase-speed minimum, gravity–capillary [rad/m] (ECKV, with eq. 24)."""
C_M = 0.23
"""The minimum phase speed, at k_m [m/s]."""
X_0 = 2.2e4
"""Dimensionless fetch of full development (eq. 37)."""
KARMAN = 0.41
"""von Kármán's constant in u* = κ U₁₀/ln(10/z_0) (eq. 60)."""
OMEGA_C_RANGE = (0.84, 5.0)
"""Inverse wave ages the paper's JONSWAP fits cover: 0.84 fully developed, 5 very young."""


def inverse_wave_age(wind_speed_m_s: float, fetch_m: float) -> float:
    """Ω_c = U₁₀/c_p from the fetch (eq. 37): 0.84 fully developed, rising as the fetch shortens."""
    x = GRAVITY_M_S2 / wind_speed_m_s**2 * fetch_m
    return 0.84 * math.tanh((x / X_0) ** 0.4) ** -0.75


def shortest_fetch_m(wind_speed_m_s: float) -> float:
    """The fetch at which Ω_c reaches the fits' upper limit 5 (eq. 37 inverted)."""
    t = (OMEGA_C_RANGE[1] / 0.84) ** (-1.0 / 0.75)
    return X_0 * math.atanh(t) ** 2.5 * wind_speed_m_s**2 / GRAVITY_M_S2


def phase_speed(k: np.ndarray) -> np.ndarray:
    """c(k) of gravity–capillary waves in deep water (eq. 24) [m/s]."""
    return np.sqrt(GRAVITY_M_S2 / k * (1.0 + (k / K_M) ** 2))


def friction_velocity(wind_speed_m_s: float, omega: float) -> float:
    """u* [m/s] from U₁₀ over a sea of inverse wave age Ω = U₁₀/c_p (eqs. 60, 66)."""
    z0 = 3.7e-5 * wind_speed_m_s**2 / GRAVITY_M_S2 * omega**0.9
    return KARMAN * wind_speed_m_s / math.log(10.0 / z0)


def curvature_spectra(k: np.ndarray, wind_speed_m_s: float, fetch_m: float) -> tuple[np.ndarray, ...]:
    """(B_l, B_h, Δ) at wavenumbers ``k`` > 0: the long- and short-wave curvature spectra (eqs. 31,
    40; S = (B_l + B_h)/k³) and the spreading's up/cross-wind contrast Δ(k) (eq. 57)."""
    k = np.asarray(k, np.float64)
    u10 = float(wind_speed_m_s)
    omega_c = inverse_wave_age(u10, fetch_m)
    kp = GRAVITY_M_S2 / u10**2 * omega_c**2
    c = phase_speed(k)
    cp = float(phase_speed(np.array(kp)))
    omega = u10 / cp
    sqrt_ratio = np.sqrt(k / kp)
    sigma = 0.08 * (1.0 + 4.0 * omega_c**-3)
    gamma = 1.7 if omega_c < 1.0 else 1.7 + 6.0 * math.log10(omega_c)
    peak = gamma ** np.exp(-((sqrt_ratio - 1.0) ** 2) / (2.0 * sigma**2))  # J_p
    lpm_jp = np.exp(-1.25 * (kp / k) ** 2) * peak
    alpha_p = 6e-3 * math.sqrt(omega)
    b_long = 0.5 * alpha_p * cp / c * lpm_jp * np.exp(-omega / math.sqrt(10.0) * (sqrt_ratio - 1.0))
    ustar = friction_velocity(u10, omega)
    log_u = math.log(ustar / C_M)
    alpha_m = max(0.0, 1e-2 * (1.0 + (log_u if ustar <= C_M else 3.0 * log_u)))
    b_short = 0.5 * alpha_m * C_M / c * lpm_jp * np.exp(-0.25 * (k / K_M - 1.0) ** 2)
    a_m = 0.13 * ustar / C_M
    delta = np.tanh(math.log(2.0) / 4.0 + 4.0 * (c / cp) ** 2.5 + a_m * (C_M / c) ** 2.5)
    return b_long, b_short, delta


def elfouhaily_spectrum(kx: np.ndarray, ky: np.ndarray, *, wind_speed_m_s: float, wind_direction_deg: float,
                        fetch_m: float, small_wave_m: float = 0.0) -> np.ndarray:
    """P(k) [m⁴] on the wavenumber plane (eq. 67): (1/2π) k⁻⁴ (B_l + B_h)(1 + Δ cos 2φ), φ from the
    wind, times Tessendorf's exp(−k² l²) for ``small_wave_m`` = l; zero at k = 0."""
    kx = np.asarray(kx, np.float64)
    ky = np.asarray(ky, np.float64)
    k = np.hypot(kx, ky)
    p = np.zeros_like(k)
    live = k > 0.0
    b_long, b_short, delta = curvature_spectra(k[live], wind_speed_m_s, fetch_m)
    phi = np.arctan2(ky[live], kx[live]) - math.radians(wind_direction_deg)
    kl = k[live]
    p[live] = ((b_long + b_short) / kl**4 * (1.0 + delta * np.cos(2.0 * phi)) / (2.0 * math.pi)
               * np.exp(-kl * kl * small_wave_m**2))
    return p
