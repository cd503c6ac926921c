"""``RenderResult.transmitted_flux_w_nm`` means one thing for every method: the flux that enters
the water through the surface, before attenuation (issue 25)."""

from __future__ import annotations

import numpy as np
import pytest

import warpcaustics as wc

from helpers import flat_water_scene, fresnel_t_angles

ELEVATION_DEG = 50.0
DEPTH_M = 3.0


def _entering_flux(result) -> np.ndarray:
    """E_sun cosθ T(θ) L² per band (float64): what still water lets in over the whole patch."""
    theta = np.radians(90.0 - ELEVATION_DEG)
    t = fresnel_t_angles(np.array([theta]), 1.0, 1.333)[0]
    return result.sun_irradiance * np.cos(theta) * t * result.extent_m**2


@pytest.mark.parametrize("method", ["fluxratio", "photons", "beams", "sunmap", "eikonal", "wave3d"])
def test_transmitted_flux_is_what_enters_the_water_for_every_method(method):
    """Still, absorbing water: every method's transmitted flux is E_sun cosθ T(θ) L², not reduced by
    the attenuation on the way down (the approximate methods report their flux-ratio pass's)."""
    extra = {"caustics.method": method}
    if method in ("eikonal", "wave3d"):
        extra.update({"caustics.eikonal_resolution": 32, "caustics.wave3d_resolution": 48,
                      "caustics.wave3d_cells_per_wavelength": 4})
    result = wc.render(flat_water_scene(ELEVATION_DEG, DEPTH_M, "turbid_harbor", **extra), device="cpu")
    assert result.floor_flux_w_nm.max() < 0.5 * result.transmitted_flux_w_nm.min()  # the water absorbs
    # float32 per-triangle (per-photon, per-beam) sums of a float64 analytic value
    np.testing.assert_allclose(result.transmitted_flux_w_nm, _entering_flux(result), rtol=2e-5)


def test_delivered_flux_is_the_attenuated_flux_the_floor_receives():
    """Flux ratio: ``delivered_flux_w_nm`` (the old meaning of transmitted) is the entering flux times
    exp(−c D / cosθ_t), and all of it lands on the floor of a still, periodic patch."""
    result = wc.render(flat_water_scene(ELEVATION_DEG, DEPTH_M, "turbid_harbor"), device="cpu")
    theta = np.radians(90.0 - ELEVATION_DEG)
    cos_t = np.sqrt(1.0 - (np.sin(theta) / 1.333) ** 2)
    expected = _entering_flux(result) * np.exp(-result.attenuation_per_m * DEPTH_M / cos_t)
    np.testing.assert_allclose(result.delivered_flux_w_nm, expected, rtol=2e-5)
    np.testing.assert_allclose(result.floor_flux_w_nm, result.delivered_flux_w_nm, rtol=1e-5)


def test_transmitted_flux_does_not_depend_on_the_water():
    """The flux entering the water is the same in clear and turbid water and at any depth (same
    bits: the surface and the light are the same)."""
    clear = wc.render(flat_water_scene(ELEVATION_DEG, 2.0, "none"), device="cpu")
    turbid = wc.render(flat_water_scene(ELEVATION_DEG, 9.0, "turbid_harbor"), device="cpu")
    np.testing.assert_array_equal(clear.transmitted_flux_w_nm, turbid.transmitted_flux_w_nm)


def test_transmitted_flux_with_dispersion_is_per_band():
    """With dispersion each band enters with its own Fresnel transmittance: E_sun cosθ T(θ, n(λ)) L²
    per band, for the flux ratio (per index group) as for photons."""
    theta = np.radians(90.0 - ELEVATION_DEG)
    for method in ("fluxratio", "photons"):
        result = wc.render(flat_water_scene(ELEVATION_DEG, DEPTH_M, "pure", **{
            "optics.dispersion": True, "caustics.method": method}), device="cpu")
        t = np.array([fresnel_t_angles(np.array([theta]), 1.0, n)[0] for n in result.ior])
        expected = result.sun_irradiance * np.cos(theta) * t * result.extent_m**2
        assert np.ptp(result.ior) > 1e-3  # the bands really differ
        np.testing.assert_allclose(result.transmitted_flux_w_nm, expected, rtol=2e-5, err_msg=method)
