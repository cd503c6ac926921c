"""Shared geometry and optics helpers (``@wp.func``) used by the stage kernels."""

import warp as wp

wp.set_module_options({"enable_backward": False})

vec8 = wp.types.vector(length=8, dtype=wp.float32)
"""Up to eight polygon coordinates: a triangle clipped by two slabs has at most seven vertices."""


@wp.func
def cell_centre(ix: int, iy: int, n: int, extent_m: float) -> wp.vec2:
    """(x, y) [m] of cell (ix, iy) of an n×n grid over the patch: ``(i + 0.5) L/n - L/2``."""
    cell = extent_m / float(n)
    return wp.vec2((float(ix) + 0.5) * cell - 0.5 * extent_m, (float(iy) + 0.5) * cell - 0.5 * extent_m)


@wp.func
def normal_from_slopes(dh_dx: float, dh_dy: float) -> wp.vec3:
    """Unit upward normal of a height field z = h(x, y) with the given slopes."""
    return wp.normalize(wp.vec3(-dh_dx, -dh_dy, 1.0))


@wp.func
def bilinear_cell(n: int, extent_m: float, x: float, y: float):
    """Periodic bilinear lookup on an n×n cell-centre grid: corner indices (i0, j0, i1, j1) and
    fractions (tu, tv) for the point (x, y) [m]."""
    u = (x + 0.5 * extent_m) * float(n) / extent_m - 0.5
    v = (y + 0.5 * extent_m) * float(n) / extent_m - 0.5
    fu = wp.floor(u)
    fv = wp.floor(v)
    i0 = ((int(fu) % n) + n) % n
    j0 = ((int(fv) % n) + n) % n
    return i0, j0, (i0 + 1) % n, (j0 + 1) % n, u - fu, v - fv


@wp.func
def grid_cell(n: int, extent_m: float, periodic: int, x: float, y: float):
    """:func:`bilinear_cell` on a grid that wraps when ``periodic`` and is clamped to its outer
    cell centres otherwise."""
    if periodic != 0:
        return bilinear_cell(n, extent_m, x, y)
    u = wp.clamp((x + 0.5 * extent_m) * float(n) / extent_m - 0.5, 0.0, float(n - 1))
    v = wp.clamp((y + 0.5 * extent_m) * float(n) / extent_m - 0.5, 0.0, float(n - 1))
    i0 = wp.min(int(wp.floor(u)), n - 1)
    j0 = wp.min(int(wp.floor(v)), n - 1)
    return i0, j0, wp.min(i0 + 1, n - 1), wp.min(j0 + 1, n - 1), u - float(i0), v - float(j0)


@wp.func
def grid_bilinear(grid: wp.array2d[wp.vec3], extent_m: float, periodic: int, x: float, y: float) -> wp.vec3:
    """Bilinear sample of a cell-centre vec3 grid at (x, y) [m] (:func:`grid_cell`)."""
    i0, j0, i1, j1, tu, tv = grid_cell(grid.shape[0], extent_m, periodic, x, y)
    return (1.0 - tv) * ((1.0 - tu) * grid[j0, i0] + tu * grid[j0, i1]) + tv * (
        (1.0 - tu) * grid[j1, i0] + tu * grid[j1, i1]
    )


@wp.func
def scalar_bilinear(
    grid: wp.array2d[wp.float32], extent_m: float, periodic: int, x: float, y: float
) -> float:
    """Bilinear sample of a cell-centre scalar grid at (x, y) [m] (:func:`grid_cell`)."""
    i0, j0, i1, j1, tu, tv = grid_cell(grid.shape[0], extent_m, periodic, x, y)
    return bilerp(grid[j0, i0], grid[j0, i1], grid[j1, i0], grid[j1, i1], tu, tv)


@wp.func
def bilerp(a: float, b: float, c: float, d: float, tu: float, tv: float) -> float:
    """(1-tv)((1-tu) a + tu b) + tv((1-tu) c + tu d): a, b on row j0; c, d on row j1."""
    return (1.0 - tv) * ((1.0 - tu) * a + tu * b) + tv * ((1.0 - tu) * c + tu * d)


