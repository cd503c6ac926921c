"""Irradiance on the floor's texels: each beam's cut through the floor triangles of a texel,
clipped exactly to the texel (Sutherland–Hodgman).
"""

import warp as wp

from warpcaustics.kernels.caustics.beams.irradiance import add_beam_irradiance, flux_density
from warpcaustics.kernels.caustics.beams.raster import TileGrid, tile_index
from warpcaustics.kernels.caustics.beams.section import (
    MIN_AREA_FRACTION,
    Beams,
    BeamSample,
    clamped_sample,
    copy_range,
    cross2,
    lit,
    load_corners,
    sample_beam,
    section_vertex,
    xy,
)
from warpcaustics.kernels.geometry import clip_side, clip_to_slab, polygon_area, vec8

wp.set_module_options({"enable_backward": False})


@wp.func
def plane_cut(v: wp.vec3, d: wp.vec3, a: wp.vec3, n: wp.vec3) -> wp.vec2:
    """(x, y) where the edge line v + t d meets the plane through a with normal n."""
    t = wp.dot(a - v, n) / wp.dot(d, n)
    return xy(v + t * d)


@wp.func
def texel_normals(corner: wp.vec2, texel_m: float, a3: wp.vec3, zb: float, zc: float, zd: float, flat: bool):
    """Unit normals of the texel's floor triangles (a, b, d) below the diagonal a→d (x ≥ y in texel
    units) and (a, d, c) above it; straight up on a flat texel."""
    n_lower = wp.vec3(0.0, 0.0, 1.0)
    n_upper = wp.vec3(0.0, 0.0, 1.0)
    if not flat:
        d3 = wp.vec3(corner[0] + texel_m, corner[1] + texel_m, zd)
        n_lower = wp.normalize(wp.cross(wp.vec3(corner[0] + texel_m, corner[1], zb) - a3, d3 - a3))
        n_upper = wp.normalize(wp.cross(d3 - a3, wp.vec3(corner[0], corner[1] + texel_m, zc) - a3))
    return n_lower, n_upper


@wp.func
def texel_copies(bm: Beams, b: int, z_lo: float, z_hi: float, corner: wp.vec2, texel_m: float):
    """(kx0, kx1, ky0, ky1): the copies of the texel that beam b may reach. Its sections between the
    texel's lowest and highest corners bound its cuts through both triangles (sections are linear
    in z)."""
    lo = wp.vec2(1.0e30)
    hi = wp.vec2(-1.0e30)
    for e in range(3):
        for k in range(2):
            zz = z_lo
            if k == 1:
                zz = z_hi
            sv = section_vertex(bm.base[b, e], bm.direction[b, e], zz)
            lo = wp.min(lo, sv)
            hi = wp.max(hi, sv)
    kx0, kx1 = copy_range(lo[0], hi[0], corner[0], texel_m, bm.extent_m, bm.periodic)
    ky0, ky1 = copy_range(lo[1], hi[1], corner[1], texel_m, bm.extent_m, bm.periodic)
    return kx0, kx1, ky0, ky1


@wp.func
def edges_cross_down(direction: wp.array2d[wp.vec3], b: int, n: wp.vec3) -> bool:
    """Whether every edge of beam b crosses the plane of unit normal n downwards."""
    if (
        wp.dot(direction[b, 0], n) > -1.0e-6
        or wp.dot(direction[b, 1], n) > -1.0e-6
        or wp.dot(direction[b, 2], n) > -1.0e-6
    ):
        return False
    return True


