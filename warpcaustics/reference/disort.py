"""Irradiance at the floor of still water from a discrete-ordinate solver: the random walk's reference.

PythonicDISORT (Ho 2024, a numpy/scipy port of Stamnes et al.'s DISORT, in the ``test`` extra)
solves the plane-parallel radiative transfer equation for a homogeneous layer of optical depth
τ = cD and single-scattering albedo ω = b/c lit by a collimated beam — here the sun refracted into
still water, μ0 = cos θ_w, carrying the flux F0 that crossed the surface. It knows a Lambertian
bottom (``BDRF_Fourier_modes = [A]``) but not a reflecting top, so the Fresnel top is iterated: the
upwelling diffuse radiance that reaches the surface, u(0, μ), is reflected as R(μ) u(0, μ) into the
downward boundary condition (only the zeroth Fourier mode matters for fluxes, and a flat surface
keeps each mode), R being the unpolarised Fresnel reflectance water → air (Born & Wolf §1.5.2),
1 past the critical angle. Each pass solves the whole problem again with the new top condition,
until it changes Ed(D) by less than ``tol``: a fixed point of the reflected light.

Strongly forward phase functions use DISORT's δ-M scaling (Wiscombe 1977): the Legendre moment
χ_NLeg is taken as the forward peak (``f_arr``), which is exact for fluxes to the truncation's
accuracy. The quadrature's own error — the Fresnel top's step at the critical angle falls between
the nodes, and Ed(D) converges slowly and not monotonically with the streams (measured for b·D = 4.8,
A = 0.5, a 60° sun: 1.0162, 1.0039, 1.0085, 1.0071 at 32, 64, 128, 256 streams) — is estimated by
:func:`floor_irradiance` as the change from half the streams (``error``), 256 by default.

Used by ``tests/test_walk_boundaries.py`` and ``python -m benchmarks.vs_disort``.
"""

from __future__ import annotations

import numpy as np

from warpcaustics.reference.floor import fresnel_transmittance


def hg_moments(g: float, count: int) -> np.ndarray:
    """Legendre moments χ_l = g^l (l < count) of the Henyey–Greenstein phase function."""
    return float(g) ** np.arange(count, dtype=np.float64)


def table_moments(theta: np.ndarray, weight: np.ndarray, count: int) -> np.ndarray:
    """Legendre moments χ_l = 2π ∫ p(θ) P_l(cos θ) sin θ dθ (l < count) of a phase function given by
    its float64 quadrature (θ, w) (:func:`~warpcaustics.optics.phase.phase_quadrature`: the walk's),
    divided by χ_0 (1 to the quadrature's accuracy); P_l(cos θ) by Bonnet's recurrence."""
    mu = np.cos(np.asarray(theta, np.float64))
    moments = np.empty(count)
    p_prev, p_cur = np.ones_like(mu), mu
    moments[0] = weight.sum()
    for l in range(1, count):
        moments[l] = weight @ p_cur
        p_prev, p_cur = p_cur, ((2 * l + 1) * mu * p_cur - l * p_prev) / (l + 1)
    return moments / moments[0]


def fresnel_reflectance_up(mu: np.ndarray, ior: float) -> np.ndarray:
    """Unpolarised Fresnel reflectance of water → air for upwelling light at cos θ = ``mu``
    (1 past the critical angle, total internal reflection)."""
    return 1.0 - fresnel_transmittance(np.asarray(mu, np.float64), float(ior))


def _solve(tau: float, omega: float, moments: np.ndarray, mu0: float, floor_albedo: float,
           fresnel_ior: float | None, streams: int, tol: float, max_passes: int) -> tuple[float, int]:
    from PythonicDISORT import pydisort

    nleg = streams
    leg = np.zeros(nleg + 1)
    leg[: min(len(moments), nleg + 1)] = moments[: nleg + 1]
    f = leg[nleg]  # δ-M: the moment past the truncation is the forward peak
    bdrf = [float(floor_albedo)] if floor_albedo > 0.0 else []
    b_neg = 0.0
    ed_prev = None
    for passes in range(1, max_passes + 1):
        mu, _, fm, u0 = pydisort(np.array([tau]), np.array([omega]), streams, leg[None, :], mu0,
                                 1.0 / mu0, 0.0, NLeg=nleg, NFourier=1, f_arr=np.array([f]), b_neg=b_neg,
                                 BDRF_Fourier_modes=bdrf)[:4]
        ed = float(sum(fm(tau)))  # diffuse + direct, per unit of the beam's flux (I0 μ0 = 1)
        if fresnel_ior is None or (ed_prev is not None and abs(ed - ed_prev) <= tol * ed):
            return ed, passes
        up = mu[: streams // 2]  # the upward nodes; the downward ones are their negatives, same order
        b_neg = fresnel_reflectance_up(up, fresnel_ior) * u0(0.0)[: streams // 2]  # mode 0 alone
        ed_prev = ed
    raise RuntimeError(f"the Fresnel top did not converge in {max_passes} passes")


def floor_irradiance(depth_m: float, absorption_per_m: float, scattering_per_m: float, mu0: float,
                     moments: np.ndarray, *, floor_albedo: float = 0.0, fresnel_ior: float | None = None,
                     streams: int = 256, tol: float = 1e-9, max_passes: int = 200) -> dict:
    """Ed(D) / F0: the downwelling irradiance at the floor (scattered and direct) over the flux that
    crossed the surface, for a beam at cos θ_w = ``mu0`` in the water. ``floor_albedo``: a Lambertian
    floor (0: black); ``fresnel_ior``: the water's index for a Fresnel top (None: light leaving
    upwards escapes). Returns ``ed`` at ``streams`` streams, ``error``: its change at half as many
    (the quadrature's error, a bound in practice), and ``passes``: the solves the top took."""
    c = absorption_per_m + scattering_per_m
    tau, omega = c * depth_m, scattering_per_m / c
    ed, passes = _solve(tau, omega, moments, mu0, floor_albedo, fresnel_ior, streams, tol, max_passes)
    coarse, _ = _solve(tau, omega, moments, mu0, floor_albedo, fresnel_ior, streams // 2, tol, max_passes)
    return {"ed": ed, "error": abs(ed - coarse), "passes": passes}
