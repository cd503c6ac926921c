"""The light scattered once into a radiance sensor's line of sight, its mean: what the sensor of
``floor.view_*`` (:mod:`warpcaustics.caustics.view`), which takes the unscattered light alone
(single scattering, c = a + b), leaves out.

Along the line of sight from the sensor at depth D towards v (v_z > 0) to the still surface, a
point s metres away lies at depth z = D − s v_z. Light crossing it in direction d (μ = −d_z > 0),
of radiance L₀(d) just below the surface, is scattered into the line of sight with the phase
function p at the angle ψ between d and −v, and attenuated on to the sensor:

    L_p(v) = b ∫₀^ℓ e^{−c s} ∫ p(ψ) L₀(d) e^{−c z(s)/μ} dω_d ds,   ℓ = D / v_z,

the radiative transfer equation's source term integrated along the ray once (the single-scattering
solution; the same integrand as the camera's in-scattering, docs/physics.md, "The view from above").
The s-integral is closed: e^{−cD/μ} (1 − e^{−κℓ})/κ with κ = c (1 − v_z/μ). The light is the
refracted sun's beam, E⊥ = E_sun T(θ_s) cos θ_s / cos θ_w just below the surface, and the sky's,
L₀ = n² T(θ_a) L_sky (the n² law), from the CIE sky the scene has; both as through still water, so
the result is the scattered light's mean under a wavy sea to the order the waves' tilts average out.
The sensor reads P = ∫ L_p dω over its cone. The phase function's forward peak (Petzold's power law
below 0.1°) is integrated in polar angles: about the refracted sun for the sun's light, about each
line of sight for the sky's within :data:`INNER_DEG`; the rest of the sky on rings. The light
scattered by less than :data:`FORWARD_DEG` is kept apart (:class:`Scattered`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from warpcaustics.caustics.view import cone_directions, view_axis
from warpcaustics.optics.phase import phase_values
from warpcaustics.optics.sky import cie_sky_type, sky_radiance
from warpcaustics.optics.snell import fresnel_transmittance, refract

FORWARD_DEG = 3.0
"""The sky's light scattered by less than this into the line of sight is taken as the sky's
radiance along the line of sight times the phase function's share below it."""

CONE_SAMPLES = 64
"""Directions over the sensor's cone for the sky's scattered light (smooth across the cone)."""

SKY_RINGS = 192
"""Rings of the sky's quadrature (equal in sin²θ above the water, twice as many azimuths), for its
light scattered by more than :data:`INNER_DEG`."""

INNER_DEG = 10.0
"""The sky's light scattered by less than this into a line of sight is integrated in polar angles
about it (:data:`INNER_NODES`: log-spaced angles, split at :data:`FORWARD_DEG`; azimuths), where the
phase function's forward peak is."""

INNER_NODES = (400, 128)

SUN_NODES = (1000, 1024)
"""Polar nodes (angle from the refracted sun, log-spaced; azimuth) of the sun's scattered light."""


def _path_integral(c: float, depth_m: float, v_z: np.ndarray, mu: np.ndarray) -> np.ndarray:
    """∫₀^ℓ e^{−c s} e^{−c (D − s v_z)/μ} ds, ℓ = D / v_z, in closed form."""
    length = depth_m / v_z
    kappa = c * (1.0 - v_z / mu)
    x = kappa * length
    small = np.abs(x) < 1e-8
    ratio = np.where(small, length * (1.0 - 0.5 * x), -np.expm1(-x) / np.where(small, 1.0, kappa))
    return np.exp(-c * depth_m / mu) * ratio


