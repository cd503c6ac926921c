"""Spectral bins → CIE 1931 2° XYZ → linear sRGB, through colour-science, and a tone map.

The colour matching functions are averaged over each bin (colour-science's 1 nm CIE 1931 table),
so ``XYZ = Σ_k E_k · cmf_k · Δλ_k`` is the bin-wise integral of the spectrum against the CMFs.
"""

from __future__ import annotations

import functools
import warnings

import numpy as np

from warpcaustics.spectra import SpectralBins


@functools.cache
def _colour():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import colour
    return colour


def bin_cmfs(bins: SpectralBins) -> np.ndarray:
    """(K, 3) CIE 1931 2° colour matching functions averaged over each bin."""
    cmfs = _colour().MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    wl = cmfs.wavelengths
    return np.stack([bins.average(wl, cmfs.values[:, i], what="CIE 1931 CMF") for i in range(3)], axis=1)


def spectral_to_xyz(spectral: np.ndarray, bins: SpectralBins) -> np.ndarray:
    """(K, H, W) spectral values per nm → (H, W, 3) CIE XYZ (same units × nm, unnormalised)."""
    weights = bin_cmfs(bins) * bins.widths_nm[:, None]
    return np.einsum("khw,kc->hwc", spectral, weights)


def xyz_to_linear_srgb(xyz: np.ndarray) -> np.ndarray:
    colour = _colour()
    return colour.XYZ_to_RGB(xyz, colour.RGB_COLOURSPACES["sRGB"], apply_cctf_encoding=False)


def tone_map_srgb8(linear_rgb: np.ndarray, luminance: np.ndarray) -> np.ndarray:
    """8-bit sRGB preview: mean luminance → 0.25, an exponential shoulder for caustic peaks."""
    mean = float(np.mean(luminance))
    scale = 0.25 / mean if mean > 0 else 1.0
    mapped = 1.0 - np.exp(-np.clip(linear_rgb * scale, 0.0, None) * 1.5)
    encoded = _colour().cctf_encoding(mapped, function="sRGB")
    return np.clip(np.round(encoded * 255.0), 0, 255).astype(np.uint8)
