"""OpenEXR: linear RGB plus, optionally, one channel per spectral band in Fichet, Pacanowski &
Wilkie's (2021) spectral layout."""

from __future__ import annotations

import errno
from pathlib import Path

import numpy as np

from warpcaustics.io.files import atomic_path

EMISSIVE_UNITS = "W.m^-2.nm^-1"
RADIANCE_UNITS = "W.m^-2.sr^-1.nm^-1"


def spectral_channel_name(wavelength_nm: float) -> str:
    """Fichet, Pacanowski & Wilkie (2021) spectral EXR channel: ``S0.550,000000nm``."""
    return "S0." + f"{wavelength_nm:.6f}".replace(".", ",") + "nm"


def chromaticities(colourspace: str) -> tuple[float, ...]:
    """OpenEXR's ``chromaticities`` attribute of an RGB colour space: the x, y of its red, green and
    blue primaries and of its white, from colour-science's definition (sRGB: Rec. 709 primaries
    and D65; ACEScg: AP1 and the ACES white)."""
    from warpcaustics.optics.colour import colour_science

    space = colour_science().RGB_COLOURSPACES[colourspace]
    return tuple(float(v) for v in np.concatenate([np.ravel(space.primaries), np.ravel(space.whitepoint)]))


def write_exr(path: Path, rgb: np.ndarray, spectral: np.ndarray | None, wavelengths_nm: np.ndarray,
              extra_header: dict[str, str], units: str = EMISSIVE_UNITS, colourspace: str = "sRGB") -> None:
    """An EXR of linear ``rgb`` in ``colourspace`` (its ``chromaticities`` attribute set, so viewers
    read the primaries right) and, optionally, the ``spectral`` bands."""
    import OpenEXR

    channels = {name: np.ascontiguousarray(rgb[..., i], dtype=np.float32) for i, name in enumerate("RGB")}
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage,
              "chromaticities": chromaticities(colourspace)}
    if spectral is not None:
        for k, wl in enumerate(wavelengths_nm):
            channels[spectral_channel_name(wl)] = np.ascontiguousarray(spectral[k], dtype=np.float32)
        header["spectralLayoutVersion"] = "1.0"
        header["emissiveUnits"] = units
    header.update(extra_header)
    with atomic_path(path) as tmp, OpenEXR.File(header, channels) as exr:
        try:
            exr.write(str(tmp))
        except RuntimeError as exc:  # OpenEXR's: a full disk, a folder that cannot be written
            raise OSError(errno.EIO, " ".join(str(exc).split()), str(path)) from None
