"""The flux-ratio deposit by edge accumulation: exact area coverage at the cost of a footprint's edges.

Each surface triangle's flux is spread over its floor footprint, every texel getting overlap area /
footprint area of it (``fluxratio``'s module docstring). Clipping the footprint against each texel of
its box (``fluxratio.spread_triangle``) costs its area in texels, and on the field comparisons' fine
grids the footprints are large: rays from millimetre waves cross many times on their way down, so at
3.2 m a 3.9 mm cell's footprint spans hundreds of 2 mm texels, thousands from a low sky direction
(docs/benchmarks.md), and the deposit was most of such a frame.

Here the footprint is rasterised by its edges instead, as font renderers accumulate coverage (the
signed-area accumulation of libart and FreeType's grey rasteriser; R. Levien's font-rs, 2016): each
edge, walked row band by row band, adds to the cells it crosses the exact area to its right within
them and to the next cell the rest of its height, into a per-row *difference* buffer; a prefix sum
along each row (:func:`cover_to_bands`) then gives every texel its covered area. A closed polygon's
differences in each row band sum to zero, so the coverage ends at its far edge, and the sum over
many footprints is the sum of their coverages: the same exact overlap as clipping (to rounding),
for the cells the edges cross — the perimeter in texels, not the area. A footprint of a few texels
is still clipped (``fluxratio.spread_triangle``) into a texel buffer added at the end: for so few
the edges make as many atomic adds and more arithmetic.

Maps: on a window (``wrap = 0``) an edge left of the window stands on its left side (everything to
its right is covered), one right of it is dropped, rows outside it are skipped. On a whole periodic
map (``wrap = 1``) a column index i is stored at i mod M; a footprint reaching j periods to the right
of its start would leave the cover it carries over the seam out of the prefix sum, so each difference
stored from period j also takes j times itself off the row's ``carry``, where the prefix sum starts
(for a difference array a with Σa = 0, Σ_k cov(c + kM) = Σ_{i≤c} Σ_k a[i + kM] − Σ_j j A_j, A_j the
sum over period j). Rows wrap directly. Each edge piece's shares are formed in float64 and its last
share is what the others left of its height (the heights taken in float64, where the difference of
two float32 ends is exact), so a footprint's differences cancel along the row before each is rounded
once into the float32 buffer; the carry and the prefix sums are float64. What is left beyond a
footprint is float32 rounding of single adds, not of the footprint's geometry.
"""

import warp as wp

from warpcaustics.kernels.caustics.fluxratio import (
    DEGENERATE_AREA_TEXELS,
    FloorMap,
    TriangleDeposit,
    carries_flux,
    footprint,
    spread_triangle,
)

wp.set_module_options({"enable_backward": False})

CLIPPED_BOX = 16
"""Footprints whose box holds at most this many texels are clipped texel by texel (as many atomic
adds as the edges would make, and less arithmetic: ``python -m benchmarks.deposit``)."""

REACH_CELLS = 32
"""Side of the blocks of surface quads that :func:`block_reach` culls by (in quads)."""


@wp.struct
class CoverDeposit:
    """Where one surface triangle (iy, ix, half)'s flux goes: ``flux_w_nm[iy, ix, half, k]`` for the
    bands ``k_begin`` … ``k_begin + k_count − 1`` of its index group, as differences along the rows
    of ``cover`` (M, M, K) and ``carry`` (M, K, float64) (the module docstring), or into ``texels``."""

    cover: wp.array3d[wp.float32]
    carry: wp.array2d[wp.float64]
    texels: wp.array3d[wp.float32]
    """(M, M, K) the small footprints' overlaps, clipped texel by texel and added directly."""
    flux_w_nm: wp.array4d[wp.float32]
    k_begin: int
    k_count: int
    iy: int
    ix: int
    half: int


@wp.func
def add_difference(dep: CoverDeposit, row: int, col: int, value: wp.float64, m: int, wrap: int):
    """Add ``value`` × the triangle's flux to the difference at (row, col) of every band of its group:
    col taken modulo M with the carry's correction when ``wrap``, dropped past the map otherwise."""
    period = int(0)
    if wrap != 0:
        period = col // m
        col -= period * m
        if col < 0:  # floor division, whichever way the integer division rounds
            period -= 1
            col += m
    elif col >= m:
        return
    for j in range(dep.k_count):
        k = dep.k_begin + j
        amount = value * wp.float64(dep.flux_w_nm[dep.iy, dep.ix, dep.half, k])
        wp.atomic_add(dep.cover, row, col, k, wp.float32(amount))
        if period != 0:
            wp.atomic_add(dep.carry, row, k, -wp.float64(period) * amount)


