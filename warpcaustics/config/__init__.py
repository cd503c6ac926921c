"""Scene configuration: TOML validated into frozen dataclasses, with dotted overrides.

Every section is a frozen dataclass; a field's docstring says what it is, with its unit in
brackets, and its ``metadata`` carries the allowed range. ``docs/config.md`` documents each key.
Validation errors are one line naming the key, the value, what is allowed and, for unknown keys,
the nearest valid key.
"""

from __future__ import annotations

import dataclasses
import datetime
import difflib
import enum
import math
import sys
import typing
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    import tomli as tomllib

from warpcaustics.errors import ConfigError


def _range(lo: float | None = None, hi: float | None = None, *, lo_open: bool = False) -> dict:
    return {"range": (lo, hi, lo_open)}


class WaterModel(str, enum.Enum):
    FLAT = "flat"
    HEIGHTFIELD = "heightfield"
    FFT = "fft"
    POOL = "pool"
    WAVEPOOL = "wavepool"
    PROCEDURAL = "procedural"


class WaterSpectrum(str, enum.Enum):
    PHILLIPS = "phillips"
    JONSWAP = "jonswap"


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


class SunSpectrum(str, enum.Enum):
    ASTM_G173 = "astm_g173"
    D65 = "d65"
    BLACKBODY = "blackbody"
    FILE = "file"


class Scattering(str, enum.Enum):
    SINGLE = "single"
    MULTIPLE = "multiple"


class SkyModel(str, enum.Enum):
    NONE = "none"
    UNIFORM = "uniform"


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


class CausticsMethod(str, enum.Enum):
    FLUXRATIO = "fluxratio"
    PHOTONS = "photons"
    BEAMS = "beams"
    BOTH = "both"
    SUNMAP = "sunmap"
    EIKONAL = "eikonal"
    WAVE3D = "wave3d"

    @property
    def uses_receivers(self) -> bool:
        """Photons and beams light every receiver (relief, walls, meshes) and feed the camera."""
        return self in (CausticsMethod.PHOTONS, CausticsMethod.BEAMS, CausticsMethod.BOTH)


class Intersection(str, enum.Enum):
    NEWTON = "newton"
    EXACT = "exact"


class FloorShape(str, enum.Enum):
    FLAT = "flat"
    SLOPE = "slope"
    RIPPLES = "ripples"
    FILE = "file"


class BeamInterpolation(str, enum.Enum):
    SMOOTH = "smooth"
    FLAT = "flat"


class DeviceChoice(str, enum.Enum):
    AUTO = "auto"
    CPU = "cpu"
    CUDA = "cuda"


# Values other issues will add, each with why it is not built yet ("" where that is not known): named
# so an error can say where they stand instead of "unknown".
PLANNED_VALUES = {
    "sky.model": {
        "cie_clear": "it needs the CIE standard-sky coefficients from a maintained source, which no "
        "colour-science release has yet",
    },
}


@dataclass(frozen=True)
class DropConfig:
    time_s: float = field(default=0.0, metadata=_range(0.0, None))
    """When the drop lands [s]."""
    x_m: float = 0.0
    """Where it lands, x [m] (the pool spans ±extent_m/2)."""
    y_m: float = 0.0
    """Where it lands, y [m]."""
    radius_m: float = field(default=0.1, metadata=_range(0.0, None, lo_open=True))
    """Gaussian radius (standard deviation) of the added water [m]."""
    height_m: float = field(default=0.05, metadata=_range(-10.0, 10.0))
    """Peak height of the added (or, if negative, removed) water [m]."""


@dataclass(frozen=True)
class BodyConfig:
    radius_m: float = field(default=0.0, metadata=_range(0.0, None))
    """Radius of a disc-shaped body moving through the ``pool`` [m]; 0 = no body."""
    center_x_m: float = 0.0
    """Centre of its circular path, x [m]."""
    center_y_m: float = 0.0
    """Centre of its circular path, y [m]."""
    path_radius_m: float = field(default=1.0, metadata=_range(0.0, None))
    """Radius of the circular path [m]."""
    period_s: float = field(default=4.0, metadata=_range(0.0, None, lo_open=True))
    """Time for one turn (counter-clockwise seen from above) [s]."""
    response_s: float = field(default=0.02, metadata=_range(0.0, None, lo_open=True))
    """Time over which the water under the body takes on its velocity [s]."""


