"""The colour path: spectral bins → CIE 1931 XYZ → linear sRGB, against colour-science's own data."""

import numpy as np
import pytest

from warpcaustics import colour_out
from warpcaustics.spectra import SpectralBins


@pytest.mark.parametrize("bin_nm", [1.0, 5.0])
def test_d65_is_srgb_white(bin_nm):
    """CIE D65 integrated over 1–5 nm bins maps to linear sRGB (1, 1, 1)·Y within 1e-3."""
    colour = colour_out._colour()
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
