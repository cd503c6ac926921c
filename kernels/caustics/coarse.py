"""The whole patch's light on coarse texels, beside a fine floor-map window: the small-angle
transfer's large scales (``warpcaustics/caustics/small_angle.py``).

A window of a periodic sea sees light scattered in from the sea around it. The small-angle transfer
spreads the light of a beam over metres once b·s is a few (Darecki's water at 7–10 m), so a
window's scattered light must come from the pattern around the window, not only from the window
repeated. The flux of each quad of the pass (its two triangles', ``fluxratio.triangle_flux``) is
put at the mean of its four floor hits and shared bilinearly among the four nearest texel centres of
a coarse map of the whole patch ("cloud in cell"): the flux is kept exactly (float64 sums), its
position to about a footprint. The transfer takes only the scales above two coarse texels from this
map, and the window's own texels correct the rest (``SmallAngleScattering.transfer``), so that an
error in where the coarse map puts light cancels to first order.
"""

import warp as wp

from warpcaustics.kernels.caustics.fluxratio import carries_flux, grid_corner, wrap_coord

wp.set_module_options({"enable_backward": False})


@wp.kernel
def splat_quads(
    hit_xy: wp.array3d[wp.vec2],
    flux_w_nm: wp.array4d[wp.float32],
    wavelengths_per_group: int,
    extent_m: float,
    coarse_scale: float,
    coarse: wp.array3d[wp.float64],
):
    """Add the flux of quad (iy, ix)'s two triangles for index group g [W nm⁻¹] to ``coarse`` (Mc,
    Mc, K), a whole periodic map of ``coarse_scale`` texels per metre whose texel (i, j) is centred at
    −L/2 + (i + ½)/scale: bilinear weights at the mean of the quad's four floor hits (its corners
    lifted across the patch's seam), indices wrapping."""
    g, iy, ix = wp.tid()
    n = hit_xy.shape[1]
    k_begin = g * wavelengths_per_group
    if carries_flux(flux_w_nm, iy, ix, 0, k_begin, wavelengths_per_group) == 0:
        if carries_flux(flux_w_nm, iy, ix, 1, k_begin, wavelengths_per_group) == 0:
            return
    xb, yb, sb = grid_corner(ix, iy, 1, 0, n, extent_m, 1)  # corner (0, 0) is (ix, iy) itself
    xc, yc, sc = grid_corner(ix, iy, 1, 1, n, extent_m, 1)
    xd, yd, sd = grid_corner(ix, iy, 0, 1, n, extent_m, 1)
    centre = 0.25 * (hit_xy[g, iy, ix] + hit_xy[g, yb, xb] + sb + hit_xy[g, yc, xc] + sc
                     + hit_xy[g, yd, xd] + sd)
    m = coarse.shape[0]
    c = (centre + wp.vec2(0.5 * extent_m, 0.5 * extent_m)) * coarse_scale - wp.vec2(0.5, 0.5)
    fx = wp.floor(c[0])
    fy = wp.floor(c[1])
    tx = c[0] - fx
    ty = c[1] - fy
    cx = int(wrap_coord(fx, m))
    cy = int(wrap_coord(fy, m))
    cx1 = (cx + 1) % m
    cy1 = (cy + 1) % m
    for j in range(wavelengths_per_group):
        k = k_begin + j
        f = wp.float64(flux_w_nm[iy, ix, 0, k]) + wp.float64(flux_w_nm[iy, ix, 1, k])
        wp.atomic_add(coarse, cy, cx, k, f * wp.float64((1.0 - tx) * (1.0 - ty)))
        wp.atomic_add(coarse, cy, cx1, k, f * wp.float64(tx * (1.0 - ty)))
        wp.atomic_add(coarse, cy1, cx, k, f * wp.float64((1.0 - tx) * ty))
        wp.atomic_add(coarse, cy1, cx1, k, f * wp.float64(tx * ty))