@dataclass(frozen=True)
class WaterConfig:
    model: WaterModel = WaterModel.FFT
    """Surface model: ``flat``, ``heightfield`` (from ``water.file``), ``fft`` (Tessendorf), the walled
    ``pool`` (shallow water) and ``wavepool`` (wave equation), or ``procedural`` (GPU Gems octave
    waves, an open patch that does not tile)."""
    extent_m: float = field(default=16.0, metadata=_range(0.0, None, lo_open=True))
    """Side L of the square water patch centred at the origin [m]."""
    resolution: int | None = field(default=None, metadata=_range(4, 4096))
    """Vertices per side N (default 256; a heightfield takes N from its file) [-]."""
    file: str | None = None
    """``.npy`` 2-D float array of heights [m], ``h[iy, ix]``, at cell centres; relative paths
    are resolved against the config file's folder."""
    spectrum: WaterSpectrum = WaterSpectrum.PHILLIPS
    """Wave spectrum of the ``fft`` ocean: ``phillips`` (Tessendorf) or ``jonswap`` (fetch-limited)."""
    wind_speed_m_s: float = field(default=4.0, metadata=_range(0.0, 60.0, lo_open=True))
    """Wind speed at 10 m [m/s]."""
    wind_direction_deg: float = field(default=0.0, metadata=_range(-360.0, 360.0))
    """Direction the wind blows to, from +x towards +y [deg]."""
    phillips_amplitude: float = field(default=1.75e-3, metadata=_range(0.0, 1.0, lo_open=True))
    """Phillips constant A (dimensionless): height variance = A·π·(V²/g)²/2 over all k."""
    small_wave_m: float = field(default=0.0, metadata=_range(0.0, None))
    """Waves shorter than this are suppressed by exp(-k² l²) (Tessendorf eq. 41) [m]."""
    fetch_m: float = field(default=100_000.0, metadata=_range(0.0, 1.0e7, lo_open=True))
    """Distance over which the wind has blown (JONSWAP) [m]."""
    jonswap_gamma: float = field(default=3.3, metadata=_range(1.0, 10.0))
    """JONSWAP peak enhancement γ (1 = Pierson–Moskowitz shape) [-]."""
    spreading_s: float = field(default=10.0, metadata=_range(0.0, 1000.0))
    """Exponent s of the cos-2s directional spreading (JONSWAP); larger = narrower [-]."""
    choppiness: float = field(default=0.0, metadata=_range(0.0, 5.0))
    """Strength λ of the choppy horizontal displacement (Tessendorf eq. 29) [-]; 0 = none."""
    viscosity_m2_s: float = field(default=1.0e-4, metadata=_range(0.0, 1.0))
    """Kinematic (eddy) viscosity of the shallow-water ``pool`` [m²/s]."""
    cfl: float = field(default=0.4, metadata=_range(0.0, 0.7, lo_open=True))
    """Courant number of the pools' steps: dt = cfl·Δx / (|u| + √(g h)) [-]; the explicit gravity
    step is stable up to 1/√2 in 2-D, hence at most 0.7."""
    drops: tuple[DropConfig, ...] = ()
    """Drops falling into the ``pool`` or ``wavepool``: ``[[water.drops]]`` tables with time_s,
    x_m, y_m, radius_m, height_m."""
    body: BodyConfig = field(default_factory=BodyConfig)
    """A body moving through the ``pool`` on a circular path, pushing the water."""
    wave_speed_m_s: float = field(default=0.0, metadata=_range(0.0, 100.0))
    """Wave speed c of the ``wavepool`` [m/s]; 0 means the shallow-water speed √(g·floor.depth_m)."""
    damping_per_s: float = field(default=0.5, metadata=_range(0.0, 100.0))
    """Damping γ of the ``wavepool`` (η_tt = c²∇²η − γη_t): energy decays as e^(−γt) [1/s]."""
    seed: int = field(default=0, metadata=_range(0, 2**63 - 1))
    """Seed of the ocean's random phases and amplitudes."""
    procedural_amplitude: float = field(default=0.01, metadata=_range(0.0, 1.0))
    """A of the ``procedural`` waves (GPU Gems ch. 2's VTXSIZE): η = 2Aℓ·r·Σ −f cos(…) [-]."""
    procedural_frequency: float = field(default=10.0, metadata=_range(0.0, 1.0e4, lo_open=True))
    """W of the ``procedural`` waves (the chapter's WAVESIZE): phase W·x̂·ŷ/f in units of ℓ [-]."""
    procedural_factor: float = field(default=1.0, metadata=_range(0.0, 100.0, lo_open=True))
    """f_0 of the ``procedural`` waves (the chapter's FACTOR): the first octave's weight; each
    further octave halves it [-]."""
    procedural_speed_rad_s: float = field(default=2.0, metadata=_range(-1.0e3, 1.0e3))
    """S of the ``procedural`` waves (the chapter's SPEED): phase rate [rad/s]."""
    procedural_octaves: int = field(default=4, metadata=_range(1, 16))
    """Number of octaves of the ``procedural`` waves [-]."""
    procedural_scale_m: float = field(default=0.0, metadata=_range(0.0, None))
    """ℓ, one model unit of the chapter's shader in metres [m]; 0 = half of ``extent_m``."""

    @property
    def walled(self) -> bool:
        """The stateful pools have walls."""
        return self.model in (WaterModel.POOL, WaterModel.WAVEPOOL)

    @property
    def periodic(self) -> bool:
        """A tileable patch (flat, heightfield, fft); the pools and the procedural waves are not."""
        return not self.walled and self.model is not WaterModel.PROCEDURAL

    @property
    def stateful(self) -> bool:
        """Frame k steps on from frame k−1 (the pools); the other models are functions of time."""
        return self.walled


@dataclass(frozen=True)
class FloorConfig:
    depth_m: float = field(default=4.0, metadata=_range(0.0, None, lo_open=True))
    """Depth of the floor below the water at rest at the origin (floor at z = -depth_m + relief) [m]."""
    shape: FloorShape = FloorShape.FLAT
    """Relief of the floor: ``flat``, ``slope`` (a plane), ``ripples`` (sand ripples, a sine) or
    ``file`` (``floor.file``); anything but ``flat`` needs ``caustics.method = "photons"`` or ``"beams"``."""
    slope_deg: float = field(default=5.0, metadata=_range(0.0, 60.0))
    """Inclination of the ``slope`` [deg]."""
    slope_azimuth_deg: float = field(default=0.0, metadata=_range(-360.0, 360.0))
    """Direction in which the ``slope`` descends (gets deeper), from +x towards +y [deg]."""
    ripple_amplitude_m: float = field(default=0.03, metadata=_range(0.0, None))
    """Half the crest-to-trough height of the ``ripples`` [m]."""
    ripple_wavelength_m: float = field(default=0.5, metadata=_range(0.0, None, lo_open=True))
    """Crest-to-crest distance of the ``ripples`` [m]."""
    ripple_direction_deg: float = field(default=0.0, metadata=_range(-360.0, 360.0))
    """Direction across the ripple crests, from +x towards +y [deg]."""
    file: str | None = None
    """``.npy`` 2-D square float array of floor relief [m] (added to z = -depth_m), ``h[iy, ix]`` at
    cell centres over the water extent; relative paths start at the config file's folder."""
    albedo: tuple[float, ...] = field(default=(0.6, 0.55, 0.45), metadata=_range(0.0, 1.0))
    """Diffuse albedo of the floor: one value (grey) or three (linear sRGB, turned into a
    reflectance spectrum by Mallett & Yuksel 2019 through colour-science) [-]."""
    albedo_file: str | None = None
    """CSV of a measured reflectance spectrum (header line, then wavelength [nm], reflectance 0…1);
    replaces ``albedo``. Relative paths start at the config file's folder."""


