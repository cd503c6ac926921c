"""Per-vertex refraction of the sun into the water (Snell + exact Fresnel), one kernel."""

import warp as wp

from warpcaustics.kernels.geometry import bilerp, bilinear_cell, sun_into_water

wp.set_module_options({"enable_backward": False})


@wp.kernel
def refract_to_floor(
    positions: wp.array2d[wp.vec3],
    normals: wp.array2d[wp.vec3],
    visible: wp.array2d[wp.float32],
    ior: wp.array[wp.float32],
    sun_dir: wp.vec3,
    floor_z: float,
    hit_xy: wp.array3d[wp.vec2],
    path_m: wp.array3d[wp.float32],
    transmittance: wp.array3d[wp.float32],
):
    """Refract the sun at vertex (iy, ix) for index group g and follow it to the floor plane.

    Writes the floor hit, the path length in water [m] and the Fresnel transmittance times the
    vertex's sun visibility. Vertices lit from behind (n·s <= 0) or whose ray does not descend get
    transmittance 0 and a vertical ray, so triangles that use them carry no flux but keep finite
    geometry.
    """
    g, iy, ix = wp.tid()
    v = positions[iy, ix]
    n = normals[iy, ix]
    t, T = sun_into_water(n, sun_dir, 1.0 / ior[g])
    T = T * visible[iy, ix]
    ell = (floor_z - v[2]) / t[2]
    hit_xy[g, iy, ix] = wp.vec2(v[0] + ell * t[0], v[1] + ell * t[1])
    path_m[g, iy, ix] = ell
    transmittance[g, iy, ix] = T


@wp.func
def surface_height(positions: wp.array2d[wp.vec3], extent_m: float, x: float, y: float) -> float:
    """Height of a cell-centre height field at (x, y) [m]: periodic bilinear interpolation
    (a walled surface is only sampled inside its walls)."""
    i0, j0, i1, j1, tu, tv = bilinear_cell(positions.shape[0], extent_m, x, y)
    return bilerp(positions[j0, i0][2], positions[j0, i1][2], positions[j1, i0][2],
                  positions[j1, i1][2], tu, tv)


@wp.kernel
def height_range(positions: wp.array2d[wp.vec3], z_range: wp.array[wp.float32]):
    """z_range = (min z, max z) of the surface; initialise to (+big, -big) before launching."""
    iy, ix = wp.tid()
    z = positions[iy, ix][2]
    wp.atomic_min(z_range, 0, z)
    wp.atomic_max(z_range, 1, z)


@wp.kernel
def sun_visibility(
    positions: wp.array2d[wp.vec3],
    sun_dir: wp.vec3,
    extent_m: float,
    periodic: int,
    z_range: wp.array[wp.float32],
    visible: wp.array2d[wp.float32],
):
    """1 where the sun is seen from vertex (iy, ix), 0 where a crest of the surface hides it.

    Marches from the vertex towards the sun in half-cell horizontal steps over the periodic height
    field until the ray rises above the highest crest.
    """
    iy, ix = wp.tid()
    p = positions[iy, ix]
    horizontal = wp.sqrt(sun_dir[0] * sun_dir[0] + sun_dir[1] * sun_dir[1])
    visible[iy, ix] = 1.0
    if horizontal < 1.0e-6:
        return  # sun at the zenith: a height field cannot shade itself
    n = positions.shape[0]
    cell = extent_m / float(n)
    step = 0.5 * cell / horizontal  # along the ray, per half cell travelled horizontally
    steps = int(wp.ceil((z_range[1] - p[2]) / (sun_dir[2] * step))) + 1
    tolerance = 1.0e-4 * cell
    for i in range(1, steps + 1):
        q = p + (float(i) * step) * sun_dir
        if periodic == 0 and (wp.abs(q[0]) > 0.5 * extent_m - 0.5 * cell
                              or wp.abs(q[1]) > 0.5 * extent_m - 0.5 * cell):
            return  # the ray leaves a walled pool over its rim: nothing more to hide the sun
        if surface_height(positions, extent_m, q[0], q[1]) > q[2] + tolerance:
            visible[iy, ix] = 0.0
            return
