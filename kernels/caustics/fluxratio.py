"""Floor caustics by flux ratio: each refracted surface triangle deposits its flux on the floor.

The footprint of a surface triangle's refracted rays on the horizontal floor plane is the
horizontal section of its caustic volume (Sandberg & Falemo 2005; Ernst et al. 2005). Its flux is
spread over the footprint by exact area overlap with each texel, so the flux deposited equals the
triangle's flux to rounding, whatever the footprint's size or orientation (folded footprints count
by their unsigned area). Texel indices wrap: the surface and the floor map are periodic with period
L (in walled pools light beyond the walls is dropped).

This module holds the triangles' fluxes and the overlap by clipping against each texel
(Sutherland–Hodgman, :func:`spread_triangle`), which the photons' footprints use; the flux-ratio
map's own deposit accumulates the same overlaps by the footprints' edges
(``kernels/caustics/coverage.py``), at the cost of their perimeter rather than their area.

Surface triangles: each quad of the vertex grid splits into ``half = 0``: corners (0,0), (1,0),
(1,1) and ``half = 1``: (0,0), (1,1), (0,1), both counter-clockwise seen from above (see
``quad_corner`` for the periodic wrap and for walled pools).
"""

import warp as wp

from warpcaustics.kernels.geometry import clip_to_slab, polygon_area, vec8

wp.set_module_options({"enable_backward": False})

DEGENERATE_AREA_TEXELS = 1.0e-9
"""Footprints smaller than this [texel^2] deposit at their centroid (a focus point or line)."""

MAX_CLIPPED_TEXELS = 4096
"""Footprints whose bounding box holds more texels are deposited by area samples (bounded work)."""

SAMPLE_SUBDIVISIONS = 32
"""Such a footprint is cut into SAMPLE_SUBDIVISIONS² congruent triangles; each centroid gets an
equal share of the flux."""


@wp.func
def quad_corner(qx: int, qy: int, half: int, corner: int, n: int, extent_m: float, periodic: int):
    """Grid index of a triangle corner of quad (qx, qy) and the shift [m] to add to that vertex.

    Periodic surfaces have N×N quads; a corner past the last row/column wraps to index 0 shifted by
    L. Walled surfaces have (N+1)×(N+1) quads reaching the walls: quad q spans vertices q−1…q, and a
    corner outside the grid is a wall vertex, the edge vertex moved by ±Δ/2 onto the wall (same
    height, normal, transmittance and refracted direction), so the floor is covered to the walls.
    """
    dx = int(0)
    dy = int(0)
    if half == 0:
        if corner >= 1:
            dx = 1
        if corner == 2:
            dy = 1
    else:
        if corner == 1:
            dx = 1
        if corner >= 1:
            dy = 1
    return grid_corner(qx, qy, dx, dy, n, extent_m, periodic)


@wp.func
def grid_corner(qx: int, qy: int, dx: int, dy: int, n: int, extent_m: float, periodic: int):
    """Grid index of corner (dx, dy) ∈ {0, 1}² of quad (qx, qy) and the shift [m] to add to that
    vertex (the periodic wrap or the wall offset described in :func:`quad_corner`)."""
    shift = wp.vec2(0.0)
    if periodic != 0:
        cx = qx + dx
        cy = qy + dy
        if cx == n:
            cx = 0
            shift[0] = extent_m
        if cy == n:
            cy = 0
            shift[1] = extent_m
        return cx, cy, shift
    half_cell = 0.5 * extent_m / float(n)
    cx = qx - 1 + dx
    cy = qy - 1 + dy
    if cx < 0:
        cx = 0
        shift[0] = -half_cell
    if cx > n - 1:
        cx = n - 1
        shift[0] = half_cell
    if cy < 0:
        cy = 0
        shift[1] = -half_cell
    if cy > n - 1:
        cy = n - 1
        shift[1] = half_cell
    return cx, cy, shift


@wp.func
def wrap_coord(x: float, m: int) -> float:
    """x reduced into [0, m), in floating point (safe for coordinates beyond the int range)."""
    fm = float(m)
    r = x - fm * wp.floor(x / fm)
    if r >= fm:
        r = 0.0
    return r


@wp.func
def lift(p: wp.vec3, shift: wp.vec2) -> wp.vec3:
    return p + wp.vec3(shift[0], shift[1], 0.0)


@wp.func
def texel(i: int, m: int, periodic: int) -> int:
    """Texel index i on a map of m: wrapped when periodic, −1 (dropped) outside a walled map."""
    if periodic == 0:
        if i < 0 or i >= m:
            return -1
        return i
    r = i % m
    if r < 0:
        r += m
    return r


