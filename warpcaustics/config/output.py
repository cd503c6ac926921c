"""``[output]`` and ``[stats]``: what is written, and the irradiance statistics of run.json."""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

from warpcaustics.config.fields import _coordinate, _range


class Colourspace(str, enum.Enum):
    SRGB = "sRGB"
    ACESCG = "ACEScg"


class WhiteBalance(str, enum.Enum):
    D65 = "d65"
    SUN = "sun"


@dataclass(frozen=True)
class OutputConfig:
    spectral_exr: bool = True
    """Write the per-band floor irradiance into the EXR (``S0.<λ>nm`` channels) besides RGB."""
    colourspace: Colourspace = Colourspace.SRGB
    """Linear RGB of the EXR's R, G, B channels: ``sRGB`` or ``ACEScg`` (the PNG is always sRGB)."""
    white_balance: WhiteBalance = WhiteBalance.D65
    """``d65``: colours as a D65-adapted observer sees them; ``sun``: the sun's own spectrum is
    rendered neutral (von Kries / CAT02)."""
    exposure_ev: float = field(default=0.0, metadata=_range(-20.0, 20.0))
    """PNG exposure relative to the automatic one (mean luminance → 0.25) [stops]."""
    vtk: bool = False
    """Also write VTK files for ParaView / pyvista: ``surface_NNNN.vts`` (water surface, normals),
    ``floor_NNNN.vti`` (floor irradiance per band) and, with photons, ``receivers_NNNN.vtp``
    (receiver meshes with their irradiance per band)."""
    npz: bool = False
    """Also write ``frame_NNNN.npz``: the floor map (K, M, M), wavelengths, bin edges, x, y, time
    and the PAR map, as plain numpy arrays."""
    netcdf: bool = False
    """Also write ``frame_NNNN.nc`` through xarray (``pip install 'warpcaustics[science]'``):
    floor irradiance on coordinates time, wavelength, y, x with units as attributes, and PAR."""


@dataclass(frozen=True)
class ProbeConfig:
    x_m: float = field(default=0.0, metadata=_coordinate())
    """Where the probe sits on the floor, x [m]."""
    y_m: float = field(default=0.0, metadata=_coordinate())
    """Where it sits, y [m]."""


@dataclass(frozen=True)
class StatsConfig:
    collector_mm: float = field(default=0.0, metadata=_range(0.0, 1.0e5))
    """Diameter of the circular collector the statistics average over (a sensor's window) [mm];
    0 = the texels themselves."""
    flash_threshold: float = field(default=1.5, metadata=_range(1.0, 100.0, lo_open=True))
    """A flash is irradiance above this many times the mean [-]."""
    wavelength_nm: float | None = field(default=None, metadata=_range(100.0, 5000.0))
    """Also report the statistics of the band holding this wavelength (e.g. 510 nm) [nm]."""
    per_band: bool = False
    """Also report the statistics of every band, each after the collector (run.json's ``bands``;
    with a sky, each band's sky and direct-sun parts too, ``bands_sky`` and ``bands_direct``):
    spectral CVs, e.g. Darecki et al. (2011)'s 443/532/670 nm."""
    probes: tuple[ProbeConfig, ...] = ()
    """Floor points whose irradiance over an animation is reported (``[[stats.probes]]`` tables
    with x_m, y_m); none given: the floor map's centre."""
    integration_s: float = field(default=0.0, metadata=_range(0.0, 1.0e4))
    """A radiometer's integration time [s]: the probes' E(t) over an animation is also reported
    averaged over the last ``integration_s`` before each sample (``time_statistics.integrated``);
    0 = instantaneous samples only. Gernez & Antoine (2009) sampled at 6 Hz and did not publish it:
    compare 0 and 1/6 s."""
