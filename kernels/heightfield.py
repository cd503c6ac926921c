"""Surfaces from a periodic height field sampled at cell centres (flat water and water.file)."""

import warp as wp

from warpcaustics.kernels.geometry import cell_centre, normal_from_slopes

wp.set_module_options({"enable_backward": False})


@wp.kernel
def heightfield_surface(
    heights: wp.array2d[wp.float32],
    extent_m: float,
    positions: wp.array2d[wp.vec3],
    normals: wp.array2d[wp.vec3],
):
    """Vertices at cell centres; normals from periodic central differences (exact for quadratics)."""
    iy, ix = wp.tid()
    n = heights.shape[0]
    cell = extent_m / float(n)
    hx = (heights[iy, (ix + 1) % n] - heights[iy, (ix + n - 1) % n]) / (2.0 * cell)
    hy = (heights[(iy + 1) % n, ix] - heights[(iy + n - 1) % n, ix]) / (2.0 * cell)
    xy = cell_centre(ix, iy, n, extent_m)
    positions[iy, ix] = wp.vec3(xy[0], xy[1], heights[iy, ix])
    normals[iy, ix] = normal_from_slopes(hx, hy)


@wp.func
def sample_periodic_bilinear(heights: wp.array2d[wp.float32], extent_m: float, x: float, y: float) -> float:
    """Height at (x, y) [m] by periodic bilinear interpolation between cell-centre samples."""
    n = heights.shape[0]
    u = (x + 0.5 * extent_m) * float(n) / extent_m - 0.5
    v = (y + 0.5 * extent_m) * float(n) / extent_m - 0.5
    fu = wp.floor(u)
    fv = wp.floor(v)
    tu = u - fu
    tv = v - fv
    i0 = ((int(fu) % n) + n) % n
    j0 = ((int(fv) % n) + n) % n
    i1 = (i0 + 1) % n
    j1 = (j0 + 1) % n
    return (1.0 - tv) * ((1.0 - tu) * heights[j0, i0] + tu * heights[j0, i1]) + tv * (
        (1.0 - tu) * heights[j1, i0] + tu * heights[j1, i1])


@wp.kernel
def sample_heights(
    heights: wp.array2d[wp.float32],
    extent_m: float,
    points_xy: wp.array[wp.vec2],
    out_heights: wp.array[wp.float32],
):
    i = wp.tid()
    p = points_xy[i]
    out_heights[i] = sample_periodic_bilinear(heights, extent_m, p[0], p[1])