@wp.func
def texel_of(x: float, m: int, periodic: int) -> int:
    """Texel holding coordinate x [texels], safe for coordinates beyond the int range."""
    if periodic == 0:
        if x < 0.0 or x >= float(m):
            return -1
        return int(x)
    return int(wrap_coord(x, m))


@wp.func
def reaching(transmittance: wp.array3d[wp.float32], path_m: wp.array3d[wp.float32], g: int, x: int, y: int,
             c: float) -> float:
    """T exp(−c l) of vertex (y, x) for index group g: the share of its ray's light that enters and
    reaches the floor."""
    return transmittance[g, y, x] * wp.exp(-c * path_m[g, y, x])


@wp.kernel
def triangle_flux(
    positions: wp.array2d[wp.vec3],
    path_m: wp.array3d[wp.float32],
    transmittance: wp.array3d[wp.float32],
    sun_dir: wp.vec3,
    sun_irradiance: wp.array[wp.float32],
    attenuation_per_m: wp.array[wp.float32],
    wavelengths_per_group: int,
    extent_m: float,
    periodic: int,
    flux_w_nm: wp.array4d[wp.float32],
    entering_m2: wp.array4d[wp.float32],
):
    """Flux [W nm^-1] that each triangle (iy, ix, half) of quad (iy, ix) delivers to the floor at every
    wavelength k, and its share of the light that enters the water (before attenuation); one thread
    per quad, whose four corners serve both halves.

    ``flux_w_nm`` is (Q, Q, 2, K) with Q quads per side (N periodic, N+1 walled): a triangle's
    wavelengths are contiguous for the deposit.

    ``E_sun(k) * A_perp * mean_i(T_i exp(-c(k) l_i))``, with ``A_perp`` the triangle's area
    projected perpendicular to the sun (0 for triangles facing away from it);
    ``entering_m2`` (G, Q, Q, 2): ``A_perp * mean_i(T_i)`` per index group, the flux entering the
    water through the triangle per unit irradiance [m²] (no K axis: the host multiplies by E(k)).
    Half 0 has corners (0,0), (1,0), (1,1), half 1 (0,0), (1,1), (0,1) (:func:`quad_corner`).
    """
    iy, ix = wp.tid()
    n = positions.shape[0]
    xa, ya, sa = grid_corner(ix, iy, 0, 0, n, extent_m, periodic)
    xb, yb, sb = grid_corner(ix, iy, 1, 0, n, extent_m, periodic)
    xc, yc, sc = grid_corner(ix, iy, 1, 1, n, extent_m, periodic)
    xd, yd, sd = grid_corner(ix, iy, 0, 1, n, extent_m, periodic)
    pa = lift(positions[ya, xa], sa)
    pb = lift(positions[yb, xb], sb)
    pc = lift(positions[yc, xc], sc)
    pd = lift(positions[yd, xd], sd)
    a_perp0 = wp.max(0.5 * wp.dot(wp.cross(pb - pa, pc - pa), sun_dir), 0.0)
    a_perp1 = wp.max(0.5 * wp.dot(wp.cross(pc - pa, pd - pa), sun_dir), 0.0)
    for k in range(sun_irradiance.shape[0]):
        g = k / wavelengths_per_group
        c = attenuation_per_m[k]
        ea = reaching(transmittance, path_m, g, xa, ya, c)
        ec = reaching(transmittance, path_m, g, xc, yc, c)
        mean_t0 = (ea + reaching(transmittance, path_m, g, xb, yb, c) + ec) / 3.0
        mean_t1 = (ea + ec + reaching(transmittance, path_m, g, xd, yd, c)) / 3.0
        flux_w_nm[iy, ix, 0, k] = sun_irradiance[k] * a_perp0 * mean_t0
        flux_w_nm[iy, ix, 1, k] = sun_irradiance[k] * a_perp1 * mean_t1
        if k % wavelengths_per_group == 0:
            ta = transmittance[g, ya, xa]
            tc = transmittance[g, yc, xc]
            entering_m2[g, iy, ix, 0] = a_perp0 * ((ta + transmittance[g, yb, xb] + tc) / 3.0)
            entering_m2[g, iy, ix, 1] = a_perp1 * ((ta + tc + transmittance[g, yd, xd]) / 3.0)


@wp.struct
class TriangleDeposit:
    """Where one surface triangle (iy, ix, half)'s flux goes: its flux ``flux_w_nm[iy, ix, half, k]``
    for the bands ``k_begin`` … ``k_begin + k_count − 1`` of its index group, added to
    ``floor_texels`` (M, M, K)."""

    floor_texels: wp.array3d[wp.float32]
    flux_w_nm: wp.array4d[wp.float32]
    k_begin: int
    k_count: int
    iy: int
    ix: int
    half: int


