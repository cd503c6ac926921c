"""OpenEXR: linear RGB plus, optionally, one channel per spectral band in Fichet, Pacanowski &
Wilkie's (2021) spectral layout."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from warpcaustics.io.files import atomic_path

EMISSIVE_UNITS = "W.m^-2.nm^-1"
RADIANCE_UNITS = "W.m^-2.sr^-1.nm^-1"


def spectral_channel_name(wavelength_nm: float) -> str:
    """Fichet, Pacanowski & Wilkie (2021) spectral EXR channel: ``S0.550,000000nm``."""
    return "S0." + f"{wavelength_nm:.6f}".replace(".", ",") + "nm"


def write_exr(path: Path, rgb: np.ndarray, spectral: np.ndarray | None, wavelengths_nm: np.ndarray,
              extra_header: dict[str, str], units: str = EMISSIVE_UNITS) -> None:
    import OpenEXR

    channels = {name: np.ascontiguousarray(rgb[..., i], dtype=np.float32) for i, name in enumerate("RGB")}
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    if spectral is not None:
        for k, wl in enumerate(wavelengths_nm):
            channels[spectral_channel_name(wl)] = np.ascontiguousarray(spectral[k], dtype=np.float32)
        header["spectralLayoutVersion"] = "1.0"
        header["emissiveUnits"] = units
    header.update(extra_header)
    with atomic_path(path) as tmp, OpenEXR.File(header, channels) as exr:
        exr.write(str(tmp))
