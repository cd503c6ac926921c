"""``[floor]``, ``[[receivers]]`` and ``[camera]``: what receives the light under the water, and
the camera that looks at it."""

from __future__ import annotations

import enum
from dataclasses import dataclass, field

from warpcaustics.config.fields import _coordinate, _length, _range


class FloorShape(str, enum.Enum):
    FLAT = "flat"
    SLOPE = "slope"
    RIPPLES = "ripples"
    FILE = "file"


@dataclass(frozen=True)
class FloorConfig:
    depth_m: float = field(default=4.0, metadata=_length(positive=True))
    """Depth of the floor below the water at rest at the origin (floor at z = -depth_m + relief) [m]."""
    shape: FloorShape = FloorShape.FLAT
    """Relief of the floor: ``flat``, ``slope`` (a plane), ``ripples`` (sand ripples, a sine) or
    ``file`` (``floor.file``); anything but ``flat`` needs ``caustics.method = "photons"`` or ``"beams"``."""
    slope_deg: float = field(default=5.0, metadata=_range(0.0, 60.0))
    """Inclination of the ``slope`` [deg]."""
    slope_azimuth_deg: float = field(default=0.0, metadata=_range(-360.0, 360.0))
    """Direction in which the ``slope`` descends (gets deeper), from +x towards +y [deg]."""
    ripple_amplitude_m: float = field(default=0.03, metadata=_length())
    """Half the crest-to-trough height of the ``ripples`` [m]."""
    ripple_wavelength_m: float = field(default=0.5, metadata=_length(positive=True))
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
    view_fov_deg: float = field(default=0.0, metadata=_range(0.0, 60.0))
    """Full angle of the field of view of an upward-looking radiance sensor at every texel of the
    floor map (``fluxratio``, single scattering, a periodic sea without chop): the map then holds the
    light arriving within that cone, ∫ L dω over it [W m⁻² nm⁻¹], not the irradiance; divided by
    the cone's solid angle, the radiance the sensor reads (Darecki et al. 2011's radiometers: 4.5°).
    0 = the irradiance (the default) [deg]."""
    view_zenith_deg: float = field(default=0.0, metadata=_range(0.0, 90.0))
    """Zenith angle of the radiance sensor's axis, looking up (``view_fov_deg``) [deg]."""
    view_azimuth_deg: float = field(default=0.0, metadata=_range(-360.0, 360.0))
    """Azimuth towards which the radiance sensor's axis leans, from +x towards +y as the sun's
    (the sun's azimuth: looking towards the sun) [deg]."""


@dataclass(frozen=True)
class ReceiverConfig:
    mesh: str = "sphere"
    """A triangle mesh: ``sphere``, ``cube``, ``cylinder`` or ``cone`` (pyvista's unit-size
    primitives) or a file (OBJ, PLY, STL, VTK, VTP; relative to the config file's folder)."""
    scale: tuple[float, ...] = field(default=(1.0,), metadata=_length(positive=True))
    """Scale factor: one value or (sx, sy, sz) [-]; applied first."""
    rotate_deg: tuple[float, ...] = field(default=(0.0, 0.0, 0.0), metadata=_range(-360.0, 360.0))
    """Rotations about x, then y, then z [deg]; applied after scaling."""
    translate_m: tuple[float, ...] = field(default=(0.0, 0.0, -2.0), metadata=_coordinate())
    """Translation (x, y, z) [m]; applied last."""
    albedo: tuple[float, ...] = field(default=(0.7, 0.7, 0.7), metadata=_range(0.0, 1.0))
    """Diffuse albedo: one value (grey) or three (linear sRGB, as for the floor) [-]."""
    albedo_file: str | None = None
    """CSV of a reflectance spectrum (as ``floor.albedo_file``); replaces ``albedo``."""
    ior: float | None = field(default=None, metadata=_range(1.0, 4.0))
    """With ``caustics.bounces`` > 1: a clear, non-absorbing dielectric of this refractive index
    (glass ≈ 1.5) that the light passes through (Fresnel at both faces) instead of landing on;
    unset = opaque and diffuse [-]."""
    specular: bool = False
    """With ``caustics.bounces`` > 1: a perfect mirror that reflects all the light it meets."""


@dataclass(frozen=True)
class CameraConfig:
    enabled: bool = False
    """Render a camera image (needs ``caustics.method = "photons"`` or ``"beams"``)."""
    position_m: tuple[float, ...] = field(default=(0.0, -6.0, -1.0), metadata=_coordinate())
    """Pinhole position (x, y, z) [m]: below the water surface (z < 0), or above every crest (z > 0:
    the view from above the water, through the refracting surface)."""
    look_at_m: tuple[float, ...] = field(default=(0.0, 0.0, -3.0), metadata=_coordinate())
    """Point the camera looks at (x, y, z) [m]."""
    up: tuple[float, ...] = field(default=(0.0, 0.0, 1.0), metadata=_coordinate())
    """Up direction of the image (x, y, z) [-]."""
    fov_deg: float = field(default=60.0, metadata=_range(1.0, 170.0))
    """Vertical field of view [deg]."""
    width: int = field(default=320, metadata=_range(8, 8192))
    """Image width [pixels]."""
    height: int = field(default=240, metadata=_range(8, 8192))
    """Image height [pixels]."""
    shaft_samples: int = field(default=32, metadata=_range(1, 1024))
    """Above the water: midpoint samples of the single scattering along each refracted view ray,
    from the surface to the receiver it meets, and with photons the horizontal slices of the water
    their light is gathered on [-]."""
