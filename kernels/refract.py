"""Per-vertex refraction of the sun into the water (Snell + exact Fresnel), one kernel."""

import warp as wp

from warpcaustics.kernels.geometry import fresnel_transmittance, refract

wp.set_module_options({"enable_backward": False})

MIN_DOWNWARD_COS = 1.0e-3
"""A refracted ray must descend at least this steeply (|d_z|) to reach the floor plane."""


@wp.kernel
def refract_to_floor(
    positions: wp.array2d[wp.vec3],
    normals: wp.array2d[wp.vec3],
    ior: wp.array[wp.float32],
    sun_dir: wp.vec3,
    floor_z: float,
    hit_xy: wp.array3d[wp.vec2],
    path_m: wp.array3d[wp.float32],
    transmittance: wp.array3d[wp.float32],
):
    """Refract the sun at vertex (iy, ix) for index group g and follow it to the floor plane.

    Writes the floor hit, the path length in water [m] and the Fresnel transmittance. Vertices lit
    from behind (n·s <= 0) or whose ray does not descend get transmittance 0 and a vertical ray,
    so triangles that use them carry no flux but keep finite geometry.
    """
    g, iy, ix = wp.tid()
    v = positions[iy, ix]
    n = normals[iy, ix]
    eta = 1.0 / ior[g]
    cos_i = wp.dot(n, sun_dir)
    t = wp.vec3(0.0, 0.0, -1.0)
    T = float(0.0)
    if cos_i > 0.0:
        d = refract(-sun_dir, n, eta)
        if d[2] < -MIN_DOWNWARD_COS:
            t = wp.normalize(d)
            T = fresnel_transmittance(cos_i, eta)
    ell = (floor_z - v[2]) / t[2]
    hit_xy[g, iy, ix] = wp.vec2(v[0] + ell * t[0], v[1] + ell * t[1])
    path_m[g, iy, ix] = ell
    transmittance[g, iy, ix] = T
