"""``[optics]``: water optics (absorption, scattering, phase function, refractive index) and the
spectral sampling (``optics.wavelengths``)."""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

from warpcaustics.config.fields import _range


class WaterType(str, enum.Enum):
    NONE = "none"
    PURE = "pure"
    CLEAR_OCEAN = "clear_ocean"
    COASTAL_OCEAN = "coastal_ocean"
    TURBID_HARBOR = "turbid_harbor"
    JERLOV_I = "jerlov_I"
    JERLOV_IA = "jerlov_IA"
    JERLOV_IB = "jerlov_IB"
    JERLOV_II = "jerlov_II"
    JERLOV_III = "jerlov_III"
    JERLOV_1C = "jerlov_1C"
    JERLOV_3C = "jerlov_3C"
    JERLOV_5C = "jerlov_5C"
    JERLOV_7C = "jerlov_7C"
    JERLOV_9C = "jerlov_9C"
    BIO_OPTICAL = "bio_optical"


class Scattering(str, enum.Enum):
    SINGLE = "single"
    MULTIPLE = "multiple"
    SMALL_ANGLE = "small_angle"


class BeamSpread(str, enum.Enum):
    WELLS = "wells"
    WALK = "walk"


class PhaseFunctionKind(str, enum.Enum):
    HENYEY_GREENSTEIN = "henyey_greenstein"
    PETZOLD = "petzold"


class PetzoldStation(str, enum.Enum):
    AUTEC_7 = "AUTEC 7"
    AUTEC_8 = "AUTEC 8"
    AUTEC_9 = "AUTEC 9"
    HAOCE_5 = "HAOCE 5"
    HAOCE_11 = "HAOCE 11"
    NUC_2200 = "NUC 2200"
    NUC_2040 = "NUC 2040"
    NUC_2240 = "NUC 2240"


class JerlovSource(str, enum.Enum):
    AUTO = "auto"
    SOLONENKO2015 = "solonenko2015"
    WILLIAMSON2022 = "williamson2022"


@dataclass(frozen=True)
class WavelengthConfig:
    min_nm: float = field(default=400.0, metadata=_range(380.0, 780.0))
    """Lower edge of the first bin [nm]."""
    max_nm: float = field(default=700.0, metadata=_range(380.0, 780.0))
    """Upper edge of the last bin [nm]."""
    bins: int = field(default=16, metadata=_range(1, 400))
    """Number K of equal bins; values are bin averages per nm."""
    list_nm: tuple[float, ...] = field(default=(), metadata=_range(380.0, 780.0))
    """Listed wavelengths [nm], strictly increasing, sampled exactly (point values, not bin
    averages); for integrals each reaches half-way to its neighbours (the outer ones symmetric).
    Overrides min_nm/max_nm/bins. In TOML write ``optics.wavelengths = [450.0, 550.0, 650.0]``;
    ``optics.wavelengths = "rgb"`` means three equal bins over 400–700 nm."""


@dataclass(frozen=True)
class OpticsConfig:
    water_type: WaterType = WaterType.PURE
    """Water optics: ``pure`` (Pope & Fry 1997 absorption + Zhang 2009 scattering), the thesis
    types ``clear_ocean``, ``coastal_ocean``, ``turbid_harbor``, the Jerlov types ``jerlov_I`` …
    ``jerlov_9C`` (from the ``jerlov`` package), or ``none`` (c = 0, for validation)."""
    jerlov_source: JerlovSource = JerlovSource.AUTO
    """Which publication the ``jerlov`` package takes a and b of a Jerlov type from:
    ``williamson2022`` (measured; IB, II, III, 1C, 3C, 5C), ``solonenko2015`` (all ten types,
    inverted from Kd; no a for 3C at 675–700 nm and 5C at 600–700 nm) or ``auto`` (Williamson
    where it has the type, else Solonenko)."""
    ior: float = field(default=1.333, metadata=_range(1.0, 3.0, lo_open=True))
    """Refractive index of water, used for every wavelength when ``dispersion`` is off [-]."""
    chlorophyll_mg_m3: float = field(default=0.1, metadata=_range(0.0, 100.0))
    """Chlorophyll concentration of the ``bio_optical`` (case-1) water [mg m⁻³]."""
    cdom_440_per_m: float = field(default=0.0, metadata=_range(0.0, 20.0))
    """CDOM absorption at 440 nm of the ``bio_optical`` water [1/m]."""
    cdom_slope_per_nm: float = field(default=0.0176, metadata=_range(0.0, 0.1))
    """Exponential slope S of CDOM absorption, a(λ) = a(440) e^(−S(λ−440)) [1/nm] (default:
    ECOMAMA-MORS, shared/data bio_optical_model_parameters.csv)."""
    phase_function: PhaseFunctionKind = PhaseFunctionKind.HENYEY_GREENSTEIN
    """Phase function of in-water scattering (for the volume caustics of issues 5–6):
    ``henyey_greenstein`` or ``petzold`` (measured, from the ``jerlov`` package)."""
    hg_g: float | None = field(default=None, metadata=_range(-0.99, 0.99))
    """Mean cosine g of Henyey–Greenstein; default: that of ``petzold_station`` [-]."""
    petzold_station: PetzoldStation = PetzoldStation.HAOCE_11
    """Petzold (1972) station of the ``petzold`` phase function (and of the default g)."""
    dispersion: bool = False
    """Use n(λ) of seawater from Quan & Fry (1995) at each bin centre instead of ``ior``."""
    scattering: Scattering = Scattering.SINGLE
    """``single``: light scattered out of the direct beam is lost (c = a + b attenuates it);
    ``multiple``: a Monte Carlo random walk carries it on (a reference mode: ``fluxratio`` on a
    periodic sea; the single-scattering map is kept beside it); ``small_angle``: the
    single-scattering map plus its scattered light by the small-angle transfer of the water column
    (Wells 1973), scaled to the random walk's mean — the walk's amount of scattered light without
    its noise (same scenes as ``multiple``)."""
    beam_spread: BeamSpread = BeamSpread.WELLS
    """How ``small_angle`` spreads the scattered light (docs/physics.md): ``wells``, Wells (1973)'s
    closed-form small-angle transfer; ``walk``, the column's beam spread function measured by a
    random walk of a pencil beam in still water (every scattering's exact geometry, absorption
    along each photon's own path, light scattered sideways and back, Fresnel at the surface)."""
    beam_spread_photons: int = field(default=262144, metadata=_range(1024, 2**26))
    """Photons of each ``walk`` beam spread function (one per light direction, cached) [-]."""
    mc_samples: int = field(default=4, metadata=_range(1, 64))
    """Photons per surface cell side of the ``multiple`` random walk (s² per cell and band) [-]."""
    mc_max_events: int = field(default=64, metadata=_range(1, 10000))
    """Scattering events after which a ``multiple`` photon is stopped (its weight counted as
    truncated) [-]."""
    mc_seed: int = field(default=0, metadata=_range(0, 2**31 - 1))
    """Seed of the ``multiple`` random walk."""
    salinity_psu: float = field(default=35.0, metadata=_range(0.0, 45.0))
    """Salinity for n(λ) (Quan & Fry 1995; fitted for 0–35 ‰) [PSU ≈ ‰]."""
    temperature_c: float = field(default=20.0, metadata=_range(-2.0, 35.0))
    """Water temperature for n(λ) (Quan & Fry 1995; fitted for 0–30 °C) [°C]."""
    wavelengths: WavelengthConfig = field(default_factory=WavelengthConfig)
    """Spectral sampling."""
