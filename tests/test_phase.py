"""Phase functions on the device: Henyey–Greenstein moments and Petzold's measured table."""

import numpy as np
import pytest

from warpcaustics.config import config_from_dict
from warpcaustics.phase import PhaseFunction, petzold_table


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


def test_petzold_table_is_the_measurement(device):
    """The device's Petzold phase function equals β(θ)/b of the station (jerlov package) at the
    measured angles, and ∫ p dΩ over 0.1–180° plus the unmeasured share below 0.1° is 1 (2 %)."""
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
    np.testing.assert_allclose(pf.evaluate(np.cos(theta[far]), device),
                               (np.asarray(vsf.vsf) / vsf.b)[far], rtol=2e-3)
    t, p, below = petzold_table("AUTEC 8")
    fine = np.linspace(t[0], np.pi, 200001)
    p_fine = np.exp(np.interp(fine, t, np.log(p)))  # the same log-linear rule as the device
    assert 2 * np.pi * np.trapezoid(p_fine * np.sin(fine), fine) + below == pytest.approx(1.0, abs=0.02)


def test_default_g_is_the_petzold_mean_cosine():
    """Without optics.hg_g, Henyey–Greenstein takes the mean cosine of the Petzold station."""
    optics = config_from_dict({}).optics
    pf = PhaseFunction.from_optics(optics, "cpu")
    t, p, _ = petzold_table(optics.petzold_station.value)
    w = np.sin(t) * p
    assert pf.g == pytest.approx(np.trapezoid(np.cos(t) * w, t) / np.trapezoid(w, t), rel=1e-12)
    assert 0.8 < pf.g < 0.99  # ocean water scatters strongly forward