@wp.func
def clip_cut(q0: wp.vec2, q1: wp.vec2, q2: wp.vec2, origin: wp.vec2, texel_m: float, flat: bool, piece: int):
    """The cut (q0, q1, q2) in texel units from the copy's corner ``origin``, clipped to the texel
    [0, 1]² and, unless ``flat``, to floor triangle ``piece`` (0: x ≥ y, 1: x ≤ y): (x, y, count),
    count < 3 where nothing is left."""
    px = vec8()
    py = vec8()
    px[0] = (q0[0] - origin[0]) / texel_m
    py[0] = (q0[1] - origin[1]) / texel_m
    px[1] = (q1[0] - origin[0]) / texel_m
    py[1] = (q1[1] - origin[1]) / texel_m
    px[2] = (q2[0] - origin[0]) / texel_m
    py[2] = (q2[1] - origin[1]) / texel_m
    cx, cy, cn = clip_to_slab(px, py, 3, 0, 0.0, 1.0)
    if cn < 3:
        return cx, cy, cn
    rx, ry, rn = clip_to_slab(cx, cy, cn, 1, 0.0, 1.0)
    if rn < 3 or flat:
        return rx, ry, rn
    if piece == 0:
        return clip_side(rx, ry, rn, 1.0, -1.0, 0.0)
    return clip_side(rx, ry, rn, -1.0, 1.0, 0.0)


@wp.func
def polygon_centroid(rx: vec8, ry: vec8, rn: int) -> wp.vec2:
    """Area centroid of polygon (rx, ry) (its vertex mean if degenerate): exact for an integrand
    linear over it."""
    ax = float(0.0)
    ay = float(0.0)
    a2 = float(0.0)
    mx = float(0.0)
    my = float(0.0)
    for v in range(rn):
        vn = (v + 1) % rn
        cr = rx[v] * ry[vn] - rx[vn] * ry[v]
        a2 += cr
        ax += (rx[v] + rx[vn]) * cr
        ay += (ry[v] + ry[vn]) * cr
        mx += rx[v]
        my += ry[v]
    if wp.abs(a2) > 1.0e-12:
        mx = ax / (3.0 * a2)
        my = ay / (3.0 * a2)
    else:
        mx = mx / float(rn)
        my = my / float(rn)
    return wp.vec2(mx, my)


@wp.func
def floor_point(
    corner: wp.vec2, c: wp.vec2, texel_m: float, za: float, n: wp.vec3, shift: wp.vec2
) -> wp.vec3:
    """The point of the plane through (corner, za) with normal n above texel coordinates c, moved to
    the copy ``shift``."""
    x = corner[0] + c[0] * texel_m
    y = corner[1] + c[1] * texel_m
    z = za + ((n[0] * (corner[0] - x) + n[1] * (corner[1] - y)) / n[2])
    return wp.vec3(x + shift[0], y + shift[1], z)


@wp.func
def piece_sample(bm: Beams, b: int, p: wp.vec3) -> BeamSample:
    """Beam b at a piece's centroid p; a centroid on the section's boundary to rounding is clamped in."""
    s = sample_beam(bm, b, p)
    if s.inside == 0:
        s = clamped_sample(load_corners(bm, b), p)
    return s


@wp.func
def piece_density(bm: Beams, b: int, s: BeamSample, cut: float, n: wp.vec3, p: wp.vec3, scale: float):
    """(scale, density) of a piece with centroid p, its flux going over the texel's true area
    (``scale``: the piece's share of that area). Flat: the beam's flux w Σλ T spread evenly over
    its cut through this plane (area ``cut`` [m²]; exact flux, as a section on a flat floor).
    Smooth: its irradiance on the plane, E_h |d·n| / |d_z|, times the piece's true area."""
    if bm.smooth == 0:
        return scale, bm.weight[b] * s.transmit / wp.max(cut, MIN_AREA_FRACTION * s.area)
    cos_factor = wp.abs(wp.dot(s.d, n)) / wp.abs(s.d[2])
    density = flux_density(bm, b, s, p[2], bm.periodic)
    return scale * cos_factor / n[2], density


