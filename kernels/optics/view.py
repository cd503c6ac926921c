"""A radiance sensor's sky, traced back from each texel through the sensor's cone (caustics/view.py;
its float64 twin is ``warpcaustics/reference/view.py``)."""

import warp as wp

from warpcaustics.kernels.geometry import fresnel_transmittance, grid_bilinear, refract

wp.set_module_options({"enable_backward": False})


@wp.func
def cie_relative(d: wp.vec3, sun: wp.vec3, cie: wp.vec4, cie_e: float, scale: float) -> float:
    """L/L_zenith of the CIE standard general sky (ISO 15469) towards ``d`` (above the horizon):
    f(χ) φ(Z) × ``scale`` (= 1/(f(Z_sun) φ(0))), f(χ) = 1 + c [exp(dχ) − exp(dπ/2)] + e cos²χ,
    φ(Z) = 1 + a exp(b/cos Z); ``cie`` = (a, b, c, d), ``cie_e`` = e."""
    chi = wp.acos(wp.clamp(wp.dot(d, sun), -1.0, 1.0))
    cos_chi = wp.cos(chi)
    f = 1.0 + cie[2] * (wp.exp(cie[3] * chi) - wp.exp(cie[3] * 0.5 * wp.pi)) + cie_e * cos_chi * cos_chi
    phi = 1.0 + cie[0] * wp.exp(cie[1] / d[2])
    return f * phi * scale


@wp.kernel
def view_sky(
    positions: wp.array2d[wp.vec3],
    normals: wp.array2d[wp.vec3],
    extent_m: float,
    origin: wp.vec2,
    texel_m: float,
    floor_z: float,
    directions: wp.array[wp.vec3],
    d_omega: float,
    iterations: int,
    ior: wp.array[wp.float32],
    attenuation_per_m: wp.array[wp.float32],
    zenith_radiance: wp.array[wp.float32],
    uniform: int,
    sun: wp.vec3,
    cie: wp.vec4,
    cie_e: float,
    cie_scale: float,
    out: wp.array3d[wp.float32],
):
    """Texel (iy, ix) at (origin + (i + ½) texel, floor_z): for each direction u of the cone, up to
    the periodic bilinear height field (``iterations`` fixed-point steps), out through the
    interpolated normal (Snell; total internal reflection or a ray leaving below the horizon: 0),
    and Σ_u n² T L_sky(out) exp(−c ℓ) dω into ``out[k, iy, ix]`` per band k (L_sky = L_zenith ×
    the CIE shape, or L_zenith for a uniform sky)."""
    iy, ix = wp.tid()
    x = origin[0] + (float(ix) + 0.5) * texel_m
    y = origin[1] + (float(iy) + 0.5) * texel_m
    bands = ior.shape[0]
    for k in range(bands):
        out[k, iy, ix] = 0.0
    for q in range(directions.shape[0]):
        u = directions[q]
        if u[2] <= 0.0:
            continue
        h = float(0.0)
        for _k in range(iterations):  # as the sun map's backward rays (kernels/caustics/sunmap.py)
            run = (h - floor_z) / u[2]
            h = grid_bilinear(positions, extent_m, 1, x + run * u[0], y + run * u[1])[2]
        ell = (h - floor_z) / u[2]
        normal = wp.normalize(grid_bilinear(normals, extent_m, 1, x + ell * u[0], y + ell * u[1]))
        cos_w = wp.dot(normal, u)
        for k in range(bands):
            eta = ior[k]
            air = refract(u, -normal, eta)
            if air[2] <= 0.0:  # total internal reflection, or out into another wave
                continue
            trans = fresnel_transmittance(cos_w, eta)
            relative = float(1.0)
            if uniform == 0:
                relative = cie_relative(wp.normalize(air), sun, cie, cie_e, cie_scale)
            weight = eta * eta * zenith_radiance[k] * d_omega * wp.exp(-attenuation_per_m[k] * ell)
            out[k, iy, ix] = out[k, iy, ix] + weight * trans * relative
