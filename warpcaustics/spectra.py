"""Spectral sampling, the sun's spectrum and the water's attenuation, as bin averages.

``optics.wavelengths = {min_nm, max_nm, bins}`` means K equal bins; ``wavelengths_nm`` are the bin
centres and every quantity is the average over its bin of the linear interpolant of its source
table. Sources (files under ``warpcaustics/data/``, provenance in its README):

- sun: ASTM G173-03 direct + circumsolar spectral irradiance [W m^-2 nm^-1] (SMARTS 2.9.2),
  on a plane perpendicular to the beam;
- ``pure`` water absorption: Pope & Fry (1997), Appl. Opt. 36, 8710 [1/m];
- ``pure`` water scattering: Zhang, Hu & He (2009), Opt. Express 17, 5698, seawater at 35 PSU and
  20 °C [1/m];
- ``none``: c = 0 (validation);
- refractive index n(λ) of seawater relative to air: Quan & Fry (1995), Appl. Opt. 34, 3477,
  ``n = n0 + (n1 + n2 T + n3 T²) S + n4 T² + (n5 + n6 S + n7 T)/λ + n8/λ² + n9/λ³`` (λ in nm,
  T in °C, S in ‰), coefficients from ``data/n_water_quan_fry_1995_coefficients.csv``.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from warpcaustics.config import OpticsConfig, WaterType
from warpcaustics.errors import ConfigError

DATA_DIR = Path(__file__).parent / "data"
_SAMPLES_PER_NM = 10  # integration points per nm for bin averages of linear interpolants


@functools.cache
def _table(name: str, column: str) -> tuple[np.ndarray, np.ndarray]:
    path = DATA_DIR / name
    header = path.read_text(encoding="utf-8").splitlines()[0].split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    return data[:, 0], data[:, header.index(column)]


def sun_table() -> tuple[np.ndarray, np.ndarray]:
    return _table("solar_astm_g173_03.csv", "E_direct_circumsolar_W_m2_nm")


def pure_absorption_table() -> tuple[np.ndarray, np.ndarray]:
    return _table("aw_pope_fry_1997.csv", "a_w_per_m")


def pure_scattering_table() -> tuple[np.ndarray, np.ndarray]:
    return _table("bw_zhang2009_and_morel1974_computed.csv", "b_sw_ZHH2009_T20_S35_per_m")


@dataclass(frozen=True)
class SpectralBins:
    """K equal wavelength bins."""

    edges_nm: np.ndarray
    """(K+1,) bin edges [nm]."""

    @classmethod
    def uniform(cls, min_nm: float, max_nm: float, bins: int) -> SpectralBins:
        return cls(np.linspace(min_nm, max_nm, bins + 1))

    @property
    def centres_nm(self) -> np.ndarray:
        return 0.5 * (self.edges_nm[1:] + self.edges_nm[:-1])

    @property
    def widths_nm(self) -> np.ndarray:
        return np.diff(self.edges_nm)

    def average(self, wavelength_nm: np.ndarray, values: np.ndarray, what: str) -> np.ndarray:
        """Average of the linear interpolant of a table over each bin."""
        lo, hi = self.edges_nm[0], self.edges_nm[-1]
        if lo < wavelength_nm[0] or hi > wavelength_nm[-1]:
            raise ConfigError(
                f"optics.wavelengths = {lo:g}..{hi:g} nm lies outside the {what} data "
                f"({wavelength_nm[0]:g}..{wavelength_nm[-1]:g} nm); narrow optics.wavelengths")
        out = np.empty(len(self.edges_nm) - 1)
        for k, (a, b) in enumerate(zip(self.edges_nm[:-1], self.edges_nm[1:])):
            n = max(2, int(np.ceil((b - a) * _SAMPLES_PER_NM)))
            x = a + (np.arange(n) + 0.5) * (b - a) / n  # midpoint rule on a fine grid
            out[k] = np.interp(x, wavelength_nm, values).mean()
        return out


@dataclass(frozen=True)
class WaterOptics:
    """Per-bin optical properties used by a render."""

    absorption_per_m: np.ndarray
    scattering_per_m: np.ndarray

    @property
    def attenuation_per_m(self) -> np.ndarray:
        """Beam attenuation c = a + b [1/m]: scattered light leaves the direct beam."""
        return self.absorption_per_m + self.scattering_per_m


def bins_for(optics: OpticsConfig) -> SpectralBins:
    w = optics.wavelengths
    return SpectralBins.uniform(w.min_nm, w.max_nm, w.bins)


def sun_irradiance(bins: SpectralBins) -> np.ndarray:
    """Direct + circumsolar solar irradiance per bin [W m^-2 nm^-1] (ASTM G173-03)."""
    return bins.average(*sun_table(), what="ASTM G173 solar")


def water_optics(water_type: WaterType, bins: SpectralBins) -> WaterOptics:
    """Absorption and scattering of the named water type, averaged over each bin."""
    if water_type is WaterType.NONE:
        zero = np.zeros(len(bins.centres_nm))
        return WaterOptics(zero, zero.copy())
    if water_type is WaterType.PURE:
        a = bins.average(*pure_absorption_table(), what="Pope & Fry 1997 absorption")
        b = bins.average(*pure_scattering_table(), what="Zhang 2009 scattering")
        return WaterOptics(a, b)
    raise ConfigError(f"optics.water_type = {water_type.value!r} has no optical data")  # pragma: no cover


@functools.cache
def _quan_fry_coefficients() -> dict[str, float]:
    rows = (DATA_DIR / "n_water_quan_fry_1995_coefficients.csv").read_text(encoding="utf-8").splitlines()[1:]
    return {name: float(value) for name, value in (row.split(",") for row in rows)}


def quan_fry_index(wavelength_nm: np.ndarray, salinity_psu: float, temperature_c: float) -> np.ndarray:
    """Refractive index of seawater relative to air, Quan & Fry (1995) [-]."""
    c = _quan_fry_coefficients()
    lam = np.asarray(wavelength_nm, dtype=np.float64)
    s, t = salinity_psu, temperature_c
    return (c["n0"] + (c["n1"] + c["n2"] * t + c["n3"] * t * t) * s + c["n4"] * t * t
            + (c["n5"] + c["n6"] * s + c["n7"] * t) / lam + c["n8"] / lam**2 + c["n9"] / lam**3)


def refractive_index(optics: OpticsConfig, bins: SpectralBins) -> np.ndarray:
    """(K,) refractive index per bin: Quan & Fry at the bin centres, or ``optics.ior`` throughout."""
    if optics.dispersion:
        return quan_fry_index(bins.centres_nm, optics.salinity_psu, optics.temperature_c)
    return np.full(len(bins.centres_nm), optics.ior)