@wp.func
def cover_piece(dep: CoverDeposit, row: int, x0: float, x1: float, d: wp.float64, col0: int, m: int,
                wrap: int):
    """A straight piece of an edge within one row band, from x0 to x1 (x0 ≤ x1, texels relative to
    column ``col0``), of signed height ``d`` (times the weight): the area to its right within each
    cell it crosses, the rest of ``d`` to the cell after (font-rs's accumulation). The last share is
    what the others left of ``d``, so that the piece's shares sum to ``d`` to float64 rounding
    whatever the float32 geometry's: the row's differences cancel beyond the footprint (each then
    rounded once, into the float32 buffer)."""
    x0_floor = wp.floor(x0)
    i0 = int(x0_floor)
    x1_ceil = wp.ceil(x1)
    i1 = int(x1_ceil)
    if i1 <= i0 + 1:  # within one cell: the part of it right of the piece's mid-point
        first = d * wp.float64(1.0 - (0.5 * (x0 + x1) - x0_floor))
        add_difference(dep, row, col0 + i0, first, m, wrap)
        add_difference(dep, row, col0 + i0 + 1, d - first, m, wrap)
        return
    s = 1.0 / (x1 - x0)
    f0 = x0 - x0_floor
    a0 = 0.5 * s * (1.0 - f0) * (1.0 - f0)  # the first cell's triangle right of the piece
    f1 = x1 - x1_ceil + 1.0
    am = 0.5 * s * f1 * f1  # the last cell's triangle left of it
    given = d * wp.float64(a0)
    add_difference(dep, row, col0 + i0, given, m, wrap)
    if i1 == i0 + 2:
        share = d * wp.float64(1.0 - a0 - am)
        add_difference(dep, row, col0 + i0 + 1, share, m, wrap)
        given += share
    else:
        a1 = s * (1.5 - f0)
        share = d * wp.float64(a1 - a0)
        add_difference(dep, row, col0 + i0 + 1, share, m, wrap)
        given += share
        full = d * wp.float64(s)
        for i in range(i0 + 2, i1 - 1):
            add_difference(dep, row, col0 + i, full, m, wrap)
            given += full
        a2 = a1 + float(i1 - i0 - 3) * s
        share = d * wp.float64(1.0 - a2 - am)
        add_difference(dep, row, col0 + i1 - 1, share, m, wrap)
        given += share
    add_difference(dep, row, col0 + i1, d - given, m, wrap)


@wp.func
def cover_segment(dep: CoverDeposit, row: int, xa: float, xb: float, d: wp.float64, col0: int, m: int,
                  wrap: int):
    """An edge's piece in one row band, from xa to xb [texels relative to ``col0``]; on a window the
    part left of it stands on its left side and the part right of it is dropped (x is linear in y
    along the piece, so each part's share of ``d`` is its share of the x range)."""
    lo = wp.min(xa, xb)
    hi = wp.max(xa, xb)
    if wrap != 0:
        cover_piece(dep, row, lo, hi, d, col0, m, wrap)
        return
    left = float(-col0)  # the window's sides in these coordinates
    right = float(m - col0)
    if lo >= right:
        return
    if hi <= left:
        cover_piece(dep, row, left, left, d, col0, m, wrap)
        return
    if hi <= lo:
        cover_piece(dep, row, lo, hi, d, col0, m, wrap)
        return
    inside = d
    if lo < left:
        beside = d * wp.float64((left - lo) / (hi - lo))
        cover_piece(dep, row, left, left, beside, col0, m, wrap)
        inside -= beside
    if hi > right:
        inside -= d * wp.float64((hi - right) / (hi - lo))
    cover_piece(dep, row, wp.max(lo, left), wp.min(hi, right), inside, col0, m, wrap)


@wp.func
def cover_edge(dep: CoverDeposit, a: wp.vec2, b: wp.vec2, weight: wp.float64, col0: int, row0: int, m: int,
               wrap: int):
    """Edge a → b of a footprint [texels relative to texel (col0, row0)], row band by row band;
    ``weight`` carries the orientation's sign (a footprint's area counts unsigned). Each band's
    height is taken in float64, where the difference of two float32 ends is exact, so that a
    footprint's edges cancel in every band."""
    if a[1] == b[1]:
        return  # a horizontal edge sweeps no area
    p0 = a
    p1 = b
    d = weight
    if a[1] > b[1]:
        p0 = b
        p1 = a
        d = -weight
    dxdy = (p1[0] - p0[0]) / (p1[1] - p0[1])
    x_lo = wp.min(p0[0], p1[0])
    x_hi = wp.max(p0[0], p1[0])
    j_lo = int(wp.floor(p0[1]))
    j_hi = int(wp.ceil(p1[1])) - 1
    if wrap == 0:  # only the window's rows
        j_lo = wp.max(j_lo, -row0)
        j_hi = wp.min(j_hi, m - 1 - row0)
    for j in range(j_lo, j_hi + 1):
        y_top = wp.max(float(j), p0[1])
        y_bottom = wp.min(float(j + 1), p1[1])
        if y_bottom <= y_top:
            continue
        xa = wp.clamp(p0[0] + (y_top - p0[1]) * dxdy, x_lo, x_hi)
        xb = wp.clamp(p0[0] + (y_bottom - p0[1]) * dxdy, x_lo, x_hi)
        row = row0 + j
        if wrap != 0:
            row = ((row % m) + m) % m
        cover_segment(dep, row, xa, xb, d * (wp.float64(y_bottom) - wp.float64(y_top)), col0, m, wrap)