@wp.func
def add_to_texel(dep: TriangleDeposit, tx: int, ty: int, weight: float):
    """Add ``weight`` × the triangle's flux to texel (ty, tx) of each wavelength of its group
    (nothing for a texel index of −1: light that left a walled map)."""
    if tx < 0 or ty < 0:
        return
    for j in range(dep.k_count):
        k = dep.k_begin + j
        wp.atomic_add(dep.floor_texels, ty, tx, k, weight * dep.flux_w_nm[dep.iy, dep.ix, dep.half, k])


@wp.func
def deposit_by_samples(
    dep: TriangleDeposit, q0: wp.vec2, e1: wp.vec2, e2: wp.vec2, m: int, periodic: int, inv_texel_area: float
):
    """Deposit a footprint (q0, q0 + e1, q0 + e2) [texels] through the centroids of its
    SAMPLE_SUBDIVISIONS² congruent sub-triangles, each carrying an equal share of the flux."""
    s = SAMPLE_SUBDIVISIONS
    weight = inv_texel_area / float(s * s)
    for a in range(s):
        for b in range(s - a):
            for flip in range(2):
                if flip == 1 and b == s - a - 1:
                    continue  # the last row has no downward sub-triangle
                off = 1.0 / 3.0 + float(flip) / 3.0
                p = q0 + ((float(a) + off) / float(s)) * e1 + ((float(b) + off) / float(s)) * e2
                add_to_texel(dep, texel_of(p[0], m, periodic), texel_of(p[1], m, periodic), weight)


@wp.struct
class FloorMap:
    origin: wp.vec2
    """Corner (x, y) [m] of texel (0, 0) of the map."""
    centre: wp.vec2
    """Centre of the map [m]."""
    scale: float
    """Texels per metre, M / W."""
    wrap: int
    """1: the map is the whole periodic patch and its texel indices wrap; 0: texels outside the map
    are dropped (a walled pool, an open patch, or a window of a periodic sea)."""
    max_clipped: int
    """Footprints covering more texels of the map are deposited by area samples: MAX_CLIPPED_TEXELS
    for whole maps; a window's texels are few and fine, so all of them are clipped exactly."""


@wp.func
def spread_triangle(
    dep: TriangleDeposit,
    q0: wp.vec2,
    e1: wp.vec2,
    e2: wp.vec2,
    m: int,
    wrap: int,
    max_clipped: int,
    inv_texel_area: float,
    coarse_count: wp.array[wp.int32],
):
    """Spread ``dep``'s flux over the triangle (q0, q0 + e1, q0 + e2) [texels of an M × M map; q0
    within it when ``wrap``]: each texel gets overlap area / triangle area × ``inv_texel_area`` of it,
    the overlap clipped exactly (texels outside an unwrapped map are dropped). Triangles whose box
    exceeds ``max_clipped`` texels go by area samples, counted in ``coarse_count``."""
    spread_triangle_at(dep, wp.vec2i(0, 0), q0, e1, e2, m, wrap, max_clipped, inv_texel_area, coarse_count)


