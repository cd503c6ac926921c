"""Spectral bins → CIE 1931 2° XYZ → linear sRGB, through colour-science, and a tone map.

The colour matching functions are averaged over each bin (colour-science's 1 nm CIE 1931 table),
so ``XYZ = Σ_k E_k · cmf_k · Δλ_k`` is the bin-wise integral of the spectrum against the CMFs.
"""

from __future__ import annotations

import numpy as np

from warpcaustics.optics.spectra import SpectralBins, colour_science


def bin_cmfs(bins: SpectralBins) -> np.ndarray:
    """(K, 3) CIE 1931 2° colour matching functions averaged over each bin."""
    cmfs = colour_science().MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    wl = cmfs.wavelengths
    return np.stack([bins.average(wl, cmfs.values[:, i], what="CIE 1931 CMF") for i in range(3)], axis=1)


def spectral_to_xyz(spectral: np.ndarray, bins: SpectralBins) -> np.ndarray:
    """(K, H, W) spectral values per nm → (H, W, 3) CIE XYZ (same units × nm, unnormalised)."""
    weights = bin_cmfs(bins) * bins.widths_nm[:, None]
    return np.einsum("khw,kc->hwc", spectral, weights)


D65_XY = (0.3127, 0.3290)
"""CIE D65 chromaticity used when XYZ is converted into a colourspace with another white (CAT02)."""


def xyz_to_linear_srgb(xyz: np.ndarray) -> np.ndarray:
    colour = colour_science()
    return colour.XYZ_to_RGB(xyz, colour.RGB_COLOURSPACES["sRGB"], apply_cctf_encoding=False)


def xyz_to_linear_rgb(xyz: np.ndarray, colourspace: str, white_xyz: np.ndarray | None = None) -> np.ndarray:
    """XYZ → linear RGB of ``colourspace`` ("sRGB" or "ACEScg").

    ``white_xyz``: white balance — the XYZ of the light to render neutral (e.g. the sun's
    spectrum), adapted to D65 by the von Kries transform with CAT02; None keeps colours as a
    D65-adapted observer sees them. XYZ taken as D65-adapted is carried to ACEScg's white by CAT02.
    """
    colour = colour_science()
    if white_xyz is not None:
        d65 = colour.xy_to_XYZ(np.array(D65_XY)) * white_xyz[1]
        xyz = colour.chromatic_adaptation(xyz, white_xyz, d65, method="Von Kries", transform="CAT02")
    space = colour.RGB_COLOURSPACES[colourspace]
    return colour.XYZ_to_RGB(xyz, space, illuminant=np.array(D65_XY), chromatic_adaptation_transform="CAT02",
                             apply_cctf_encoding=False)


def tone_map_srgb8(linear_rgb: np.ndarray, luminance: np.ndarray, exposure_ev: float = 0.0) -> np.ndarray:
    """8-bit sRGB preview: mean luminance → 0.25·2^exposure_ev, then 1 − exp(−1.5x) as a shoulder
    for the caustic peaks, then the sRGB transfer function."""
    mean = float(np.mean(luminance))
    scale = (0.25 / mean if mean > 0 else 1.0) * 2.0**exposure_ev
    mapped = 1.0 - np.exp(-np.clip(linear_rgb * scale, 0.0, None) * 1.5)
    encoded = colour_science().cctf_encoding(mapped, function="sRGB")
    return np.clip(np.round(encoded * 255.0), 0, 255).astype(np.uint8)
