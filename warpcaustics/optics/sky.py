"""The CIE standard general sky (ISO 15469:2004 / CIE S 011/E:2003, Table 1): the relative
radiance of the 15 sky types, whose shape the sky's directions carry (``sky.model = "cie"``).

For a sky element at zenith angle Z and angular distance χ from the sun (zenith angle Z_s)::

    L(Z, χ) / L_zenith = f(χ) φ(Z) / (f(Z_s) φ(0))
    φ(Z) = 1 + a exp(b / cos Z)          (φ(π/2) = 1)
    f(χ) = 1 + c [exp(d χ) − exp(d π/2)] + e cos² χ

with the gradation (a, b) and indicatrix (c, d, e) of each type from ``data/cie_standard_general_
sky.csv`` (provenance in ``data/README.md``). Luminance shape stands for the radiance's shape at
every wavelength (the sky's spectrum is taken apart from it).
"""

from __future__ import annotations

import csv
import functools
import math
from dataclasses import dataclass

import numpy as np

from warpcaustics.optics.spectra import DATA_DIR

CIE_CLEAR_TYPE = 12
"""``sky.model = "cie_clear"``: the CIE standard clear sky of low turbidity (type 12)."""


def cie_sky_type(sky) -> int | None:
    """The CIE standard general sky's type that a sky config (``cfg.sky``) draws: ``CIE_CLEAR_TYPE``
    for ``cie_clear``, ``sky.cie_type`` for ``cie``; None for a uniform sky or none."""
    from warpcaustics.config import SkyModel

    return {SkyModel.CIE_CLEAR: CIE_CLEAR_TYPE, SkyModel.CIE: sky.cie_type}.get(sky.model)


@dataclass(frozen=True)
class CieSkyType:
    number: int
    a: float
    b: float
    c: float
    d: float
    e: float
    description: str


@functools.lru_cache(maxsize=1)
def cie_sky_types() -> dict[int, CieSkyType]:
    """The 15 types of the CIE standard general sky, by number."""
    with open(DATA_DIR / "cie_standard_general_sky.csv", encoding="utf-8", newline="") as fh:
        rows = list(csv.DictReader(fh))
    return {int(r["sky_type"]): CieSkyType(int(r["sky_type"]), float(r["a"]), float(r["b"]), float(r["c"]),
                                           float(r["d"]), float(r["e"]), r["description"]) for r in rows}


def _gradation(t: CieSkyType, cos_z: np.ndarray) -> np.ndarray:
    """φ(Z) = 1 + a exp(b / cos Z), 1 at the horizon (cos Z → 0⁺)."""
    cos_z = np.asarray(cos_z, np.float64)
    with np.errstate(divide="ignore", over="ignore"):
        out = 1.0 + t.a * np.exp(np.where(cos_z > 0.0, t.b / np.maximum(cos_z, 1e-300), -np.inf))
    return out


def _indicatrix(t: CieSkyType, chi: np.ndarray) -> np.ndarray:
    """f(χ) = 1 + c [exp(d χ) − exp(d π/2)] + e cos² χ."""
    chi = np.asarray(chi, np.float64)
    return 1.0 + t.c * (np.exp(t.d * chi) - math.exp(t.d * math.pi / 2.0)) + t.e * np.cos(chi) ** 2


def cie_zenith_value(sky_type: int, sun_direction: np.ndarray) -> float:
    """f(Z_sun) φ(0): the CIE type's unnormalised radiance at the zenith, which
    :func:`cie_relative_radiance` divides by (and the radiance sensor's kernel, caustics/view.py)."""
    t = cie_sky_types()[sky_type]
    s = np.asarray(sun_direction, np.float64)
    sun_zenith = math.acos(min(max(float(s[2] / np.linalg.norm(s)), -1.0), 1.0))
    return float(_indicatrix(t, np.array(sun_zenith)) * _gradation(t, np.array(1.0)))


def cie_relative_radiance(sky_type: int, directions: np.ndarray, sun_direction: np.ndarray) -> np.ndarray:
    """L / L_zenith of each unit direction (…, 3) towards the sky (z up) for CIE type ``sky_type``
    with the sun towards ``sun_direction`` (float64)."""
    t = cie_sky_types()[sky_type]
    d = np.asarray(directions, np.float64)
    s = np.asarray(sun_direction, np.float64)
    s = s / np.linalg.norm(s)
    chi = np.arccos(np.clip(d @ s, -1.0, 1.0))
    return _indicatrix(t, chi) * _gradation(t, d[..., 2]) / cie_zenith_value(sky_type, s)


def sky_radiance(sky_type: int | None, directions: np.ndarray, sun_direction: np.ndarray,
                 horizontal_irradiance: np.ndarray, quadrature: int = 256) -> np.ndarray:
    """(..., K) spectral radiance [W m⁻² sr⁻¹ nm⁻¹] of the sky towards unit ``directions`` (..., 3),
    zero below the horizon: the shape of CIE type ``sky_type`` (None: a uniform sky) scaled so that
    the sky's irradiance on a horizontal plane is ``horizontal_irradiance`` (K,), i.e. L(ω) =
    E_h rel(ω) / ∫ rel cos θ dΩ; the integral by the midpoint rule on ``quadrature`` rings of
    equal cos²θ and twice as many azimuths (exactly π for the uniform sky)."""
    d = np.asarray(directions, np.float64)
    e = np.asarray(horizontal_irradiance, np.float64)
    above = d[..., 2] > 0.0
    if sky_type is None:
        rel = above.astype(np.float64)
        norm = math.pi
    else:
        up = np.where(above[..., None], d, np.array([0.0, 0.0, 1.0]))
        rel = np.where(above, cie_relative_radiance(sky_type, up, sun_direction), 0.0)
        # cos θ dΩ = ½ d(sin²θ) dφ: rings equal in sin²θ carry equal weight for a uniform sky
        sin2 = (np.arange(quadrature) + 0.5) / quadrature
        phi = (np.arange(2 * quadrature) + 0.5) * math.pi / quadrature
        sin_t = np.sqrt(sin2)[:, None]
        cos_t = np.sqrt(1.0 - sin2)[:, None]
        grid = np.stack(np.broadcast_arrays(sin_t * np.cos(phi), sin_t * np.sin(phi), cos_t), axis=-1)
        norm = float(cie_relative_radiance(sky_type, grid, sun_direction).mean()) * math.pi
    return rel[..., None] * e / norm


def stratified_hemisphere(count: int, offset: float, turn: float) -> np.ndarray:
    """(count, 3) cosine-weighted stratified directions: sinθ_j = √((j + offset)/count), φ_j = turn +
    (j + offset) × the golden angle, j < count."""
    j = np.arange(count) + offset
    sin_t = np.sqrt(j / count)
    cos_t = np.sqrt(1.0 - sin_t * sin_t)
    phi = turn + j * math.pi * (3.0 - math.sqrt(5.0))
    return np.stack([sin_t * np.cos(phi), sin_t * np.sin(phi), cos_t], axis=1)