@wp.func
def spread_triangle_at(
    dep: TriangleDeposit,
    base: wp.vec2i,
    q0: wp.vec2,
    e1: wp.vec2,
    e2: wp.vec2,
    m: int,
    wrap: int,
    max_clipped: int,
    inv_texel_area: float,
    coarse_count: wp.array[wp.int32],
):
    """:func:`spread_triangle` of the triangle whose corner q0 is given relative to texel ``base``
    (its coordinates small, so that the clipping keeps float32's precision wherever it lies)."""
    q1 = q0 + e1
    q2 = q0 + e2
    u_lo = wp.floor(wp.min(q0[0], wp.min(q1[0], q2[0])))
    v_lo = wp.floor(wp.min(q0[1], wp.min(q1[1], q2[1])))
    u_hi = wp.floor(wp.max(q0[0], wp.max(q1[0], q2[0])))
    v_hi = wp.floor(wp.max(q0[1], wp.max(q1[1], q2[1])))
    single_texel = u_lo == u_hi and v_lo == v_hi
    if wrap == 0:  # only the texels inside the map are visited
        u_lo = wp.max(u_lo, float(-base[0]))
        v_lo = wp.max(v_lo, float(-base[1]))
        u_hi = wp.min(u_hi, float(m - 1 - base[0]))
        v_hi = wp.min(v_hi, float(m - 1 - base[1]))
        if u_lo > u_hi or v_lo > v_hi:
            return  # the footprint misses the map
    if (u_hi - u_lo + 1.0) * (v_hi - v_lo + 1.0) > float(max_clipped):
        # A huge footprint (grazing rays, a deep floor): bounded work, flux still conserved.
        wp.atomic_add(coarse_count, 0, 1)
        at = q0 + wp.vec2(float(base[0]), float(base[1]))
        deposit_by_samples(dep, at, e1, e2, m, wrap, inv_texel_area)
        return
    i_lo = base[0] + int(u_lo)
    j_lo = base[1] + int(v_lo)
    i_hi = base[0] + int(u_hi)
    j_hi = base[1] + int(v_hi)
    # Coordinates relative to the footprint's first texel keep the clipping arithmetic small.
    corner = wp.vec2(u_lo, v_lo)
    q0 = q0 - corner
    q1 = q1 - corner
    q2 = q2 - corner
    area = 0.5 * wp.abs(e1[0] * e2[1] - e2[0] * e1[1])
    if area < DEGENERATE_AREA_TEXELS or single_texel:
        c = (q0 + q1 + q2) / 3.0
        tx = texel(i_lo + int(wp.floor(c[0])), m, wrap)
        ty = texel(j_lo + int(wp.floor(c[1])), m, wrap)
        add_to_texel(dep, tx, ty, inv_texel_area)
        return
    px = vec8()
    py = vec8()
    px[0] = q0[0]
    py[0] = q0[1]
    px[1] = q1[0]
    py[1] = q1[1]
    px[2] = q2[0]
    py[2] = q2[1]
    for ci in range(i_hi - i_lo + 1):
        cx, cy, cn = clip_to_slab(px, py, 3, 0, float(ci), float(ci + 1))
        if cn < 3:
            continue
        # Only the rows this column's piece of the footprint spans.
        y_min = cy[0]
        y_max = cy[0]
        for v in range(1, cn):
            y_min = wp.min(y_min, cy[v])
            y_max = wp.max(y_max, cy[v])
        for cj in range(wp.max(int(wp.floor(y_min)), 0), wp.min(int(wp.floor(y_max)), j_hi - j_lo) + 1):
            rx, ry, rn = clip_to_slab(cx, cy, cn, 1, float(cj), float(cj + 1))
            if rn >= 3:
                w = polygon_area(rx, ry, rn) / area * inv_texel_area
                add_to_texel(dep, texel(i_lo + ci, m, wrap), texel(j_lo + cj, m, wrap), w)


@wp.func
def carries_flux(flux_w_nm: wp.array4d[wp.float32], iy: int, ix: int, half: int, k_begin: int,
                 k_count: int) -> int:
    """1 if triangle (iy, ix, half) delivers flux in any band of its index group: one facing away
    from the light, fully reflected or fully absorbed has nothing to spread."""
    for j in range(k_count):
        if flux_w_nm[iy, ix, half, k_begin + j] > 0.0:
            return 1
    return 0


@wp.func
def footprint(hit_xy: wp.array3d[wp.vec2], g: int, iy: int, ix: int, half: int, extent_m: float,
              periodic: int, floor_map: FloorMap, m: int):
    """Triangle (iy, ix, half)'s floor footprint for index group g in texels of the M × M map: (q0,
    e1, e2), its corners q0, q0 + e1, q0 + e2. Corner 0 is wrapped into [0, M) on a whole periodic
    map (a whole-period shift leaves the periodic deposit unchanged and keeps indices small), taken
    at its periodic image nearest a window of a periodic sea; the edges are taken in metres first so
    their precision does not depend on where the footprint lies."""
    n = hit_xy.shape[1]
    x0, y0, s0 = quad_corner(ix, iy, half, 0, n, extent_m, periodic)
    x1, y1, s1 = quad_corner(ix, iy, half, 1, n, extent_m, periodic)
    x2, y2, s2 = quad_corner(ix, iy, half, 2, n, extent_m, periodic)
    scale = floor_map.scale
    a = hit_xy[g, y0, x0] + s0
    e1 = (hit_xy[g, y1, x1] + s1 - a) * scale
    e2 = (hit_xy[g, y2, x2] + s2 - a) * scale
    if periodic != 0 and floor_map.wrap == 0:
        a = a - extent_m * wp.vec2(wp.round((a[0] - floor_map.centre[0]) / extent_m),
                                   wp.round((a[1] - floor_map.centre[1]) / extent_m))
    q0 = (a - floor_map.origin) * scale
    if floor_map.wrap != 0:
        q0 = wp.vec2(wrap_coord(q0[0], m), wrap_coord(q0[1], m))
    return q0, e1, e2


@wp.kernel
def texels_to_bands(floor_texels: wp.array3d[wp.float32], floor_irradiance: wp.array3d[wp.float32]):
    """(M, M, K) accumulation layout → (K, M, M) band images."""
    ty, tx = wp.tid()
    for k in range(floor_texels.shape[2]):
        floor_irradiance[k, ty, tx] = floor_texels[ty, tx, k]
