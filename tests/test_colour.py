"""The colour path: spectral bins → CIE 1931 XYZ → linear sRGB, against colour-science's own data."""

import numpy as np
import pytest

from warpcaustics.optics import colour as colour_out
from warpcaustics.optics.spectra import SpectralBins


@pytest.mark.parametrize("bin_nm", [1.0, 5.0])
def test_d65_is_srgb_white(bin_nm):
    """CIE D65 integrated over 1–5 nm bins maps to linear sRGB (1, 1, 1)·Y within 1e-3."""
    colour = colour_out.colour_science()
    d65 = colour.SDS_ILLUMINANTS["D65"]
    bins = SpectralBins.uniform(380.0, 780.0, int(400 / bin_nm))
    spectrum = bins.average(d65.wavelengths, d65.values, what="D65")
    xyz = colour_out.spectral_to_xyz(spectrum[:, None, None], bins)[0, 0]
    rgb = colour_out.xyz_to_linear_srgb(xyz)
    np.testing.assert_allclose(rgb / xyz[1], 1.0, atol=1e-3)


def test_equal_energy_spectrum_gives_illuminant_e():
    """A flat spectrum integrates to equal X, Y, Z (the CIE 1931 CMFs have equal areas)."""
    bins = SpectralBins.uniform(360.0, 830.0, 470)
    xyz = colour_out.spectral_to_xyz(np.ones((470, 1, 1)), bins)[0, 0]
    np.testing.assert_allclose(xyz / xyz[1], 1.0, atol=2e-3)  # the 1 nm table's areas agree to ~1e-3


def test_explicit_and_rgb_wavelengths():
    """optics.wavelengths as a list samples exactly those wavelengths (the thesis's a(550) comes out
    as published), with widths reaching half-way to the neighbours for integrals; "rgb" is three equal
    bins over 400–700 nm; D65 through them stays within 5 % of white (the price of three bins)."""
    import warpcaustics as wc
    from warpcaustics.optics import spectra

    scene = wc.load_scene(None, {"optics.wavelengths": [450.0, 550.0, 700.0],
                                 "optics.water_type": "clear_ocean"})
    bins = spectra.bins_for(scene.config.optics)
    np.testing.assert_allclose(bins.centres_nm, [450.0, 550.0, 700.0])
    np.testing.assert_allclose(bins.widths_nm, [100.0, 125.0, 150.0])
    optics = spectra.water_optics(scene.config.optics, bins)
    np.testing.assert_allclose(optics.absorption_per_m[:2], [0.0150, 0.0638], rtol=1e-12)
    np.testing.assert_allclose(optics.scattering_per_m[:2], [0.039, 0.035], rtol=1e-12)
    rgb = spectra.bins_for(wc.load_scene(None, {"optics.wavelengths": "rgb"}).config.optics)
    np.testing.assert_allclose(rgb.edges_nm, [400.0, 500.0, 600.0, 700.0])
    d65 = colour_out.colour_science().SDS_ILLUMINANTS["D65"]
    d65_bins = rgb.average(d65.wavelengths, d65.values, "D65")
    xyz = colour_out.spectral_to_xyz(d65_bins[:, None, None], rgb)[0, 0]
    np.testing.assert_allclose(colour_out.xyz_to_linear_srgb(xyz) / xyz[1], 1.0, atol=0.05)
    for bad, message in (([600.0, 500.0], "strictly increasing"), ([], "at least one"),
                         ([355.0, 365.0], "out of range")):
        with pytest.raises(wc.WarpcausticsError, match=message):
            wc.load_scene(None, {"optics.wavelengths": bad, "optics.water_type": "none"})


def test_acescg_white_and_sun_white_balance():
    """D65 maps to ACEScg (1, 1, 1)·Y through CAT02 (1e-3, 5 nm bins); with white balance to the sun
    the ASTM G173 sun itself comes out neutral in ACEScg (1e-6) and sRGB (1e-3: IEC 61966-2-1's
    XYZ→sRGB matrix is rounded to four decimals), and without it, not."""
    from warpcaustics.optics import spectra

    bins = spectra.SpectralBins.uniform(380.0, 780.0, 80)
    d65 = colour_out.colour_science().SDS_ILLUMINANTS["D65"]
    d65_bins = bins.average(d65.wavelengths, d65.values, "D65")
    xyz = colour_out.spectral_to_xyz(d65_bins[:, None, None], bins)[0, 0]
    np.testing.assert_allclose(colour_out.xyz_to_linear_rgb(xyz, "ACEScg") / xyz[1], 1.0, atol=1e-3)

    sun_bins = spectra.SpectralBins.uniform(400.0, 700.0, 60)
    sun = colour_out.spectral_to_xyz(spectra.sun_irradiance(sun_bins)[:, None, None], sun_bins)[0, 0]
    for space, tolerance in (("sRGB", 1e-3), ("ACEScg", 1e-6)):
        balanced = colour_out.xyz_to_linear_rgb(sun, space, white_xyz=sun)
        np.testing.assert_allclose(balanced / balanced.mean(), 1.0, atol=tolerance)
    unbalanced = colour_out.xyz_to_linear_rgb(sun, "sRGB")
    assert np.ptp(unbalanced / unbalanced.mean()) > 0.02  # the sun is not D65
