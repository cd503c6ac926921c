"""What several test files share: the repository's paths, float64 references written independently
of the code under test, and the still-water scene that the analytic checks render.

Paths are built from this file, never from the working directory: the suite runs from anywhere
(``cd /tmp && python -m pytest /path/to/repo/tests``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import warpcaustics as wc

ROOT = Path(__file__).resolve().parents[1]
"""The repository's root (the folder holding pyproject.toml)."""
CONFIGS = ROOT / "configs"
"""The example scenes: ``CONFIGS / "ocean.toml"``."""
SHARED_WATER_DATA = ROOT.parent / "shared" / "data" / "water"
"""Published tables of water's optical properties, beside the checkout in CI and development (a test
that reads them skips where they are absent)."""


def fresnel_t_angles(theta_i: np.ndarray, n1: float, n2: float) -> np.ndarray:
    """Unpolarised Fresnel transmittance from the angle form of Fresnel's equations (float64).

    rs = -sin(θi-θt)/sin(θi+θt), rp = tan(θi-θt)/tan(θi+θt) (Born & Wolf §1.5.2); at normal
    incidence R = ((n1-n2)/(n1+n2))^2. Written independently of the code under test.
    """
    theta_i = np.asarray(theta_i, dtype=np.float64)
    sin_t = n1 / n2 * np.sin(theta_i)
    out = np.zeros_like(theta_i)
    ok = sin_t < 1.0
    ti = theta_i[ok]
    tt = np.arcsin(sin_t[ok])
    normal = ti < 1e-6
    with np.errstate(invalid="ignore", divide="ignore"):
        rs = -np.sin(ti - tt) / np.sin(ti + tt)
        rp = np.tan(ti - tt) / np.tan(ti + tt)
    r = np.where(normal, ((n1 - n2) / (n1 + n2)) ** 2, 0.5 * (rs**2 + rp**2))
    out[ok] = 1.0 - r
    return out


def flat_water_scene(elevation_deg: float, depth_m: float, water_type: str = "pure", **extra) -> wc.Scene:
    """Still water 8 m across (32² surface and map), a point sun at azimuth 37°, 8 bands; ``extra``
    (dotted keys) last, so it may change any of these."""
    overrides = {
        "water.model": "flat",
        "water.resolution": 32,
        "water.extent_m": 8.0,
        "caustics.map_resolution": 32,
        "sun.elevation_deg": elevation_deg,
        "sun.azimuth_deg": 37.0,
        "sun.angular_diameter_deg": 0.0,  # the analytic references are a point sun's
        "floor.depth_m": depth_m,
        "optics.water_type": water_type,
        "optics.wavelengths.bins": 8,
    }
    overrides.update(extra)
    return wc.load_scene(None, overrides)


def flat_floor_irradiance(result, elevation_deg: float, depth_m: float, ior=1.333) -> np.ndarray:
    """E_sun cosθ T(θ) exp(−c D / cosθ_t) per band (float64): the floor irradiance under still water
    at ``depth_m``; ``ior`` is one index for all bands or one per band (dispersion)."""
    theta = np.radians(90.0 - elevation_deg)
    n = np.asarray(ior, dtype=np.float64)
    cos_t = np.sqrt(1.0 - (np.sin(theta) / n) ** 2)
    t = np.array([fresnel_t_angles(np.array([theta]), 1.0, nk)[0] for nk in np.atleast_1d(n)])
    t = t.reshape(n.shape)
    return result.sun_irradiance * np.cos(theta) * t * np.exp(-result.attenuation_per_m * depth_m / cos_t)


def subnormal_count(a: np.ndarray) -> int:
    """How many entries of ``a`` are float32 subnormals (non-zero, smaller than the smallest normal):
    the values that slow a CPU's arithmetic down by orders of magnitude."""
    return int(np.count_nonzero((np.abs(a) < np.finfo(np.float32).tiny) & (a != 0)))


def low_pass(field: np.ndarray, m: int, extent: float) -> np.ndarray:
    """A periodic field on an N×N cell-centred grid, cut to the wavenumbers an M×M grid holds (its
    Nyquist row and column dropped) and evaluated at that grid's cell centres, in float64 numpy."""
    n = field.shape[0]
    keep = np.r_[0:m // 2, n - m // 2 + 1:n]
    spectrum = np.fft.fft2(field.astype(np.float64))[np.ix_(keep, keep)] * (m / n) ** 2
    k = 2 * np.pi * np.fft.fftfreq(m, extent / m)[np.r_[0:m // 2, m // 2 + 1:m]]
    kx, ky = np.meshgrid(k, k)
    shift = 0.5 * extent / m - 0.5 * extent / n  # the coarse cells' centres from the fine ones'
    full = np.zeros((m, m), complex)
    index = np.r_[0:m // 2, m // 2 + 1:m]
    full[np.ix_(index, index)] = spectrum * np.exp(1j * (kx + ky) * shift)
    return np.fft.ifft2(full).real
