"""Surfaces from a periodic height field sampled at cell centres (flat water and water.file)."""

import warp as wp

from warpcaustics.kernels.geometry import bilerp, bilinear_cell, cell_centre, normal_from_slopes

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
    i0, j0, i1, j1, tu, tv = bilinear_cell(heights.shape[0], extent_m, x, y)
    return bilerp(heights[j0, i0], heights[j0, i1], heights[j1, i0], heights[j1, i1], tu, tv)


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
