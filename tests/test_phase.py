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