@wp.func
def refract(d: wp.vec3, n: wp.vec3, eta: float) -> wp.vec3:
    """Snell's law in vector form; ``eta = n1/n2``, ``n`` faces against ``d``. Zero vector on TIR."""
    c = -wp.dot(n, d)
    k = 1.0 - eta * eta * (1.0 - c * c)
    if k < 0.0:
        return wp.vec3(0.0)
    return eta * d + (eta * c - wp.sqrt(k)) * n


@wp.func
def fresnel_transmittance(cos_i: float, eta: float) -> float:
    """Exact unpolarised Fresnel transmittance ``1 - (Rs + Rp)/2`` (Born & Wolf §1.5.2).

    ``cos_i`` is the cosine of the incidence angle, ``eta = n1/n2``. Returns 0 on total internal
    reflection and for light arriving from behind the surface (``cos_i <= 0``).
    """
    if cos_i <= 0.0:
        return 0.0
    k = 1.0 - eta * eta * (1.0 - cos_i * cos_i)
    if k <= 0.0:
        return 0.0
    cos_t = wp.sqrt(k)
    rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t)
    rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t)
    return 1.0 - 0.5 * (rs * rs + rp * rp)


MIN_DOWNWARD_COS = 1.0e-3
"""A refracted ray must descend at least this steeply (|d_z|) to be followed to a receiver."""


@wp.func
def sun_into_water(normal: wp.vec3, sun_dir: wp.vec3, eta: float):
    """The sun refracted into the water at a surface point with unit ``normal``: (unit direction,
    Fresnel transmittance). Light from behind the surface (n·s <= 0), total internal reflection or
    a ray that would not descend give (straight down, 0), so it carries nothing but stays finite."""
    cos_i = wp.dot(normal, sun_dir)
    t = wp.vec3(0.0, 0.0, -1.0)
    transmitted = float(0.0)
    if cos_i > 0.0:
        d = refract(-sun_dir, normal, eta)
        if d[2] < -MIN_DOWNWARD_COS:
            t = wp.normalize(d)
            transmitted = fresnel_transmittance(cos_i, eta)
    return t, transmitted


@wp.func
def clip_side(px: vec8, py: vec8, count: int, nx: float, ny: float, c: float):
    """Sutherland–Hodgman step: keep the part of polygon (px, py) where nx x + ny y + c >= 0.
    Returns the clipped polygon and its vertex count."""
    qx = vec8()
    qy = vec8()
    m = int(0)
    for j in range(count):
        jn = (j + 1) % count
        sa = nx * px[j] + ny * py[j] + c
        sb = nx * px[jn] + ny * py[jn] + c
        if sa >= 0.0:
            qx[m] = px[j]
            qy[m] = py[j]
            m += 1
        if (sa >= 0.0) != (sb >= 0.0):
            t = sa / (sa - sb)
            qx[m] = px[j] + t * (px[jn] - px[j])
            qy[m] = py[j] + t * (py[jn] - py[j])
            m += 1
    return qx, qy, m


@wp.func
def clip_half_plane(px: vec8, py: vec8, count: int, axis: int, bound: float, keep_above: bool):
    """Keep the part of polygon ``(px, py)`` on one side of the line ``x = bound`` (``axis == 0``)
    or ``y = bound`` (``axis == 1``); ``keep_above`` keeps coordinates ``>= bound``."""
    sign = float(1.0)
    if not keep_above:
        sign = -1.0
    if axis == 0:
        return clip_side(px, py, count, sign, 0.0, -sign * bound)
    return clip_side(px, py, count, 0.0, sign, -sign * bound)


@wp.func
def clip_to_slab(px: vec8, py: vec8, count: int, axis: int, lo: float, hi: float):
    """Clip a polygon to the slab ``lo <= coordinate <= hi`` along ``axis``."""
    qx, qy, m = clip_half_plane(px, py, count, axis, lo, True)
    if m == 0:
        return qx, qy, m
    return clip_half_plane(qx, qy, m, axis, hi, False)


@wp.func
def polygon_area(px: vec8, py: vec8, count: int) -> float:
    """Unsigned shoelace area of a simple polygon."""
    s = float(0.0)
    for j in range(count):
        jn = (j + 1) % count
        s += px[j] * py[jn] - px[jn] * py[j]
    return 0.5 * wp.abs(s)
