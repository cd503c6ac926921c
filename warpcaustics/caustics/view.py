"""An upward-looking radiance sensor at every texel of the floor map (``floor.view_fov_deg``).

Darecki et al. (2011, Fig. 15; the field of view on their p. 4) measured the radiance at 532 nm in
4.5° fields of view looking up at thirteen zenith angles in the sun's plane. What such a sensor
reads, ∫ L dω over its cone C, is built here from the two parts of the light that the flux-ratio
map already separates:

* **The sun**, through the flux-ratio deposit itself: each vertex's refracted ray t reaches the floor
  carrying its share of the sun's flux; it counts only where it arrives from within C (−t·v ≥
  cos(fov/2), v the sensor's axis), weighted by 1/|t_z| so that the horizontal irradiance dE = L cosθ
  dω becomes L dω (:meth:`ViewCone.weight`, on the device, between refraction and deposit). A
  triangle carries the mean of its corners' weights: the cone's edge is blurred by the spread of
  directions across one surface cell.
* **The sky**, traced back from each texel: Q directions u evenly spread over C (equal solid angles,
  a Fibonacci spiral on the cap), each followed up to the height field (a fixed-point iteration on
  the periodic bilinear heights), refracted out through the interpolated normal (Snell; total
  internal reflection: the sensor sees the water below, whose upwelling light is not modelled, and
  gets 0), and given the sky's radiance there times the Fresnel transmittance, n² (the radiance's
  n² law) and the water's attenuation along the ray (:meth:`ViewCone.sky`). The sun's disk is not
  in the sky's radiance (it is the first part); a backward ray through a facet tilted so far that it
  leaves below the horizon sees another wave and gets 0.

Scattered light is not included (``optics.scattering = "single"``, c = a + b): near the sun's
direction its radiance is smoother than the glints', so there it would only lower the CV the map
gives; away from the sun, where the map holds the sky alone, the scattered light's own flicker is
missing too (docs/validation.md, "Radiance seen from below").
"""

from __future__ import annotations

import math

import numpy as np
import warp as wp

from warpcaustics.caustics.window import MapWindow
from warpcaustics.kernels.optics import refract as refract_kernels
from warpcaustics.kernels.optics import view as view_kernels
from warpcaustics.optics.sky import cie_sky_type, cie_sky_types, cie_zenith_value, sky_radiance

SKY_SAMPLES = 64
"""Directions Q over the cone for the sky: about 0.5° apart in a 4.5° field of view, finer than the
CIE clear sky's radiance changes outside the sun's aureole."""

HEIGHT_ITERATIONS = 5
"""Fixed-point steps h ← H(p + u (h − z_floor)/u_z) to a backward ray's surface point; each shrinks
the error by about tan θ_u times the slope (under 0.3 for slopes of 0.25 inside Snell's window)."""

GOLDEN_ANGLE = math.pi * (3.0 - math.sqrt(5.0))


def view_axis(zenith_deg: float, azimuth_deg: float) -> np.ndarray:
    """Unit axis v (z up) of a sensor looking up at ``zenith_deg`` towards ``azimuth_deg``."""
    z, a = math.radians(zenith_deg), math.radians(azimuth_deg)
    return np.array([math.sin(z) * math.cos(a), math.sin(z) * math.sin(a), math.cos(z)])


def cone_directions(axis: np.ndarray, fov_deg: float, count: int) -> tuple[np.ndarray, float]:
    """(count, 3) unit directions spread evenly over the cone of full angle ``fov_deg`` about ``axis``
    (equal solid angles: cos ψ uniform in [cos(fov/2), 1], the azimuth turning by the golden angle),
    and the solid angle each stands for [sr]."""
    cos_half = math.cos(math.radians(0.5 * fov_deg))
    j = np.arange(count) + 0.5
    cos_psi = 1.0 - j / count * (1.0 - cos_half)
    sin_psi = np.sqrt(np.maximum(0.0, 1.0 - cos_psi ** 2))
    phi = j * GOLDEN_ANGLE
    local = np.stack([sin_psi * np.cos(phi), sin_psi * np.sin(phi), cos_psi], axis=1)
    a = np.asarray(axis, np.float64) / np.linalg.norm(axis)
    helper = np.array([1.0, 0.0, 0.0]) if abs(a[2]) > 0.9 else np.array([0.0, 0.0, 1.0])
    e1 = np.cross(helper, a)
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(a, e1)
    return local @ np.stack([e1, e2, a]), 2.0 * math.pi * (1.0 - cos_half) / count


