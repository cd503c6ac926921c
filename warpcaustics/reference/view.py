"""A radiance sensor's sky in float64 numpy (``floor.view_*``): the same backward trace as the kernel
``kernels/optics/view.py`` (caustics/view.py's docstring), written with array operations."""

from __future__ import annotations

import numpy as np

from warpcaustics.caustics.view import HEIGHT_ITERATIONS, SKY_SAMPLES, cone_directions
from warpcaustics.optics.sky import cie_relative_radiance, sky_radiance
from warpcaustics.optics.snell import fresnel_transmittance, refract
from warpcaustics.reference.floor import bilinear_periodic


def view_sky(positions: np.ndarray, normals: np.ndarray, extent_m: float, x: np.ndarray, y: np.ndarray,
             floor_z: float, axis: np.ndarray, fov_deg: float, sky_type: int | None,
             sun_direction: np.ndarray, sky_horizontal: np.ndarray, ior: np.ndarray,
             attenuation_per_m: np.ndarray, samples: int = SKY_SAMPLES) -> np.ndarray:
    """(K, *x.shape) the sky's ∫ L dω over the cone seen from the floor points (x, y, floor_z) up
    through the periodic height field of cell-centre ``positions`` (N, N, 3) and ``normals`` (N, N, 3)
    over ``extent_m``: Q = ``samples`` backward rays per point (module docstring). ``sky_horizontal``
    (K,): the sky's horizontal irradiance; ``ior``, ``attenuation_per_m`` (K,) per band."""
    n = positions.shape[0]
    z = positions[..., 2]
    scale = n / extent_m

    def at(field: np.ndarray, px: np.ndarray, py: np.ndarray) -> np.ndarray:
        return bilinear_periodic(field, (px + 0.5 * extent_m) * scale - 0.5,
                                 (py + 0.5 * extent_m) * scale - 0.5)

    directions, d_omega = cone_directions(axis, fov_deg, samples)
    # L = L_zenith × L/L_zenith: the sky's normalisation to its horizontal irradiance once
    zenith = sky_radiance(sky_type, np.array([0.0, 0.0, 1.0]), sun_direction, sky_horizontal)
    out = np.zeros((len(ior), *np.shape(x)))
    for u in directions:
        if u[2] <= 0.0:
            continue
        h = np.zeros(np.shape(x))
        for _ in range(HEIGHT_ITERATIONS):
            run = (h - floor_z) / u[2]
            px, py = x + run * u[0], y + run * u[1]
            h = at(z, px, py)
        ell = (h - floor_z) / u[2]
        px, py = x + ell * u[0], y + ell * u[1]
        normal = np.stack([at(normals[..., i], px, py) for i in range(3)], axis=-1)
        normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
        cos_w = normal @ u  # the ray meets the surface from below
        for k in range(len(ior)):
            eta = float(ior[k])
            out_dir = refract(np.broadcast_to(u, normal.shape), -normal, eta)
            trans = fresnel_transmittance(cos_w, eta)  # 0 on total internal reflection
            above = out_dir[..., 2] > 0.0  # else the ray leaves into another wave: not the sky
            up = np.where(above[..., None], out_dir, u)
            relative = (above if sky_type is None else
                        np.where(above, cie_relative_radiance(sky_type, up, sun_direction), 0.0))
            out[k] += ((eta * eta * zenith[k] * d_omega) * trans * relative
                       * np.exp(-attenuation_per_m[k] * ell))
    return out