def sun_part(axis: np.ndarray, fov_deg: float, depth_m: float, sun_down: np.ndarray, beam: float,
             c: float, b: float, phase) -> tuple[float, float]:
    """∫ over the cone of the refracted sun's scattered radiance [W m⁻² (per nm)], (scattered by
    less than :data:`FORWARD_DEG`, by more): ``sun_down`` the unit direction its light travels in
    the water, ``beam`` its irradiance across the beam just below the surface, ``phase`` p(ψ)
    [1/sr] of angles [rad]; in polar angles (ψ, φ) about the direction the sensor would look to
    see the sun, where the forward peak is."""
    half = math.radians(0.5 * fov_deg)
    seen = -np.asarray(sun_down, np.float64)
    off = math.acos(min(1.0, float(seen @ axis)))
    lo, hi = max(off - half, 0.0), min(off + half, math.pi)
    split = math.radians(FORWARD_DEG)
    if lo < split < hi:  # a node at the split, so that each side is integrated on its own nodes
        count = SUN_NODES[0] // 2
        segments = [np.geomspace(max(lo, 1e-9), split, count), np.geomspace(split, hi, count)]
    else:
        segments = [np.geomspace(max(lo, 1e-9), hi, SUN_NODES[0])]
    psi = np.concatenate(segments)
    helper = np.array([1.0, 0.0, 0.0]) if abs(seen[2]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = np.cross(seen, helper)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(seen, e1)
    # the azimuths about the sun that can reach the cone: all where the cone holds the sun, else
    # those within the cone's angular half-width seen from the sun, asin(sin h / sin off)
    tangent = math.asin(min(1.0, math.sin(half) / math.sin(off))) if off > half else math.pi
    width = min(math.pi, 1.01 * tangent)
    centre = math.atan2(float(axis @ e2), float(axis @ e1))
    phi = centre + width * ((np.arange(SUN_NODES[1]) + 0.5) * 2.0 / SUN_NODES[1] - 1.0)
    sp, cp = np.sin(psi)[:, None, None], np.cos(psi)[:, None, None]
    v = cp * seen + sp * (np.cos(phi)[None, :, None] * e1 + np.sin(phi)[None, :, None] * e2)
    inside = (v @ axis >= math.cos(half)) & (v[..., 2] > 1e-6)
    v_z = np.where(inside, v[..., 2], 1.0)
    path = np.where(inside, _path_integral(c, depth_m, v_z, -sun_down[2]), 0.0)
    ring = path.sum(axis=1) * (2.0 * width / SUN_NODES[1])  # ∫ dφ at each ψ
    integrand = phase(psi) * np.sin(psi) * ring
    parts, start = [], 0
    for nodes in segments:
        parts.append(float(np.trapezoid(integrand[start:start + len(nodes)], nodes)))
        start += len(nodes)
    if len(parts) == 2:
        near, wide = parts
    else:  # wholly inside the split, or wholly outside it
        near, wide = (parts[0], 0.0) if hi <= split else (0.0, parts[0])
    if lo == 0.0:  # below the first node: p's share there, the path as at the node
        near += float(ring[0]) / (2.0 * math.pi) * _share_below(phase, psi[0])
    return b * beam * near, b * beam * wide


def _share_below(phase, theta: float) -> float:
    """∫ p dω below ``theta`` (tiny): by the power law through p at theta/2 and theta."""
    p1, p2 = phase(np.array([0.5 * theta, theta]))
    m = min(max(math.log(p1 / p2) / math.log(2.0), 0.0), 1.99)
    return 2.0 * math.pi * float(p2) * theta ** 2 / (2.0 - m)


def _in_water_sky(down: np.ndarray, sky_radiance_of, ior: float) -> np.ndarray:
    """The sky's radiance in the water along unit directions ``down`` (..., 3) its light travels in:
    n² T(θ_a) L_sky towards the direction above the water it came from (the n² law), 0 outside
    Snell's window."""
    horizontal = -ior * down[..., :2]
    sin2 = np.sum(horizontal**2, axis=-1)
    inside = (sin2 < 1.0) & (down[..., 2] < 0.0)
    up = np.concatenate([horizontal, np.sqrt(np.maximum(1.0 - sin2, 0.0))[..., None]], axis=-1)
    up = np.where(inside[..., None], up, np.array([0.0, 0.0, 1.0]))
    value = ior**2 * fresnel_transmittance(up[..., 2], 1.0 / ior) * sky_radiance_of(up)
    return np.where(inside, value, 0.0)


def sky_part(axis: np.ndarray, fov_deg: float, depth_m: float, sky_radiance_of, ior: float, c: float,
             b: float, phase) -> tuple[float, float]:
    """∫ over the cone of the sky's scattered radiance, (scattered by less than :data:`FORWARD_DEG`,
    by more): ``sky_radiance_of`` the sky's radiance above the water towards unit directions
    (..., 3). The light from within :data:`INNER_DEG` of each line of sight, where the phase
    function's forward peak is, in polar angles about it; the rest on the sky's rings."""
    views, d_omega = cone_directions(axis, fov_deg, CONE_SAMPLES)
    rings = SKY_RINGS
    sin2 = (np.arange(rings) + 0.5) / rings
    phi = (np.arange(2 * rings) + 0.5) * math.pi / rings
    sin_a = np.sqrt(sin2)[:, None]
    cos_a = np.sqrt(1.0 - sin2)[:, None] * np.ones_like(phi)
    up = np.stack(np.broadcast_arrays(sin_a * np.cos(phi), sin_a * np.sin(phi), cos_a), axis=-1)
    up = up.reshape(-1, 3)
    down = refract(-up, np.array([0.0, 0.0, 1.0]), 1.0 / ior)
    mu = -down[:, 2]
    # L₀ dω in the water = T L_sky μ_a dω_a / μ (the n² law and Snell's solid angles); μ_a dω_a = π/(2R²)
    cell = math.pi / (2 * rings**2)
    weight = fresnel_transmittance(up[:, 2], 1.0 / ior) * sky_radiance_of(up) * cell / mu
    inner, split = math.radians(INNER_DEG), math.radians(FORWARD_DEG)
    count = INNER_NODES[0] // 2
    segments = [np.geomspace(1e-7, split, count), np.geomspace(split, inner, count)]
    turns = (np.arange(INNER_NODES[1]) + 0.5) * 2.0 * math.pi / INNER_NODES[1]
    near = wide = 0.0
    for v in views:
        psi = np.arccos(np.clip(down @ -v, -1.0, 1.0))
        far = psi >= inner
        wide += np.sum(np.where(far, phase(psi) * weight * _path_integral(c, depth_m, v[2], mu), 0.0))
        helper = np.array([1.0, 0.0, 0.0]) if abs(v[2]) > 0.9 else np.array([0.0, 0.0, 1.0])
        e1 = np.cross(v, helper)
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(v, e1)
        for k, nodes in enumerate(segments):  # the light travels along d, ψ from −v
            sp, cp = np.sin(nodes)[:, None, None], np.cos(nodes)[:, None, None]
            d = -cp * v + sp * (np.cos(turns)[None, :, None] * e1 + np.sin(turns)[None, :, None] * e2)
            mu_d = np.maximum(-d[..., 2], 1e-9)
            ring = np.sum(_in_water_sky(d, sky_radiance_of, ior) * _path_integral(c, depth_m, v[2], mu_d),
                          axis=1) * (2.0 * math.pi / INNER_NODES[1])
            part = float(np.trapezoid(phase(nodes) * np.sin(nodes) * ring, nodes))
            if k == 0:
                near += part
            else:
                wide += part
    return b * near * d_omega, b * wide * d_omega


@dataclass
class Scattered:
    """The mean light scattered once into a radiance sensor's cone, ∫ L_p dω [W m⁻² nm⁻¹], per band
    (K,): scattered by less than :data:`FORWARD_DEG`, the sun's (``near_sun``) and the sky's
    (``near_sky``), which come from nearly the directions the sensor sees and flicker with them; and
    scattered by more, the sun's (``wide_sun``) and the sky's (``wide_sky``), which come from the
    whole lit water column (the sun's with the caustics along the line of sight:
    :func:`line_of_sight_modulation`)."""

    near_sun: np.ndarray
    near_sky: np.ndarray
    wide_sun: np.ndarray
    wide_sky: np.ndarray

    @property
    def wide(self) -> np.ndarray:
        """The light scattered by more than :data:`FORWARD_DEG`, the sun's and the sky's."""
        return self.wide_sun + self.wide_sky


def refracted_beam(scene, k: int) -> tuple[np.ndarray, float]:
    """Band ``k``'s refracted sun through still water: the unit direction its light travels in the
    water and its irradiance across the beam just below the surface, E⊥ = E_sun T(θ_s) cos θ_s /
    cos θ_w [W m⁻² nm⁻¹] (the sun's disk as its centre)."""
    from warpcaustics.optics import spectra

    cfg = scene.config
    bins = spectra.bins_for(cfg.optics)
    sun = float(spectra.sun_irradiance(bins, cfg.sun, scene.base_dir)[k])
    return _beam(scene.sun_direction, sun, float(spectra.refractive_index(cfg.optics, bins)[k]))


def _beam(to_sun: np.ndarray, sun: float, n: float) -> tuple[np.ndarray, float]:
    """:func:`refracted_beam` from the direction towards the sun, its beam-normal irradiance above
    the water and the water's index."""
    down = refract(-to_sun, np.array([0.0, 0.0, 1.0]), 1.0 / n)
    mu_s = float(to_sun[2])
    return down, sun * float(fresnel_transmittance(mu_s, 1.0 / n)) * mu_s / -float(down[2])


def sensor_path_radiance(scene) -> Scattered:
    """The mean light scattered once into the scene's radiance sensor (``floor.view_*``), the sun's
    beam's and the sky's, as through still water (module docstring)."""
    from warpcaustics.config import SkyModel
    from warpcaustics.optics import spectra

    cfg = scene.config
    f = cfg.floor
    if not f.view_fov_deg:
        raise ValueError("sensor_path_radiance needs a radiance sensor (floor.view_fov_deg)")
    bins = spectra.bins_for(cfg.optics)
    sun = spectra.sun_irradiance(bins, cfg.sun, scene.base_dir)
    ior = spectra.refractive_index(cfg.optics, bins)
    water = spectra.water_optics(cfg.optics, bins)
    axis = view_axis(f.view_zenith_deg, f.view_azimuth_deg)
    to_sun = scene.sun_direction

    def phase(theta):
        return phase_values(cfg.optics, theta)

    sky = None if cfg.sky.model is SkyModel.NONE else scene.sky_irradiance(sun)
    sky_type = cie_sky_type(cfg.sky)
    out = Scattered(*(np.zeros(len(bins.centres_nm)) for _ in range(4)))
    for k in range(len(out.wide_sun)):
        n, a, b = float(ior[k]), float(water.absorption_per_m[k]), float(water.scattering_per_m[k])
        down, beam = _beam(to_sun, float(sun[k]), n)
        out.near_sun[k], out.wide_sun[k] = sun_part(axis, f.view_fov_deg, f.depth_m, down, beam, a + b, b,
                                                    phase)
        if sky is not None:
            def radiance(d, k=k):
                return sky_radiance(sky_type, d, to_sun, sky[k:k + 1])[..., 0]
            out.near_sky[k], out.wide_sky[k] = sky_part(axis, f.view_fov_deg, f.depth_m, radiance, n, a + b,
                                                        b, phase)
    return out


def _ellipse_response(fx: np.ndarray, fy: np.ndarray, along: np.ndarray, a: float, b: float) -> np.ndarray:
    """The Fourier transform of a uniform ellipse of unit weight, semi-axis ``a`` along the unit
    horizontal vector ``along`` and ``b`` across it [m], at spatial frequencies (fx, fy) [1/m]:
    2 J₁(ρ)/ρ, ρ = 2π √((a f·u)² + (b f·u⊥)²)."""
    from scipy.special import j1

    f_along = fx * along[0] + fy * along[1]
    f_across = -fx * along[1] + fy * along[0]
    rho = 2.0 * math.pi * np.sqrt((a * f_along) ** 2 + (b * f_across) ** 2)
    small = rho < 1e-6
    safe = np.where(small, 1.0, rho)
    return np.where(small, 1.0 - rho**2 / 8.0, 2.0 * j1(safe) / safe)


def sun_disk_footprint(to_sun: np.ndarray, angular_diameter_deg: float,
                       ior: float) -> tuple[np.ndarray, float, float]:
    """How the sun's disk (angular radius α in the air) spreads a point sun's pattern per metre of
    depth, to first order: an ellipse with semi-axes α cos θ_a / (n μ³) along the sun's azimuth
    (Snell's dθ_w/dθ_a = cos θ_a / (n μ), and d(z tan θ_w)/dθ_w = z / μ²) and α / (n μ) across it
    (the azimuth kept, the horizontal distance z tan θ_w turned), μ = cos θ_w; returns (the unit
    horizontal vector towards the sun's azimuth, along, across)."""
    alpha = math.radians(0.5 * angular_diameter_deg)
    cos_a = float(to_sun[2])
    mu = math.sqrt(max(1.0 - (1.0 - cos_a**2) / ior**2, 0.0))
    horizontal = np.asarray(to_sun[:2], np.float64)
    norm = float(np.linalg.norm(horizontal))
    unit = horizontal / norm if norm > 1e-12 else np.array([1.0, 0.0])
    return unit, alpha * cos_a / (ior * mu**3), alpha / (ior * mu)


def line_of_sight_modulation(slices: np.ndarray, slice_depths_m: np.ndarray, texel_m: float, *,
                             depth_m: float, axis: np.ndarray, fov_deg: float, c: float,
                             thickness_m: np.ndarray | None = None, sun_disk=None) -> np.ndarray:
    """How the sun's wide-angle scattered light into a radiance sensor at each texel varies with the
    caustics along its line of sight: F(x) = Σⱼ wⱼ ⟨Eⱼ⟩_cone(x + oⱼ) / Σⱼ wⱼ Ēⱼ, mean 1, so that the
    sun's part of :func:`sensor_path_radiance`'s ``wide_sun`` becomes wide_sun · F(x).

    ``slices``: (J, M, M) the unscattered sun's irradiance on horizontal planes at ``slice_depths_m``
    between the surface and the sensor at ``depth_m``, each standing for a layer ``thickness_m``
    thick (None: midpoints of equal steps, D/J each), periodic maps of the whole patch on texels
    ``texel_m`` wide (rows along +y). The line of sight from x towards ``axis`` (v_z > 0) crosses
    depth zⱼ at sⱼ = (D − zⱼ)/v_z, offset oⱼ = sⱼ v_h; its light is attenuated by e^{−c sⱼ} on to
    the sensor, wⱼ = e^{−c sⱼ} Δzⱼ (each plane's own ∝ E, the phase function at the wide angles
    taken as constant across the patch). The sensor's cone of ``fov_deg`` reaches an ellipse at each
    plane (semi-axes sⱼ tan(fov/2)/v_z along the line's azimuth and sⱼ tan(fov/2) across, uniform:
    equal solid angles); ``sun_disk`` (:func:`sun_disk_footprint`, for slices of a point sun) spreads
    each plane by the disk's ellipse at its depth. Shifts and ellipses in Fourier space, exact for
    the periodic maps."""
    slices = np.asarray(slices, np.float64)
    count, m = slices.shape[0], slices.shape[-1]
    thickness = (np.full(count, depth_m / count) if thickness_m is None
                 else np.asarray(thickness_m, np.float64))
    freq = np.fft.fftfreq(m, d=texel_m)
    fx, fy = np.meshgrid(freq, freq)  # [iy, ix]
    v = np.asarray(axis, np.float64) / np.linalg.norm(axis)
    if v[2] <= 0.0 or len(slice_depths_m) != count or np.any(np.asarray(slice_depths_m) > depth_m):
        raise ValueError("line_of_sight_modulation needs an upward line of sight and a depth per plane, "
                         "each above the sensor")
    horizontal = float(np.hypot(v[0], v[1]))
    along = v[:2] / horizontal if horizontal > 1e-12 else np.array([1.0, 0.0])
    tan_half = math.tan(math.radians(0.5 * fov_deg))
    total = np.zeros((m, m), np.complex128)
    norm = 0.0
    for j in range(count):
        z = float(slice_depths_m[j])
        s = (depth_m - z) / v[2]
        w = math.exp(-c * s) * float(thickness[j])
        offset = s * v[:2]
        spectrum = np.fft.fft2(slices[j]) * np.exp(2j * math.pi * (fx * offset[0] + fy * offset[1]))
        spectrum *= _ellipse_response(fx, fy, along, s * tan_half / v[2], s * tan_half)
        if sun_disk is not None:
            unit, per_along, per_across = sun_disk
            spectrum *= _ellipse_response(fx, fy, unit, z * per_along, z * per_across)
        total += w * spectrum
        norm += w * float(slices[j].mean())
    return np.fft.ifft2(total).real / norm if norm > 0.0 else np.ones((m, m))