class ViewCone:
    """The radiance sensor of ``floor.view_*``: weights the sun's refracted rays by the cone, and
    traces the sky back from the texels."""

    def __init__(self, cfg, light, sun_direction: np.ndarray, device: str):
        f = cfg.floor
        self.fov_deg = float(f.view_fov_deg)
        self.axis = view_axis(f.view_zenith_deg, f.view_azimuth_deg)
        self.cos_half = math.cos(math.radians(0.5 * self.fov_deg))
        self.floor_z = -float(f.depth_m)
        self.device = device
        self.window = MapWindow(cfg)
        self._sky = self._sky_inputs = None
        if light.sky_directions is not None:
            self._prepare_sky(cfg, light, sun_direction)

    def _prepare_sky(self, cfg, light, sun_direction: np.ndarray) -> None:
        """What every frame's sky trace takes but the surface, on the device once: the cone's
        directions, the texels' grid, the sun's refractive indices (one per band, or the first bin's
        for all without dispersion), the attenuation, the sky's zenith radiance and CIE shape."""
        k = len(light.ior)
        f32 = dict(dtype=wp.float32, device=self.device)
        sky_type = cie_sky_type(cfg.sky)
        sun = np.asarray(sun_direction, np.float64)
        zenith = sky_radiance(sky_type, np.array([0.0, 0.0, 1.0]), sun,
                              np.asarray(light.sky_irradiance_horizontal, np.float64))
        directions, d_omega = cone_directions(self.axis, self.fov_deg, SKY_SAMPLES)
        t = self.window.texel_m
        self._sky = wp.empty((k, *self.window.texel_x.shape), **f32)
        """The traced sky's (K, M, M) map, reused from frame to frame."""
        x0, y0 = self.window.texel_x[0, 0] - 0.5 * t, self.window.texel_y[0, 0] - 0.5 * t
        ior = np.repeat(np.asarray(light.group_ior, np.float32), k // len(light.group_ior))
        self._sky_inputs = [
            wp.vec2(float(x0), float(y0)), float(t), self.floor_z,
            wp.array(directions.astype(np.float32), dtype=wp.vec3, device=self.device), float(d_omega),
            HEIGHT_ITERATIONS, wp.array(ior, **f32),
            wp.array(np.asarray(light.attenuation_per_m, np.float32), **f32),
            wp.array(zenith.astype(np.float32), **f32), int(sky_type is None),
            wp.vec3(*sun.astype(np.float32)), *cie_parameters(sky_type, sun)]

    def weight(self, surface, refracted, floor_z: float) -> None:
        """Scale ``refracted.transmittance`` in place: 1/|t_z| where the vertex's ray arrives from
        within the cone, 0 elsewhere (every index group)."""
        groups, n, _ = refracted.transmittance.shape
        wp.launch(refract_kernels.view_weight, dim=(groups, n, n),
                  inputs=[surface.positions, refracted.hit_xy, refracted.path_m, float(floor_z),
                          wp.vec3(*self.axis.astype(np.float32)), float(self.cos_half)],
                  outputs=[refracted.transmittance], device=self.device)

    def sky(self, surface) -> np.ndarray:
        """(K, M, M) the sky's ∫ L dω over the cone at every texel [W m⁻² nm⁻¹]: one kernel over the
        texels (``kernels/optics/view.py``), read back."""
        wp.launch(view_kernels.view_sky, dim=self.window.texel_x.shape,
                  inputs=[surface.positions, surface.normals, float(surface.extent_m), *self._sky_inputs],
                  outputs=[self._sky], device=self.device)
        return self._sky.numpy().copy()  # float32, as the sun's map


def cie_parameters(sky_type: int | None, sun_direction: np.ndarray) -> tuple[wp.vec4, float, float]:
    """((a, b, c, d), e, 1/(f(Z_sun) φ(0))) of CIE type ``sky_type`` for the kernel's
    :func:`~warpcaustics.kernels.optics.view.cie_relative` (zeros for a uniform sky)."""
    if sky_type is None:
        return wp.vec4(0.0, 0.0, 0.0, 0.0), 0.0, 1.0
    t = cie_sky_types()[sky_type]
    return wp.vec4(t.a, t.b, t.c, t.d), float(t.e), 1.0 / cie_zenith_value(sky_type, sun_direction)