@wp.kernel
def floor_texels(
    grid: TileGrid,
    tile_start: wp.array[wp.int32],
    tile_count: wp.array[wp.int32],
    tile_items: wp.array[wp.int32],
    texels_per_tile: int,
    bm: Beams,
    corner_z: wp.array2d[wp.float32],
    texel_area_m2: wp.array2d[wp.float32],
    out: wp.array2d[wp.float32],
):
    """Irradiance on the floor's true area over each texel (K, M·M) [W m^-2 nm^-1]. The floor over a
    texel is the two planar triangles on its corners (heights ``corner_z``, (M+1)², as the floor
    mesh; a flat floor is one plane). For each beam of the texel's tile and each triangle, the
    beam's three edge lines cut the triangle's plane in a triangle, which is clipped exactly
    against the triangle's footprint (Sutherland–Hodgman). ``flat``: the piece gets the share of the
    beam's flux that its area is of the cut, with the transmittance at its area centroid (exact for
    the barycentric-linear transmittance: on a flat floor flux is conserved to rounding; on a relief
    to the shadow decisions, made per piece at its centroid, and the cuts of a beam through two
    planes, each normalised on its own); ``smooth``: the interpolated irradiance on the plane at
    the centroid times the piece's area."""
    ty, tx = wp.tid()
    extent_m = bm.extent_m
    m = texels_per_tile * grid.nx
    texel_m = extent_m / float(m)
    point = ty * m + tx
    for k in range(out.shape[0]):
        out[k, point] = 0.0
    t = tile_index(grid, tx / texels_per_tile, ty / texels_per_tile)
    corner = wp.vec2(float(tx) * texel_m - 0.5 * extent_m, float(ty) * texel_m - 0.5 * extent_m)
    za = corner_z[ty, tx]
    zb = corner_z[ty, tx + 1]
    zc = corner_z[ty + 1, tx]
    zd = corner_z[ty + 1, tx + 1]
    flat = za == zb and za == zc and za == zd
    pieces = 2
    if flat:
        pieces = 1
    inv_area = 1.0 / texel_area_m2[ty, tx]
    z_lo = wp.min(wp.min(za, zb), wp.min(zc, zd))
    z_hi = wp.max(wp.max(za, zb), wp.max(zc, zd))
    a3 = wp.vec3(corner[0], corner[1], za)
    n_lower, n_upper = texel_normals(corner, texel_m, a3, zb, zc, zd, flat)
    start = tile_start[t]
    for item in range(tile_count[t]):
        b = tile_items[start + item]
        kx0, kx1, ky0, ky1 = texel_copies(bm, b, z_lo, z_hi, corner, texel_m)
        for piece in range(pieces):
            n = n_lower
            if piece == 1:
                n = n_upper
            if not edges_cross_down(bm.direction, b, n):
                continue  # a grazing or back-facing triangle
            for ky in range(ky0, ky1 + 1):
                for kx in range(kx0, kx1 + 1):  # every periodic copy of the texel the cut may cover
                    shift = wp.vec2(float(kx) * extent_m, float(ky) * extent_m)
                    # The copy's own plane (a tilted plane does not repeat with the period).
                    a_copy = a3 + wp.vec3(shift[0], shift[1], 0.0)
                    q0 = plane_cut(bm.base[b, 0], bm.direction[b, 0], a_copy, n)
                    q1 = plane_cut(bm.base[b, 1], bm.direction[b, 1], a_copy, n)
                    q2 = plane_cut(bm.base[b, 2], bm.direction[b, 2], a_copy, n)
                    rx, ry, rn = clip_cut(q0, q1, q2, corner + shift, texel_m, flat, piece)
                    if rn < 3:
                        continue
                    share = polygon_area(rx, ry, rn)  # of the texel's horizontal area
                    if not (share > 0.0):
                        continue
                    p = floor_point(corner, polygon_centroid(rx, ry, rn), texel_m, za, n, shift)
                    s = piece_sample(bm, b, p)
                    if not lit(bm, b, s, p):
                        continue
                    cut = 0.5 * wp.abs(cross2(q1 - q0, q2 - q0))  # the beam's cut through the plane [m²]
                    scale = share * texel_m * texel_m * inv_area
                    scale, density = piece_density(bm, b, s, cut, n, p, scale)
                    add_beam_irradiance(out, point, scale, bm, b, s, density)
