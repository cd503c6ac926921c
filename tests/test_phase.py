"""Phase functions on the device: Henyey–Greenstein moments and Petzold's measured table."""

import numpy as np
import pytest

from warpcaustics.config import config_from_dict
from warpcaustics.optics.phase import PhaseFunction


def _sphere_integrals(pf, device):
    """∫ p dΩ and ∫ cosθ p dΩ by float64 quadrature over μ = cosθ, dense towards the forward peak."""
    mu = np.concatenate([np.linspace(-1.0, 0.9, 20001), 1.0 - np.logspace(-1, -8, 20001)])
    p = pf.evaluate(mu, device).astype(np.float64)
    return 2 * np.pi * np.trapezoid(p, mu), 2 * np.pi * np.trapezoid(mu * p, mu)


@pytest.mark.parametrize("g", [0.0, 0.5, 0.9])
def test_henyey_greenstein_is_normalised_with_mean_cosine_g(device, g):
    """HG on the device integrates to 1 over the sphere and has mean cosine g (quadrature, 2e-3)."""
    pf = PhaseFunction.from_optics(config_from_dict({}, {"optics.hg_g": g}).optics, device)
    norm, mean_cos = _sphere_integrals(pf, device)
    assert norm == pytest.approx(1.0, abs=2e-3)
    assert mean_cos == pytest.approx(g, abs=2e-3)


def test_petzold_phase_function_is_the_normalised_measurement(device):
    """The device's Petzold phase function has the shape of the station's measured β(θ) (jerlov
    package) from 0.3° on, and integrates to 1 over the whole sphere — the measured share below
    0.1° in the forward cone included (quadrature of the device function itself, 5e-3)."""
    import warnings

    import jerlov

    optics = config_from_dict({}, {"optics.phase_function": "petzold",
                                   "optics.petzold_station": "AUTEC 8"}).optics
    pf = PhaseFunction.from_optics(optics, device)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        vsf = jerlov.petzold_scattering("AUTEC 8")
    theta = np.radians(vsf.angles_deg)
    # float32 cos θ resolves θ only to ~0.02° near the forward direction: compare from 0.3° on.
    far = vsf.angles_deg >= 0.3
    ratio = pf.evaluate(np.cos(theta[far]), device) / np.asarray(vsf.vsf)[far]
    np.testing.assert_allclose(ratio / ratio.mean(), 1.0, rtol=2e-3)
    mu = np.concatenate([np.linspace(-1.0, 0.999, 200001), 1.0 - np.logspace(-3, -9, 200001)])
    p = pf.evaluate(mu, device).astype(np.float64)
    assert 2 * np.pi * np.trapezoid(p, mu) == pytest.approx(1.0, abs=5e-3)


def test_default_g_is_the_petzold_mean_cosine(device):
    """Without optics.hg_g, Henyey–Greenstein takes the mean cosine of the Petzold station's
    normalised phase function, which the device's Petzold function reproduces by quadrature."""
    optics = config_from_dict({}).optics
    hg = PhaseFunction.from_optics(optics, device)
    petzold = PhaseFunction.from_optics(config_from_dict({}, {"optics.phase_function": "petzold"}).optics,
                                        device)
    norm, mean_cos = _sphere_integrals_fine(petzold, device)
    assert hg.g == pytest.approx(mean_cos / norm, abs=5e-3)
    assert 0.8 < hg.g < 0.99  # ocean water scatters strongly forward


def _sphere_integrals_fine(pf, device):
    mu = np.concatenate([np.linspace(-1.0, 0.999, 200001), 1.0 - np.logspace(-3, -9, 200001)])
    p = pf.evaluate(mu, device).astype(np.float64)
    return 2 * np.pi * np.trapezoid(p, mu), 2 * np.pi * np.trapezoid(mu * p, mu)


@pytest.mark.parametrize("station", ["AUTEC 8", "AUTEC 9", "AUTEC 7", "HAOCE 11", "HAOCE 5", "NUC 2240",
                                     "NUC 2200", "NUC 2040"])
def test_forward_cone_is_the_reports_power_law(station):
    """Below 0.1° Petzold's report extends β with its log-log slope, and prints the share f of b that
    the extension holds (jerlov's petzold1972_vsf.csv). The cone's exponent, fixed by continuity at
    0.1° and f alone, is that slope: the measured table's between 0.1° and 0.126° within 0.015, at
    every station; the float64 quadrature holds f below 0.1° (1e-3) and 1 over the sphere (1e-4)."""
    import warnings

    import jerlov

    from warpcaustics.config import PhaseFunctionKind
    from warpcaustics.optics.phase import petzold_table, phase_quadrature

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        vsf = jerlov.petzold_scattering(station)
    slope = -np.log(vsf.vsf[1] / vsf.vsf[0]) / np.log(vsf.angles_deg[1] / vsf.angles_deg[0])
    _, _, cone = petzold_table(station)
    assert cone.exponent == pytest.approx(slope, abs=0.015)
    theta, weight = phase_quadrature(PhaseFunctionKind.PETZOLD, None, station)
    assert weight.sum() == pytest.approx(1.0, abs=1e-4)
    below = weight[theta < cone.theta0].sum() + 0.5 * weight[theta == cone.theta0].sum()
    assert below == pytest.approx(vsf.fraction_below_0_1_deg, rel=1e-3)


def test_walk_samples_the_quadratures_phase_function():
    """The walk's inverse cumulative table, sampled at many uniform probabilities, gives the phase
    function's own shares: below 0.01°, 0.1°, 1° and 10° within 2e-3 of the float64 quadrature's
    (Petzold, HAOCE 11: the power-law cone carries shares well below float32's 0.02° in cos θ)."""
    from warpcaustics.caustics.multiple import inverse_cdf_table
    from warpcaustics.optics.phase import quadrature_for

    optics = config_from_dict({}, {"optics.phase_function": "petzold",
                                   "optics.petzold_station": "HAOCE 11"}).optics
    table = inverse_cdf_table(optics)
    u = (np.arange(200000) + 0.5) / 200000
    drawn = np.interp(u * (len(table) - 1), np.arange(len(table)), table)
    theta, weight = quadrature_for(optics)
    for limit in np.radians([0.01, 0.1, 1.0, 10.0]):
        assert np.mean(drawn < limit) == pytest.approx(weight[theta < limit].sum(), abs=2e-3)