@wp.func
def clipped(dep: CoverDeposit) -> TriangleDeposit:
    """The same triangle's deposit straight into ``dep.texels`` (``fluxratio.spread_triangle``)."""
    out = TriangleDeposit()
    out.floor_texels = dep.texels
    out.flux_w_nm = dep.flux_w_nm
    out.k_begin = dep.k_begin
    out.k_count = dep.k_count
    out.iy = dep.iy
    out.ix = dep.ix
    out.half = dep.half
    return out


@wp.func
def cover_triangle(dep: CoverDeposit, q0: wp.vec2, e1: wp.vec2, e2: wp.vec2, m: int, wrap: int,
                   max_clipped: int, inv_texel_area: float, coarse_count: wp.array[wp.int32]):
    """Spread ``dep``'s flux over the footprint (q0, q0 + e1, q0 + e2) [texels of an M × M map; q0
    within it when ``wrap``], each texel getting overlap area / footprint area × ``inv_texel_area``
    of it, by its edges. A footprint whose box holds at most CLIPPED_BOX texels is clipped texel by
    texel instead (``fluxratio.spread_triangle``: cheaper for so few, and its rules for a footprint
    within one texel, of no area, or whose box exceeds ``max_clipped`` texels, which goes by area
    samples counted in ``coarse_count``)."""
    q1 = q0 + e1
    q2 = q0 + e2
    u_lo = wp.floor(wp.min(q0[0], wp.min(q1[0], q2[0])))
    v_lo = wp.floor(wp.min(q0[1], wp.min(q1[1], q2[1])))
    u_hi = wp.floor(wp.max(q0[0], wp.max(q1[0], q2[0])))
    v_hi = wp.floor(wp.max(q0[1], wp.max(q1[1], q2[1])))
    if wrap == 0 and (u_hi < 0.0 or v_hi < 0.0 or u_lo > float(m - 1) or v_lo > float(m - 1)):
        return  # the footprint misses the window (one left of it covers as much as it uncovers)
    box = (u_hi - u_lo + 1.0) * (v_hi - v_lo + 1.0)
    if wrap == 0:  # only the texels inside the window
        box = (wp.min(u_hi, float(m - 1)) - wp.max(u_lo, 0.0) + 1.0) * (
            wp.min(v_hi, float(m - 1)) - wp.max(v_lo, 0.0) + 1.0)
    cross = e1[0] * e2[1] - e2[0] * e1[1]
    area = 0.5 * wp.abs(cross)
    if box <= float(CLIPPED_BOX) or box > float(max_clipped) or area < DEGENERATE_AREA_TEXELS:
        spread_triangle(clipped(dep), q0, e1, e2, m, wrap, max_clipped, inv_texel_area, coarse_count)
        return
    # Coordinates relative to the box's first texel keep the arithmetic small.
    corner = wp.vec2(u_lo, v_lo)
    col0 = int(u_lo)
    row0 = int(v_lo)
    weight = wp.float64(inv_texel_area) / wp.float64(area)
    if cross > 0.0:
        weight = -weight  # counter-clockwise: its edges going down in y sweep its outside
    cover_edge(dep, q0 - corner, q1 - corner, weight, col0, row0, m, wrap)
    cover_edge(dep, q1 - corner, q2 - corner, weight, col0, row0, m, wrap)
    cover_edge(dep, q2 - corner, q0 - corner, weight, col0, row0, m, wrap)


