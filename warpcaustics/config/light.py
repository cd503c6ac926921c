"""``[sun]`` and ``[sky]``: the light falling on the water."""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

from warpcaustics.config.fields import _positive, _range


class SunSpectrum(str, enum.Enum):
    ASTM_G173 = "astm_g173"
    D65 = "d65"
    BLACKBODY = "blackbody"
    FILE = "file"


class SkyModel(str, enum.Enum):
    NONE = "none"
    UNIFORM = "uniform"
    CIE = "cie"
    CIE_CLEAR = "cie_clear"


class SkySampling(str, enum.Enum):
    STRATIFIED = "stratified"
    HALVES = "halves"
    CONES = "cones"


class SkySpectrum(str, enum.Enum):
    ASTM_G173_DIFFUSE = "astm_g173_diffuse"
    SUN = "sun"


@dataclass(frozen=True)
class SunConfig:
    elevation_deg: float = field(default=60.0, metadata=_positive(90.0))
    """Angle of the sun above the horizon [deg]."""
    azimuth_deg: float = field(default=0.0, metadata=_range(-360.0, 360.0))
    """Direction towards the sun, from +x towards +y [deg]."""
    angular_diameter_deg: float = field(default=0.53, metadata=_range(0.0, 5.0))
    """Angular diameter of the sun's disk [deg]: 0 = a point; 0.53 = the real sun, integrated over
    ``disk_samples`` directions (every method but ``sunmap``, which draws this disk in its sun map)."""
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
class SkyConfig:
    model: SkyModel = SkyModel.NONE
    """Skylight (every method but ``sunmap``): ``none``; ``uniform`` (the same radiance from every
    direction of the sky); ``cie`` (the radiance shape of CIE standard general sky ``cie_type``,
    ISO 15469 / CIE S 011, around the sun); ``cie_clear`` (type 12, the CIE clear sky)."""
    cie_type: int = field(default=12, metadata=_range(1, 15))
    """The CIE standard general sky type of ``sky.model = "cie"`` (1 overcast … 12 clear … 15
    turbid; ``data/cie_standard_general_sky.csv``) [-]."""
    diffuse_fraction: float = field(default=0.0, metadata=_range(0.0, 0.99))
    """Share of the global horizontal irradiance that comes from the sky; the sun's direct beam
    (``sun.*``) is the rest [-]."""
    spectrum: SkySpectrum = SkySpectrum.ASTM_G173_DIFFUSE
    """Spectral shape of the skylight: ``astm_g173_diffuse``, the diffuse part of ASTM G173-03's
    global spectrum (global tilt − direct × cos of the sun's 11.19° incidence on its 37° plane at
    AM1.5), bluer than the sun's; or ``sun``, the sun's own shape. Scaled so that the sky's share of
    the global horizontal irradiance over the render's bins is ``diffuse_fraction``."""
    directions: int = field(default=64, metadata=_range(1, 4096))
    """Directions the sky is integrated over (cosine-weighted, stratified) [-]."""
    sampling: SkySampling = SkySampling.STRATIFIED
    """How the directions are drawn: ``stratified``, one fixed stratified set (the best mean);
    ``halves``, two stratified halves of ``directions``/2, each turned and offset at random anew
    every frame, so that each half is an unbiased estimate of the sky's continuum with an error of
    its own: the frame statistics then also give the CV without the directions' own caustic noise
    (``cv_continuous_sky``, issue 32; ``fluxratio`` with single or small-angle scattering);
    ``cones``, the stratified set with each direction's pattern spread over the floor as its cell of
    the sky would spread it (``optics/sky_cells.py``): the sky's continuum, without its directions'
    own caustics, at the cost of the same directions (``fluxratio`` on a periodic sea)."""
    surface_resolution: int = field(default=0, metadata=_range(0, 4096))
    """With ``sampling = "cones"`` over an FFT ocean: the most vertices a side of the surface the sky's
    directions are refracted through (a power of two; left aside with other samplings and seas, which
    keep the water's grid). Where ``water.resolution`` is finer, the ocean's own waves are cut to this
    grid (the same waves, the shorter ones left out). A cone spreads its direction's
    light over its cell of the sky, tens of centimetres on the floor, where the shorter waves'
    patterns are gone: on the Gernez sea (3.9 mm cells) half the grid, 1024², moves the sky's
    float64 continuum by 2–6 % in CV and under 0.2 % in mean (docs/physics.md, "The sky's
    surface"), at a quarter of the cost of each sky pass. 0 = the water's own grid [-]."""