@dataclass(frozen=True)
class SunConfig:
    elevation_deg: float = field(default=60.0, metadata=_range(0.0, 90.0, lo_open=True))
    """Angle of the sun above the horizon [deg]."""
    azimuth_deg: float = field(default=0.0, metadata=_range(-360.0, 360.0))
    """Direction towards the sun, from +x towards +y [deg]."""
    angular_diameter_deg: float = field(default=0.53, metadata=_range(0.0, 5.0))
    """Angular diameter of the sun's disk [deg]: 0 = a point; 0.53 = the real sun, integrated over
    ``disk_samples`` directions (every method but ``sunmap``, which draws its own)."""
    disk_samples: int = field(default=16, metadata=_range(2, 1024))
    """Directions over the sun's disk (equal solid angles: a sunflower pattern and its mirror
    image; an odd number is rounded down to even) [-]."""
    spectrum: SunSpectrum = SunSpectrum.ASTM_G173
    """Shape of the sun's spectrum: ``astm_g173`` (direct + circumsolar, absolute), ``d65``,
    ``blackbody`` (at ``temperature_k``) or ``file`` (``sun.file``)."""
    temperature_k: float = field(default=5778.0, metadata=_range(1000.0, 100000.0))
    """Temperature of the ``blackbody`` spectrum [K]."""
    file: str | None = None
    """CSV of the ``file`` spectrum: a header line, then wavelength [nm], spectral irradiance
    (any scale); relative paths start at the config file's folder."""
    datetime: str | None = None
    """Date and time with UTC offset (ISO 8601, e.g. ``2009-07-14T11:30:00+02:00``): with
    ``latitude_deg`` and ``longitude_deg`` it sets elevation and azimuth (pvlib's SPA; the
    ``science`` extra). Give either this or ``elevation_deg``/``azimuth_deg``."""
    latitude_deg: float | None = field(default=None, metadata=_range(-90.0, 90.0))
    """Latitude of the site, north positive [deg]."""
    longitude_deg: float | None = field(default=None, metadata=_range(-180.0, 180.0))
    """Longitude of the site, east positive [deg]."""
    irradiance_w_m2: float = field(default=0.0, metadata=_range(0.0, 1.0e5))
    """Sun irradiance on a plane perpendicular to the beam, integrated over the render's
    wavelengths [W/m²]; 0 = that of ASTM G173 direct + circumsolar over the same range."""


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
    periodic sea; the single-scattering map is kept beside it)."""
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


@dataclass(frozen=True)
class CausticsConfig:
    method: CausticsMethod = CausticsMethod.FLUXRATIO
    """Caustics method: ``fluxratio`` (refracted triangle footprints on a flat floor),
    ``photons`` (photon splatting onto every receiver, Shah et al. 2007) or ``beams`` (warped beam
    volumes through a tile-binned rasteriser onto every receiver, with volume caustics in the
    camera; Ernst et al. 2005, Liktor & Dachsbacher 2011) or ``both`` (beams and photons on the same
    frame, both saved with the difference of their floor maps) or ``sunmap`` (GPU Gems ch. 2:
    backward rays from the floor looked up in a soft sun map, scaled to the flux-ratio map's mean,
    which is saved beside it) or ``eikonal`` (after Mercier 2013: the refracted front's travel
    time on a 3-D grid, its Laplacian carried along the rays to the floor) or ``wave3d`` (after
    Mercier 2013 §4: the 3-D wave equation driven by the refracted wave, its time-averaged
    intensity on the floor); those two also save the flux-ratio map beside theirs."""
    map_resolution: int = field(default=512, metadata=_range(1, 16384))
    """Texels M per side of the floor irradiance map over the water extent (or the window) [-]."""
    map_extent_m: float = field(default=0.0, metadata=_range(0.0, None))
    """Side of a square floor-map window [m] (``fluxratio``): millimetre texels over a small part
    of a large sea; 0 = the whole water extent."""
    map_center_m: tuple[float, ...] = (0.0, 0.0)
    """Centre (x, y) of the floor-map window [m]."""
    intersection: Intersection = Intersection.EXACT
    """How a ``photons`` photon finds its receiver: ``exact`` (ray query on the receivers' BVH) or
    ``newton`` (Shah's iteration on a receiver-position buffer rendered from the light, along the
    sun's refracted direction under still water)."""
    photon_subdivisions: int = field(default=4, metadata=_range(1, 64))
    """s: photons per surface cell are s×s [-]."""
    newton_iterations: int = field(default=3, metadata=_range(0, 64))
    """Iterations k of the ``newton`` intersection [-]."""
    newton_buffer_resolution: int = field(default=1024, metadata=_range(16, 16384))
    """Texels per side of the ``newton`` receiver-position buffer seen from the light [-]."""
    beam_interpolation: BeamInterpolation = BeamInterpolation.FLAT
    """How ``beams`` spread a beam's light over its section: ``flat`` (each beam's own flux over its
    own section, as the flux-ratio map; triangle facets can show in close-ups) or ``smooth`` (after
    Ernst et al. 2005: per-vertex wave-front densities of the surrounding beams interpolated across
    each beam, continuous from beam to beam but blurred over about two surface cells)."""
    beam_levels: int = field(default=0, metadata=_range(0, 4))
    """Adaptive beams (Liktor & Dachsbacher 2011 §4.2): start from quads of 2^beam_levels surface
    cells and split where needed down to single cells; 0 = one beam pair per cell (uniform) [-]."""
    beam_tolerance: float = field(default=0.25, metadata=_range(0.0, None))
    """Split an adaptive quad where a vertex's refracted ray, followed to its receiver, misses the
    quad's interpolated ray by more than this many surface cells [-]."""
    shafts: bool = True
    """Add light shafts (single scattering in the water: along each photon's path, or through each
    beam by scan planes) to the camera image."""
    eikonal_resolution: int = field(default=128, metadata=_range(8, 1024))
    """Nodes N per side of the ``eikonal`` grid over the water extent; the spacing L/N is also the
    layer spacing in depth [-]."""
    wave3d_resolution: int = field(default=64, metadata=_range(8, 1024))
    """Nodes N per side of the ``wave3d`` grid over the water extent (also its layer spacing) [-]."""
    wave3d_cells_per_wavelength: float = field(default=8.0, metadata=_range(4.0, 1000.0))
    """The ``wave3d`` wave's wavelength λ in the water, in grid spacings: far longer than light's,
    so diffraction blurs the caustics over about √(λ·depth); at most a sixth of the patch [-]."""
    wave3d_periods: float = field(default=4.0, metadata=_range(0.5, 1000.0))
    """Periods of the drive over which u² is averaged into the ``wave3d`` intensity [-]."""
    wave3d_gain: float = field(default=1.0, metadata=_range(0.0, None, lo_open=True))
    """a of Mercier's post-process a·I^b of the ``wave3d`` intensity (1, 1: the intensity) [-]."""
    wave3d_exponent: float = field(default=1.0, metadata=_range(0.0, 10.0, lo_open=True))
    """b of Mercier's post-process a·I^b [-]."""
    sunmap_disk_deg: float = field(default=0.53, metadata=_range(0.0, 90.0))
    """Angular diameter of the sun's disk in the ``sunmap`` (full brightness inside) [deg]."""
    sunmap_halo_deg: float = field(default=5.3, metadata=_range(0.0, 180.0, lo_open=True))
    """Angular diameter of the halo where the ``sunmap`` brightness falls to 0 (GPU Gems ch. 2: an
    arc about 10 times the disk's) [deg]."""


@dataclass(frozen=True)
class ReceiverConfig:
    mesh: str = "sphere"
    """A triangle mesh: ``sphere``, ``cube``, ``cylinder`` or ``cone`` (pyvista's unit-size
    primitives) or a file (OBJ, PLY, STL, VTK, VTP; relative to the config file's folder)."""
    scale: tuple[float, ...] = field(default=(1.0,), metadata=_range(0.0, None, lo_open=True))
    """Scale factor: one value or (sx, sy, sz) [-]; applied first."""
    rotate_deg: tuple[float, ...] = field(default=(0.0, 0.0, 0.0), metadata=_range(-360.0, 360.0))
    """Rotations about x, then y, then z [deg]; applied after scaling."""
    translate_m: tuple[float, ...] = (0.0, 0.0, -2.0)
    """Translation (x, y, z) [m]; applied last."""
    albedo: tuple[float, ...] = field(default=(0.7, 0.7, 0.7), metadata=_range(0.0, 1.0))
    """Diffuse albedo: one value (grey) or three (linear sRGB, as for the floor) [-]."""
    albedo_file: str | None = None
    """CSV of a reflectance spectrum (as ``floor.albedo_file``); replaces ``albedo``."""


@dataclass(frozen=True)
class CameraConfig:
    enabled: bool = False
    """Render a camera image (needs ``caustics.method = "photons"`` or ``"beams"``); the camera is
    under water."""
    position_m: tuple[float, ...] = (0.0, -6.0, -1.0)
    """Pinhole position (x, y, z) [m]; must be below the water surface."""
    look_at_m: tuple[float, ...] = (0.0, 0.0, -3.0)
    """Point the camera looks at (x, y, z) [m]."""
    up: tuple[float, ...] = (0.0, 0.0, 1.0)
    """Up direction of the image (x, y, z) [-]."""
    fov_deg: float = field(default=60.0, metadata=_range(1.0, 170.0))
    """Vertical field of view [deg]."""
    width: int = field(default=320, metadata=_range(8, 8192))
    """Image width [pixels]."""
    height: int = field(default=240, metadata=_range(8, 8192))
    """Image height [pixels]."""


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
class SkyConfig:
    model: SkyModel = SkyModel.NONE
    """Skylight: ``none`` or ``uniform`` (the same radiance from every direction of the sky; every
    method but ``sunmap``). ``cie_clear`` is planned: it waits for a sourced table of the CIE
    standard skies (colour-science's ``sky_luminance_distribution_CIE2003`` is in no release
    yet)."""
    diffuse_fraction: float = field(default=0.0, metadata=_range(0.0, 0.99))
    """Share of the global horizontal irradiance that comes from the sky; the sun's direct beam
    (``sun.*``) is the rest [-]."""
    directions: int = field(default=64, metadata=_range(1, 4096))
    """Directions the sky is integrated over (cosine-weighted, stratified) [-]."""


@dataclass(frozen=True)
class ProbeConfig:
    x_m: float = 0.0
    """Where the probe sits on the floor, x [m]."""
    y_m: float = 0.0
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
    probes: tuple[ProbeConfig, ...] = ()
    """Floor points whose irradiance over an animation is reported (``[[stats.probes]]`` tables
    with x_m, y_m); none given: the floor map's centre."""


@dataclass(frozen=True)
class Config:
    water: WaterConfig = field(default_factory=WaterConfig)
    """The water surface."""
    floor: FloorConfig = field(default_factory=FloorConfig)
    """The receiving floor."""
    sun: SunConfig = field(default_factory=SunConfig)
    """The sun."""
    optics: OpticsConfig = field(default_factory=OpticsConfig)
    """Water optics and spectral sampling."""
    caustics: CausticsConfig = field(default_factory=CausticsConfig)
    """Caustics method and map."""
    receivers: tuple[ReceiverConfig, ...] = ()
    """Meshes under the water that receive caustics: ``[[receivers]]`` tables (``photons`` only)."""
    camera: CameraConfig = field(default_factory=CameraConfig)
    """A pinhole camera under the water (``photons`` only)."""
    output: OutputConfig = field(default_factory=OutputConfig)
    """What is written."""
    stats: StatsConfig = field(default_factory=StatsConfig)
    """Irradiance statistics reported in run.json."""
    sky: SkyConfig = field(default_factory=SkyConfig)
    """Skylight."""
    device: DeviceChoice = DeviceChoice.AUTO
    """``auto`` (CUDA when available, else CPU), ``cpu`` or ``cuda``."""

    @property
    def map_window(self) -> tuple[float, tuple[float, float]]:
        """(side [m], centre (x, y) [m]) of the floor map: ``caustics.map_extent_m``'s window, or the
        whole water patch about the origin."""
        c = self.caustics
        if c.map_extent_m:
            return c.map_extent_m, (float(c.map_center_m[0]), float(c.map_center_m[1]))
        return self.water.extent_m, (0.0, 0.0)


# ---------------------------------------------------------------------------------------------
# Validation


def _hints(cls: type) -> dict[str, Any]:
    return typing.get_type_hints(cls)


def _is_section(tp: Any) -> bool:
    return dataclasses.is_dataclass(tp)


def all_keys(cls: type = Config, prefix: str = "") -> list[str]:
    """Every dotted key of the configuration tree (leaves only)."""
    keys = []
    for name, tp in _hints(cls).items():
        if _tuple_item(tp) is not None:
            keys += [f"{prefix}{name}[].{k}" for k in all_keys(_tuple_item(tp))]
        elif _is_section(tp):
            keys += all_keys(tp, f"{prefix}{name}.")
        else:
            keys.append(f"{prefix}{name}")
    return keys


def _tuple_item(tp: Any) -> type | None:
    """The dataclass D of a ``tuple[D, ...]`` annotation (a TOML array of tables), else None."""
    if typing.get_origin(tp) is tuple:
        args = typing.get_args(tp)
        if len(args) == 2 and args[1] is Ellipsis and dataclasses.is_dataclass(args[0]):
            return args[0]
    return None


def _nearest(key: str) -> str:
    keys = all_keys() + [k.rsplit(".", 1)[0] for k in all_keys() if "." in k]
    match = difflib.get_close_matches(key, keys, n=1, cutoff=0.0)
    return match[0] if match else ""


def _describe(value: Any) -> str:
    return repr(value) if isinstance(value, str) else str(value).lower() if isinstance(value, bool) \
        else str(value)


def _convert(key: str, value: Any, tp: Any, meta: dict) -> Any:
    """Check one leaf value against its annotated type and range; return the typed value."""
    origin = typing.get_origin(tp)
    args = typing.get_args(tp)
    if origin in (typing.Union, getattr(__import__("types"), "UnionType", None)) and type(None) in args:
        if value is None:
            return None
        tp = next(a for a in args if a is not type(None))
    if isinstance(tp, type) and issubclass(tp, enum.Enum):
        allowed = [m.value for m in tp]
        if isinstance(value, str) and value in allowed:
            return tp(value)
        planned = PLANNED_VALUES.get(key, {})
        if value in planned:
            why = planned[value]
            raise ConfigError(f"{key} = {_describe(value)} is not implemented yet"
                              + (f" ({why})" if why else "") + f"; allowed now: {', '.join(allowed)}")
        raise ConfigError(f"{key} = {_describe(value)} is not allowed; allowed: {', '.join(allowed)}")
    if typing.get_origin(tp) is tuple and typing.get_args(tp) == (float, Ellipsis):
        if isinstance(value, (int, float)) and not isinstance(value, bool):
            value = [value]  # one number stands for a one-value list (a grey albedo, a uniform scale)
        if not isinstance(value, (list, tuple)) or not all(
                isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
            raise ConfigError(f"{key} = {_describe(value)} must be a list of numbers")
        return tuple(_convert(key, v, float, meta) for v in value)
    if tp is bool:
        if isinstance(value, bool):
            return value
        raise ConfigError(f"{key} = {_describe(value)} has the wrong type; expected true or false")
    if tp is int:
        if isinstance(value, bool) or not isinstance(value, int):
            raise ConfigError(f"{key} = {_describe(value)} has the wrong type; expected an integer")
    elif tp is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise ConfigError(f"{key} = {_describe(value)} has the wrong type; expected a number")
        value = float(value)
        if not math.isfinite(value):
            raise ConfigError(f"{key} = {value} is not finite; expected a finite number")
    elif tp is str:
        if not isinstance(value, str):
            raise ConfigError(f"{key} = {_describe(value)} has the wrong type; expected a string")
        return value
    lo, hi, lo_open = meta.get("range", (None, None, False))
    if lo is not None and (value < lo or (lo_open and value == lo)):
        raise ConfigError(f"{key} = {value} is out of range; allowed: {_range_text(lo, hi, lo_open)}")
    if hi is not None and value > hi:
        raise ConfigError(f"{key} = {value} is out of range; allowed: {_range_text(lo, hi, lo_open)}")
    return value


def _range_text(lo, hi, lo_open) -> str:
    left = "" if lo is None else f"{lo} {'<' if lo_open else '<='} "
    right = "" if hi is None else f" <= {hi}"
    return f"{left}value{right}"


def _build(cls: type, table: dict, prefix: str) -> Any:
    fields = {f.name: f for f in dataclasses.fields(cls)}
    hints = _hints(cls)
    kwargs = {}
    for name, value in table.items():
        key = f"{prefix}{name}"
        if name not in fields:
            raise ConfigError(f"unknown key '{key}' = {_describe(value)}; nearest valid key: "
                              f"'{_nearest(key)}' (see docs/config.md)")
        tp = hints[name]
        item = _tuple_item(tp)
        if item is not None:
            if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
                raise ConfigError(f"{key} must be a list of tables, e.g. {key} = [{{ ... }}] or "
                                  f"[[{key}]] sections")
            kwargs[name] = tuple(_build(item, v, f"{key}[{i}].") for i, v in enumerate(value))
        elif _is_section(tp):
            if not isinstance(value, dict):
                raise ConfigError(f"{key} = {_describe(value)} must be a table ([{key}] or "
                                  f"{key}.<name> = ...)")
            kwargs[name] = _build(tp, value, f"{key}.")
        else:
            kwargs[name] = _convert(key, value, tp, dict(fields[name].metadata))
    return cls(**kwargs)


def _check_consistency(cfg: Config) -> None:
    w = cfg.optics.wavelengths
    if any(b <= a for a, b in zip(w.list_nm, w.list_nm[1:])):
        raise ConfigError(f"optics.wavelengths = {list(w.list_nm)} must be strictly increasing")
    if w.max_nm <= w.min_nm:
        raise ConfigError(f"optics.wavelengths.max_nm = {w.max_nm} must exceed "
                          f"optics.wavelengths.min_nm = {w.min_nm}")
    if cfg.water.model is WaterModel.HEIGHTFIELD and not cfg.water.file:
        raise ConfigError("water.file is missing; water.model = 'heightfield' needs a .npy file of "
                          "heights (set water.file = \"path.npy\")")
    if cfg.water.model is not WaterModel.HEIGHTFIELD and cfg.water.file:
        raise ConfigError(f"water.file = {cfg.water.file!r} is only read by water.model = "
                          f"'heightfield' (model is {cfg.water.model.value!r}); remove it or change the "
                          "model")
    if cfg.sun.spectrum is SunSpectrum.FILE and not cfg.sun.file:
        raise ConfigError("sun.file is missing; sun.spectrum = 'file' needs a CSV of wavelength [nm], "
                          "irradiance (set sun.file = \"sun.csv\")")
    _check_photon_scene(cfg)
    n = cfg.water.resolution
    if cfg.water.model is WaterModel.FFT and n is not None and (n & (n - 1)):
        raise ConfigError(f"water.resolution = {n} must be a power of two for water.model = 'fft' "
                          f"(e.g. {1 << max(2, round(math.log2(n)))})")


def _check_vector(key: str, value: tuple[float, ...], lengths: tuple[int, ...]) -> None:
    if len(value) not in lengths:
        raise ConfigError(f"{key} = {list(value)} must have {' or '.join(map(str, lengths))} values")


def _check_periodic_floor(cfg: Config) -> None:
    """Under a periodic sea the floor must tile the patch too: the photons of the neighbouring
    tiles are folded into the patch, which is only right if the floor repeats with it."""
    if not cfg.water.periodic:
        return
    floor = cfg.floor
    if floor.shape is FloorShape.SLOPE:
        raise ConfigError(f"floor.shape = 'slope' does not repeat, but water.model = "
                          f"{cfg.water.model.value!r} is a periodic patch: use a water model that does not "
                          "tile (water.model = \"pool\", \"wavepool\" or \"procedural\") or a floor that "
                          "tiles (ripples, file)")
    if floor.shape is FloorShape.RIPPLES:
        a = math.radians(floor.ripple_direction_deg)
        m = math.cos(a) * cfg.water.extent_m / floor.ripple_wavelength_m
        n = math.sin(a) * cfg.water.extent_m / floor.ripple_wavelength_m
        mi, ni = round(m), round(n)
        if max(abs(m - mi), abs(n - ni)) > 1e-4:
            if mi == 0 and ni == 0:
                mi = 1
            wavelength = cfg.water.extent_m / math.hypot(mi, ni)
            direction = math.degrees(math.atan2(ni, mi))
            raise ConfigError(
                f"floor ripples (wavelength {floor.ripple_wavelength_m:g} m, direction "
                f"{floor.ripple_direction_deg:g}°) do not tile the periodic {cfg.water.extent_m:g} m patch; "
                f"the nearest that do: floor.ripple_wavelength_m = {wavelength:.12g}, "
                f"floor.ripple_direction_deg = {direction:.12g}")


GREY_METHODS = (CausticsMethod.SUNMAP, CausticsMethod.EIKONAL, CausticsMethod.WAVE3D)
"""Methods that trace one refractive index for all bands."""


def _check_map_window(cfg: Config) -> None:
    c = cfg.caustics
    _check_vector("caustics.map_center_m", c.map_center_m, (2,))
    if not c.map_extent_m:
        if any(c.map_center_m):
            raise ConfigError(f"caustics.map_center_m = {list(c.map_center_m)} places a window, but "
                              "caustics.map_extent_m is 0 (the whole patch); set caustics.map_extent_m")
        return
    if c.method is not CausticsMethod.FLUXRATIO:
        raise ConfigError(f"caustics.map_extent_m = {c.map_extent_m:g} (a floor-map window) works with "
                          f"caustics.method = \"fluxratio\" only (the method is {c.method.value!r}); set "
                          "caustics.map_extent_m = 0")
    half = 0.5 * cfg.water.extent_m
    if c.map_extent_m > cfg.water.extent_m:
        raise ConfigError(f"caustics.map_extent_m = {c.map_extent_m:g} exceeds water.extent_m = "
                          f"{cfg.water.extent_m:g}; a window is part of the patch")
    x, y = c.map_center_m
    if cfg.water.periodic and 0.5 * cfg.water.extent_m < c.map_extent_m < cfg.water.extent_m:
        raise ConfigError(f"caustics.map_extent_m = {c.map_extent_m:g} is more than half the periodic "
                          f"{cfg.water.extent_m:g} m patch (a footprint could reach it from two periods); "
                          f"use at most {0.5 * cfg.water.extent_m:g} or the whole {cfg.water.extent_m:g}")
    if not cfg.water.periodic and max(abs(x), abs(y)) + 0.5 * c.map_extent_m > half:
        raise ConfigError(f"the floor-map window (caustics.map_center_m = {list(c.map_center_m)}, "
                          f"caustics.map_extent_m = {c.map_extent_m:g}) reaches past the "
                          f"{cfg.water.model.value!r} patch (|x|, |y| <= {half:g} m); move or shrink it")


def _check_sky(cfg: Config) -> None:
    sky = cfg.sky
    if sky.model is SkyModel.NONE:
        if sky.diffuse_fraction:
            raise ConfigError(f"sky.diffuse_fraction = {sky.diffuse_fraction:g} needs a sky; set "
                              "sky.model = \"uniform\" (or sky.diffuse_fraction = 0)")
        return
    method = cfg.caustics.method
    if method is CausticsMethod.SUNMAP:
        raise ConfigError("sky.model with caustics.method = \"sunmap\": the sun map looks up the sun alone "
                          "(its halo stands in for the sky); set sky.model = \"none\"")
    if method in (CausticsMethod.PHOTONS, CausticsMethod.BOTH) and (
            cfg.caustics.intersection is Intersection.NEWTON):
        raise ConfigError("sky.model with caustics.intersection = \"newton\": the Newton guesses come from "
                          "the sun's light view, not the sky's; set caustics.intersection = \"exact\"")
    if sky.diffuse_fraction <= 0.0:
        raise ConfigError(f"sky.model = {sky.model.value!r} with sky.diffuse_fraction = 0 has no light; set "
                          "sky.diffuse_fraction (e.g. 0.15) or sky.model = \"none\"")


def _check_scattering(cfg: Config) -> None:
    if cfg.optics.scattering is not Scattering.MULTIPLE:
        return
    needs = []
    if cfg.caustics.method is not CausticsMethod.FLUXRATIO:
        needs.append(f"caustics.method = \"fluxratio\" (not {cfg.caustics.method.value!r})")
    if not cfg.water.periodic:
        needs.append(f"a periodic sea (not water.model = {cfg.water.model.value!r})")
    if cfg.optics.dispersion:
        needs.append("optics.dispersion = false")
    if needs:
        raise ConfigError("optics.scattering = \"multiple\" (a reference random walk) needs "
                          + "; ".join(needs))


def _check_sun_disk(cfg: Config) -> None:
    disk, drawn = cfg.sun.angular_diameter_deg, cfg.caustics.sunmap_disk_deg
    if cfg.caustics.method is CausticsMethod.SUNMAP and disk > 0.0 and abs(disk - drawn) > 1e-9:
        raise ConfigError(f"sun.angular_diameter_deg = {disk:g} but the sun map draws a disk of "
                          f"caustics.sunmap_disk_deg = {drawn:g}; set them equal (or the sun to 0)")


def _check_stats(cfg: Config) -> None:
    side, (cx, cy) = cfg.map_window
    half = 0.5 * side
    for i, p in enumerate(cfg.stats.probes):
        if abs(p.x_m - cx) > half or abs(p.y_m - cy) > half:
            raise ConfigError(f"stats.probes[{i}] = ({p.x_m:g}, {p.y_m:g}) m is off the floor map "
                              f"({side:g} m wide around ({cx:g}, {cy:g}) m); move it onto the map")
    wl = cfg.stats.wavelength_nm
    w = cfg.optics.wavelengths
    lo, hi = (w.list_nm[0], w.list_nm[-1]) if w.list_nm else (w.min_nm, w.max_nm)
    if wl is not None and not lo <= wl <= hi:
        raise ConfigError(f"stats.wavelength_nm = {wl:g} is outside the spectral bins ({lo:g}–{hi:g} nm); "
                          "pick a wavelength inside optics.wavelengths")
    if cfg.stats.collector_mm * 1e-3 > side:
        raise ConfigError(f"stats.collector_mm = {cfg.stats.collector_mm:g} is wider than the "
                          f"{side:g} m floor map; use a smaller collector")
    if cfg.output.netcdf:
        try:
            import xarray  # noqa: F401
        except ImportError:
            raise ConfigError("output.netcdf = true needs xarray: pip install 'warpcaustics[science]' "
                              "(or set output.netcdf = false)") from None


def _check_sunmap(cfg: Config) -> None:
    """The approximate methods' own settings."""
    c = cfg.caustics
    if c.method in GREY_METHODS and cfg.optics.dispersion:
        raise ConfigError(f"optics.dispersion = true needs a method that refracts each band: "
                          f"caustics.method = {c.method.value!r} traces one index for all bands; set "
                          "optics.dispersion = false or caustics.method = \"fluxratio\", \"beams\" or "
                          "\"photons\"")
    if c.method is CausticsMethod.WAVE3D and c.wave3d_cells_per_wavelength > c.wave3d_resolution / 6:
        raise ConfigError(f"caustics.wave3d_cells_per_wavelength = {c.wave3d_cells_per_wavelength:g} makes "
                          f"the wave longer than a sixth of the patch at caustics.wave3d_resolution = "
                          f"{c.wave3d_resolution} (its direction could not be kept); use at most "
                          f"{c.wave3d_resolution / 6:g} or raise caustics.wave3d_resolution")
    if c.sunmap_halo_deg <= c.sunmap_disk_deg:
        raise ConfigError(f"caustics.sunmap_halo_deg = {c.sunmap_halo_deg:g} must exceed "
                          f"caustics.sunmap_disk_deg = {c.sunmap_disk_deg:g} (the halo surrounds the disk)")


def _check_beam_levels(cfg: Config) -> None:
    """Adaptive beams refine quads of 2^levels cells of a periodic sea."""
    levels = cfg.caustics.beam_levels
    if not levels:
        return
    if not cfg.water.periodic:
        raise ConfigError(f"caustics.beam_levels = {levels} needs a periodic sea (water.model fft, flat "
                          f"or heightfield), not the non-periodic {cfg.water.model.value!r}; set "
                          "caustics.beam_levels = 0")
    n = cfg.water.resolution
    if n is not None and n % (1 << levels):
        raise ConfigError(f"caustics.beam_levels = {levels} needs water.resolution divisible by "
                          f"{1 << levels} (it is {n}); lower caustics.beam_levels or change water.resolution")
    if cfg.caustics.beam_interpolation is BeamInterpolation.SMOOTH:
        raise ConfigError("caustics.beam_interpolation = 'smooth' needs the uniform grid of beams; set "
                          "caustics.beam_levels = 0 or caustics.beam_interpolation = 'flat'")


def _check_photon_scene(cfg: Config) -> None:
    """Receivers other than a flat floor, and the camera, need the photon or beam method."""
    _check_beam_levels(cfg)
    _check_sunmap(cfg)
    _check_map_window(cfg)
    _check_sun_disk(cfg)
    _check_sky(cfg)
    _check_scattering(cfg)
    _check_stats(cfg)
    photons = cfg.caustics.method.uses_receivers
    needs = []
    if cfg.floor.shape is not FloorShape.FLAT:
        needs.append(f"floor.shape = {cfg.floor.shape.value!r}")
    if cfg.receivers:
        needs.append("[[receivers]]")
    if cfg.camera.enabled:
        needs.append("camera.enabled = true")
    if needs and not photons:
        raise ConfigError(f"{', '.join(needs)} needs caustics.method = \"photons\" or \"beams\" "
                          f"(the method is "
                          f"{cfg.caustics.method.value!r})")
    if cfg.floor.shape is FloorShape.FILE and not cfg.floor.file:
        raise ConfigError("floor.file is missing; floor.shape = 'file' needs a .npy file of floor relief "
                          "(set floor.file = \"floor.npy\")")
    if cfg.floor.shape is not FloorShape.FILE and cfg.floor.file:
        raise ConfigError(f"floor.file = {cfg.floor.file!r} is only read by floor.shape = 'file'; remove "
                          "it or set floor.shape = \"file\"")
    _check_periodic_floor(cfg)
    _check_vector("floor.albedo", cfg.floor.albedo, (1, 3))
    for i, r in enumerate(cfg.receivers):
        _check_vector(f"receivers[{i}].scale", r.scale, (1, 3))
        _check_vector(f"receivers[{i}].rotate_deg", r.rotate_deg, (3,))
        _check_vector(f"receivers[{i}].translate_m", r.translate_m, (3,))
        _check_vector(f"receivers[{i}].albedo", r.albedo, (1, 3))
    cam = cfg.camera
    for name in ("position_m", "look_at_m", "up"):
        _check_vector(f"camera.{name}", getattr(cam, name), (3,))
    view = [b - a for a, b in zip(cam.position_m, cam.look_at_m)]
    if math.hypot(*view) == 0.0:
        raise ConfigError("camera.look_at_m equals camera.position_m; look at another point")
    up = cam.up
    cross = (view[1] * up[2] - view[2] * up[1], view[2] * up[0] - view[0] * up[2],
             view[0] * up[1] - view[1] * up[0])
    if math.hypot(*cross) <= 1e-9 * math.hypot(*view) * max(math.hypot(*up), 1e-300):
        raise ConfigError(f"camera.up = {list(up)} is parallel to the view direction; choose another up")


def _set_dotted(table: dict, key: str, value: Any) -> None:
    parts = key.split(".")
    node = table
    for i, part in enumerate(parts[:-1]):
        child = node.setdefault(part, {})
        if not isinstance(child, dict):
            raise ConfigError(f"override '{key}': '{'.'.join(parts[: i + 1])}' is a value, not a table")
        node = child
    node[parts[-1]] = value


def parse_override(text: str) -> tuple[str, Any]:
    """Parse ``key=value`` from the command line; the value is a TOML literal or a bare string."""
    if "=" not in text:
        raise ConfigError(f"--set {text!r} must look like key=value, e.g. sun.elevation_deg=45")
    key, raw = (s.strip() for s in text.split("=", 1))
    try:
        value = tomllib.loads(f"v = {raw}")["v"]
    except tomllib.TOMLDecodeError:
        value = raw
    return key, value


def config_from_dict(table: dict, overrides: dict[str, Any] | None = None) -> Config:
    """Validate a plain nested dict (as read from TOML) plus dotted overrides into a Config."""
    table = _deepcopy(table)
    for key, value in (overrides or {}).items():
        _set_dotted(table, key, value)
    optics = table.get("optics")
    if isinstance(optics, dict):
        wavelengths = optics.get("wavelengths")
        # Shorthands: a list of centres, or "rgb" (three equal bins over 400-700 nm).
        if isinstance(wavelengths, list):
            if not wavelengths:
                raise ConfigError("optics.wavelengths = [] needs at least one wavelength [nm]")
            optics["wavelengths"] = {"list_nm": wavelengths}
        elif wavelengths == "rgb":
            optics["wavelengths"] = {"min_nm": 400.0, "max_nm": 700.0, "bins": 3}
        elif isinstance(wavelengths, str):
            raise ConfigError(f"optics.wavelengths = {wavelengths!r} is not allowed; allowed: a table "
                              f"{{min_nm, max_nm, bins}}, a list of centres [nm] or \"rgb\"")
    _resolve_sun_position(table, set(overrides or {}))
    cfg = _build(Config, table, "")
    _check_consistency(cfg)
    return cfg


def _resolve_sun_position(table: dict, overridden: set[str]) -> None:
    """``sun.datetime`` with latitude and longitude: write the sun's elevation and azimuth into the
    table (so the resolved config, run.json and sweep ids carry them). A place given by overrides
    replaces an elevation and azimuth from the file; given in the same layer, they conflict."""
    sun = table.get("sun")
    if not isinstance(sun, dict):
        return
    place = [k for k in ("datetime", "latitude_deg", "longitude_deg") if sun.get(k) is not None]
    if not place:
        return
    if len(place) < 3:
        missing = [f"sun.{k}" for k in ("datetime", "latitude_deg", "longitude_deg") if k not in place]
        raise ConfigError(f"sun.{place[0]} needs {' and '.join(missing)} too (the sun's position comes "
                          "from a date, a time and a place)")
    explicit = [k for k in ("elevation_deg", "azimuth_deg") if k in sun]
    place_overridden = any(f"sun.{k}" in overridden for k in place)
    angles_overridden = any(f"sun.{k}" in overridden for k in explicit)
    if explicit and place_overridden and not angles_overridden:
        for k in explicit:  # the overrides' place wins over the file's angles
            del sun[k]
        explicit = []
    if explicit and angles_overridden and not place_overridden:
        for k in ("datetime", "latitude_deg", "longitude_deg"):  # and the overrides' angles over its place
            sun.pop(k, None)
        return
    from warpcaustics.optics.solar import parse_datetime, sun_position

    for key, limit in (("latitude_deg", 90.0), ("longitude_deg", 180.0)):
        if isinstance(sun[key], bool) or not isinstance(sun[key], (int, float)):
            raise ConfigError(f"sun.{key} = {_describe(sun[key])} has the wrong type; expected a number")
        if abs(sun[key]) > limit:
            raise ConfigError(f"sun.{key} = {sun[key]} is out of range; allowed: -{limit:g} <= value <= "
                              f"{limit:g}")
    if isinstance(sun["datetime"], (datetime.datetime, datetime.date)):
        sun["datetime"] = sun["datetime"].isoformat()  # a TOML date-time literal (quoted or not)
    if not isinstance(sun["datetime"], str):
        raise ConfigError(f"sun.datetime = {_describe(sun['datetime'])} must be a string, e.g. "
                          "\"2009-07-14T11:30:00+02:00\"")
    elevation, azimuth = sun_position(parse_datetime(sun["datetime"]), float(sun["latitude_deg"]),
                                      float(sun["longitude_deg"]))
    if elevation <= 0.0:
        raise ConfigError(f"sun.datetime = {sun['datetime']!r}: the sun is {-elevation:.1f}° below the "
                          f"horizon at latitude {sun['latitude_deg']}°, longitude {sun['longitude_deg']}°; "
                          "pick a daytime")
    if explicit:
        # both in one layer: accepted when they agree (a resolved config, e.g. run.json's, read back)
        given = {"elevation_deg": elevation, "azimuth_deg": azimuth}
        if any(isinstance(sun[k], bool) or not isinstance(sun[k], (int, float))
               or abs((float(sun[k]) - given[k] + 180.0) % 360.0 - 180.0) > 1e-6 for k in explicit):
            raise ConfigError(f"sun.{explicit[0]} and sun.datetime both set the sun's position; give one "
                              "of them")
    sun["elevation_deg"] = elevation
    sun["azimuth_deg"] = azimuth


def read_toml(path: str | Path) -> dict:
    """Read a TOML file, turning a missing or malformed file into a one-line ConfigError."""
    path = Path(path)
    try:
        text = path.read_text(encoding="utf-8")
    except FileNotFoundError:
        raise ConfigError(f"config file {str(path)!r} does not exist; check the path") from None
    except (IsADirectoryError, PermissionError, UnicodeDecodeError) as exc:
        raise ConfigError(f"config file {str(path)!r} cannot be read: {exc}") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"config file {str(path)!r} is not valid TOML: {exc}") from None


def config_to_dict(cfg: Any) -> dict:
    """Resolved configuration as plain TOML/JSON-compatible values."""
    out = {}
    for f in dataclasses.fields(cfg):
        value = getattr(cfg, f.name)
        if dataclasses.is_dataclass(value):
            out[f.name] = config_to_dict(value)
        elif isinstance(value, tuple):
            out[f.name] = [config_to_dict(v) if dataclasses.is_dataclass(v) else v for v in value]
        elif isinstance(value, enum.Enum):
            out[f.name] = value.value
        else:
            out[f.name] = value
    return out


def _deepcopy(table: dict) -> dict:
    return {k: _deepcopy(v) if isinstance(v, dict) else v for k, v in table.items()}