@wp.kernel
def deposit_footprints(
    runs: wp.array[wp.vec2i],
    g: int,
    hit_xy: wp.array3d[wp.vec2],
    flux_w_nm: wp.array4d[wp.float32],
    wavelengths_per_group: int,
    extent_m: float,
    periodic: int,
    floor_map: FloorMap,
    cover: wp.array3d[wp.float32],
    carry: wp.array2d[wp.float64],
    texels: wp.array3d[wp.float32],
    coarse_count: wp.array[wp.int32],
):
    """Spread triangle (iy, ix, half)'s flux over its floor footprint for index group g, as row
    differences into ``cover`` (M, M, K) and ``carry`` (M, K), small footprints straight into
    ``texels`` (M, M, K) (:func:`cover_to_bands` sums them):
    texel (ty, tx) spans ``origin + [tx, tx+1] / scale`` in x. On a window of a periodic sea each
    footprint is taken at its periodic image nearest the window.

    The triangles are those of rows of quads: thread (r, cx, half) takes quad
    ``runs[r] + (0, cx)`` (iy, first ix + cx), past the last column none. The runs are every row of
    the blocks :func:`block_reach` found near the window (on the CPU a thread that returns at once
    still costs its launch, and the culled ones took most of a window's deposit), or every whole
    row, in row-major order either way, so that on the CPU, where a launch runs its threads in
    order, the map is the same to the bit whichever blocks are culled."""
    r, cx, half = wp.tid()
    run = runs[r]
    iy = run[0]
    ix = run[1] + cx
    if ix >= flux_w_nm.shape[1]:
        return
    m = cover.shape[0]
    k_begin = g * wavelengths_per_group
    if carries_flux(flux_w_nm, iy, ix, half, k_begin, wavelengths_per_group) == 0:
        return
    dep = CoverDeposit()
    dep.cover = cover
    dep.carry = carry
    dep.texels = texels
    dep.flux_w_nm = flux_w_nm
    dep.k_begin = k_begin
    dep.k_count = wavelengths_per_group
    dep.iy = iy
    dep.ix = ix
    dep.half = half
    q0, e1, e2 = footprint(hit_xy, g, iy, ix, half, extent_m, periodic, floor_map, m)
    scale = floor_map.scale
    cover_triangle(dep, q0, e1, e2, m, floor_map.wrap, floor_map.max_clipped, scale * scale, coarse_count)


@wp.func
def images_meet(lo: float, hi: float, window_lo: float, window_hi: float, period: float) -> int:
    """1 if some periodic image [lo, hi] + k·period (k an integer) meets [window_lo, window_hi]."""
    k_lo = wp.ceil((window_lo - hi) / period)
    k_hi = wp.floor((window_hi - lo) / period)
    if k_lo <= k_hi:
        return 1
    return 0


@wp.kernel
def block_reach(hit_xy: wp.array3d[wp.vec2], cells: int, extent_m: float, floor_map: FloorMap,
                reach: wp.array3d[wp.int32]):
    """Whether the footprints of a periodic sea's block of cells × cells quads (by, bx) can reach a
    window of the floor map, for index group g: the box of the block's floor hits (its vertices',
    across the patch's seam with the period added, so the box holds each of its footprints) or a
    periodic image of it meets the window widened by a texel. A culling for the deposit on a small
    window of a large patch (the field comparisons: 1 m of 8–32 m), where almost every footprint
    falls beside the window: it spares those triangles the deposit's arithmetic."""
    g, by, bx = wp.tid()
    n = hit_xy.shape[1]
    lo = wp.vec2(1.0e30, 1.0e30)
    hi = wp.vec2(-1.0e30, -1.0e30)
    for j in range(wp.min(cells, n - by * cells) + 1):
        for i in range(wp.min(cells, n - bx * cells) + 1):
            cx = bx * cells + i
            cy = by * cells + j
            shift = wp.vec2(0.0, 0.0)
            if cx >= n:
                cx -= n
                shift[0] = extent_m
            if cy >= n:
                cy -= n
                shift[1] = extent_m
            p = hit_xy[g, cy, cx] + shift
            lo = wp.min(lo, p)
            hi = wp.max(hi, p)
    texel_m = 1.0 / floor_map.scale
    window_lo = floor_map.origin - wp.vec2(texel_m, texel_m)
    window_hi = 2.0 * floor_map.centre - floor_map.origin + wp.vec2(texel_m, texel_m)
    reach[g, by, bx] = images_meet(lo[0], hi[0], window_lo[0], window_hi[0], extent_m) * images_meet(
        lo[1], hi[1], window_lo[1], window_hi[1], extent_m)


@wp.kernel
def cover_to_bands(cover: wp.array3d[wp.float32], carry: wp.array2d[wp.float64],
                   texels: wp.array3d[wp.float32], floor_irradiance: wp.array3d[wp.float32]):
    """Row ty of band k: the prefix sum of its differences from its carry, plus the clipped
    footprints' texels, into the (K, M, M) band images. Where no footprint reaches, the sum is zero
    to rounding, either side: an irradiance is never negative, so those are written as 0."""
    ty, k = wp.tid()
    total = carry[ty, k]
    for tx in range(cover.shape[1]):
        total += wp.float64(cover[ty, tx, k])
        value = total + wp.float64(texels[ty, tx, k])
        floor_irradiance[k, ty, tx] = wp.float32(wp.max(value, wp.float64(0.0)))
