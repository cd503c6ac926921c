"""Tile binning of beams over a horizontal plane (floor texels, receiver points) and over the
screen (the volume pass): tile spans, oriented boxes, per-tile lists.

Binning (Laine & Karras 2011; Kerbl et al. 2023): every beam (or periodic copy of a beam) gets a
span of tiles, tiles count their beams (atomics), an exclusive scan gives each tile's start, and
a scatter fills the per-tile lists; each query (texel, receiver point, pixel) then loops only over
its tile's list and adds up additively, so the order of beams never matters except for rounding.
On the GPU the order inside a tile follows the atomics, so sums may differ in the last bits from
run to run; on the CPU launches are serial and the result is deterministic.
"""

import warp as wp

from warpcaustics.kernels.caustics.beams.bounds import bound_corners
from warpcaustics.kernels.caustics.beams.section import copy_offset, safe_area, section_vertex, shadow_slack
from warpcaustics.kernels.scene.camera.pinhole import PinholeCamera

wp.set_module_options({"enable_backward": False})


@wp.struct
class TileGrid:
    """Tiles over a plane: tile (i, j) covers ``origin + [i, i+1) size`` × ``[j, j+1) size``."""

    origin: wp.vec2
    size: wp.vec2
    nx: int
    ny: int
    wrap: int
    """1: indices wrap (a periodic sea); 0: clamped to the grid."""


@wp.func
def tile_index(grid: TileGrid, i: int, j: int) -> int:
    if grid.wrap != 0:
        i = ((i % grid.nx) + grid.nx) % grid.nx
        j = ((j % grid.ny) + grid.ny) % grid.ny
    return j * grid.nx + i


@wp.func
def tile_of(grid: TileGrid, p: wp.vec2) -> int:
    i = int(wp.floor((p[0] - grid.origin[0]) / grid.size[0]))
    j = int(wp.floor((p[1] - grid.origin[1]) / grid.size[1]))
    if grid.wrap == 0:  # a walled pool: points on the walls belong to the edge tiles
        i = wp.clamp(i, 0, grid.nx - 1)
        j = wp.clamp(j, 0, grid.ny - 1)
    return tile_index(grid, i, j)


@wp.func
def set_span(grid: TileGrid, lo: wp.vec2, hi: wp.vec2, spans: wp.array2d[wp.int32], b: int):
    """Store the tile range covering the box [lo, hi]: (i0, j0, i1, j1), or an empty range."""
    i0 = int(wp.floor((lo[0] - grid.origin[0]) / grid.size[0]))
    j0 = int(wp.floor((lo[1] - grid.origin[1]) / grid.size[1]))
    i1 = int(wp.floor((hi[0] - grid.origin[0]) / grid.size[0]))
    j1 = int(wp.floor((hi[1] - grid.origin[1]) / grid.size[1]))
    if grid.wrap != 0:
        if i1 - i0 >= grid.nx:
            i0 = 0
            i1 = grid.nx - 1
        if j1 - j0 >= grid.ny:
            j0 = 0
            j1 = grid.ny - 1
    else:
        i0 = wp.max(i0, 0)
        j0 = wp.max(j0, 0)
        i1 = wp.min(i1, grid.nx - 1)
        j1 = wp.min(j1, grid.ny - 1)
    spans[b, 0] = i0
    spans[b, 1] = j0
    spans[b, 2] = i1
    spans[b, 3] = j1


@wp.func
def empty_span(spans: wp.array2d[wp.int32], b: int):
    spans[b, 0] = 0
    spans[b, 1] = 0
    spans[b, 2] = -1
    spans[b, 3] = -1


@wp.kernel
def horizontal_spans(
    grid: TileGrid,
    base: wp.array2d[wp.vec3],
    direction: wp.array2d[wp.vec3],
    end_m: wp.array2d[wp.float32],
    weight: wp.array[wp.float32],
    area_coef: wp.array[wp.vec3],
    query_lo_z: float,
    query_hi_z: float,
    spans: wp.array2d[wp.int32],
):
    """Tiles of the horizontal grid that the beam's sections between the query heights touch (the
    sections are linear in z, so the box of the two end sections bounds them all)."""
    b = wp.tid()
    if weight[b] <= 0.0:
        empty_span(spans, b)
        return
    top = wp.max(base[b, 0][2], wp.max(base[b, 1][2], base[b, 2][2]))
    bottom = top
    for i in range(3):
        bottom = wp.min(bottom, base[b, i][2] + end_m[b, i] * direction[b, i][2])
    # Points up to shadow_slack beyond the end are lit: reach below the lowest end by twice that.
    v_mean = (base[b, 0][2] + base[b, 1][2] + base[b, 2][2]) / 3.0
    bottom = bottom - 2.0 * shadow_slack(safe_area(area_coef[b], bottom, v_mean))
    hi_z = wp.min(top, query_hi_z)
    lo_z = wp.max(bottom, query_lo_z)
    if lo_z > hi_z:
        empty_span(spans, b)
        return
    lo = wp.vec2(1.0e30)
    hi = wp.vec2(-1.0e30)
    for i in range(3):
        for k in range(2):
            z = lo_z
            if k == 1:
                z = hi_z
            q = section_vertex(base[b, i], direction[b, i], z)
            lo = wp.min(lo, q)
            hi = wp.max(hi, q)
    set_span(grid, lo, hi, spans, b)


@wp.func
def perp(axis: wp.vec2) -> wp.vec2:
    return wp.vec2(-axis[1], axis[0])


@wp.func
def in_frame(q: wp.vec2, axis: wp.vec2) -> wp.vec2:
    """q in the frame (axis, perp(axis))."""
    return wp.vec2(wp.dot(q, axis), wp.dot(q, perp(axis)))


@wp.func
def tile_in_box(grid: TileGrid, i: int, j: int, axis: wp.vec2, lo: wp.vec2, hi: wp.vec2) -> bool:
    """Whether tile (i, j) overlaps the oriented box [lo, hi] in the frame (axis, perp(axis))
    (separating axes of the box; the tile's own axes are covered by the span)."""
    x0 = grid.origin[0] + float(i) * grid.size[0]
    y0 = grid.origin[1] + float(j) * grid.size[1]
    c0 = in_frame(wp.vec2(x0, y0), axis)
    c1 = in_frame(wp.vec2(x0 + grid.size[0], y0), axis)
    c2 = in_frame(wp.vec2(x0, y0 + grid.size[1]), axis)
    c3 = in_frame(wp.vec2(x0 + grid.size[0], y0 + grid.size[1]), axis)
    mn = wp.min(wp.min(c0, c1), wp.min(c2, c3))
    mx = wp.max(wp.max(c0, c1), wp.max(c2, c3))
    return not (mx[0] < lo[0] or mn[0] > hi[0] or mx[1] < lo[1] or mn[1] > hi[1])


@wp.func
def listed(
    grid: TileGrid,
    i: int,
    j: int,
    use_boxes: int,
    box_axis: wp.array[wp.vec2],
    box_lo: wp.array[wp.vec2],
    box_hi: wp.array[wp.vec2],
    b: int,
) -> bool:
    if use_boxes == 0:
        return True
    return tile_in_box(grid, i, j, box_axis[b], box_lo[b], box_hi[b])


@wp.kernel
def bin_tiles(
    grid: TileGrid,
    spans: wp.array2d[wp.int32],
    use_boxes: int,
    box_axis: wp.array[wp.vec2],
    box_lo: wp.array[wp.vec2],
    box_hi: wp.array[wp.vec2],
    scatter: int,
    tile_start: wp.array[wp.int32],
    tile_fill: wp.array[wp.int32],
    tile_items: wp.array[wp.int32],
):
    """Each tile of an item's span (that its oriented box touches, with ``use_boxes``) takes the
    item: ``scatter == 0`` only counts it in ``tile_fill``; ``scatter == 1`` also writes it at
    ``tile_start[t]`` plus its place in the tile's count."""
    b = wp.tid()
    for j in range(spans[b, 1], spans[b, 3] + 1):
        for i in range(spans[b, 0], spans[b, 2] + 1):
            if listed(grid, i, j, use_boxes, box_axis, box_lo, box_hi, b):
                t = tile_index(grid, i, j)
                slot = wp.atomic_add(tile_fill, t, 1)
                if scatter != 0:
                    tile_items[tile_start[t] + slot] = b


# --- screen tiles -------------------------------------------------------------------------------


NEAR_M = 1.0e-3
"""Camera-space depth of the near plane that bounding volumes are clipped against [m]."""


@wp.func
def screen_xy(cam: PinholeCamera, x: wp.vec3, depth: float) -> wp.vec2:
    """Continuous pixel coordinates of x at camera-space depth ``depth`` (> 0), kept finite."""
    v = x - cam.position
    px = (wp.dot(v, cam.right) / (depth * cam.tan_half_fov * cam.aspect) + 1.0) * 0.5 * float(cam.width)
    py = (1.0 - wp.dot(v, cam.up) / (depth * cam.tan_half_fov)) * 0.5 * float(cam.height)
    return wp.vec2(wp.clamp(px, -1.0e6, 1.0e6), wp.clamp(py, -1.0e6, 1.0e6))


@wp.func
def hull_edge(cam: PinholeCamera, a: wp.vec3, b: wp.vec3, axis: wp.vec2, lo: wp.vec2, hi: wp.vec2):
    """Grow the box [lo, hi], in the screen frame (axis, perp(axis)), by the projection of the part
    of segment ab in front of the near plane."""
    za = wp.dot(a - cam.position, cam.forward)
    zb = wp.dot(b - cam.position, cam.forward)
    if za > NEAR_M:
        q = in_frame(screen_xy(cam, a, za), axis)
        lo = wp.min(lo, q)
        hi = wp.max(hi, q)
    if (za > NEAR_M) != (zb > NEAR_M):
        x = a + ((NEAR_M - za) / (zb - za)) * (b - a)
        q = in_frame(screen_xy(cam, x, NEAR_M), axis)
        lo = wp.min(lo, q)
        hi = wp.max(hi, q)
    return lo, hi


@wp.func
def volume_box(cam: PinholeCamera, lower: wp.mat33, upper: wp.mat33, axis: wp.vec2):
    """The box, in the screen frame (axis, perp(axis)), of a convex volume given by its lower and
    upper triangles and the corner lines joining them (:func:`bound_corners`), clipped to the near
    plane: every edge's projected part in front of it."""
    lo = wp.vec2(1.0e30)
    hi = wp.vec2(-1.0e30)
    for i in range(3):
        i1 = (i + 1) % 3
        lo, hi = hull_edge(cam, lower[i], upper[i], axis, lo, hi)
        lo, hi = hull_edge(cam, lower[i], lower[i1], axis, lo, hi)
        lo, hi = hull_edge(cam, upper[i], upper[i1], axis, lo, hi)
    return lo, hi


@wp.kernel
def screen_spans(
    grid: TileGrid,
    cam: PinholeCamera,
    base: wp.array2d[wp.vec3],
    direction: wp.array2d[wp.vec3],
    end_m: wp.array2d[wp.float32],
    weight: wp.array[wp.float32],
    copies: int,
    extent_m: float,
    bounds: int,
    spans: wp.array2d[wp.int32],
    box_axis: wp.array[wp.vec2],
    box_lo: wp.array[wp.vec2],
    box_hi: wp.array[wp.vec2],
    box_pixels: wp.array[wp.float32],
    tally: wp.array[wp.int32],
):
    """Screen bounds of each beam copy ``b · copies² + c``: the tile span of the screen box of its
    bounding volume (``bounds``: ``bounds.HULL``, ``PRISM`` or ``ERNST``) and an oriented box
    along the beam's projected axis (base centroid → end centroid) that the tiles and pixels are
    then tested against. ``box_pixels``: pixels of the axis-aligned box; ``tally[3]`` counts the
    beam copies whose prism fell back to the hull."""
    item = wp.tid()
    per_beam = copies * copies
    b = item / per_beam
    box_axis[item] = wp.vec2(1.0, 0.0)
    box_lo[item] = wp.vec2(1.0)
    box_hi[item] = wp.vec2(-1.0)
    box_pixels[item] = 0.0
    if weight[b] <= 0.0:
        empty_span(spans, item)
        return
    shift = copy_offset(item % per_beam, copies, extent_m)
    lower, upper, used = bound_corners(base, direction, end_m, b, shift, bounds)
    if used == 0:
        wp.atomic_add(tally, 3, 1)
    lo, hi = volume_box(cam, lower, upper, wp.vec2(1.0, 0.0))
    w = float(cam.width)
    h = float(cam.height)
    if lo[0] > hi[0] or hi[0] < 0.0 or hi[1] < 0.0 or lo[0] >= w or lo[1] >= h:
        empty_span(spans, item)
        return
    lo = wp.max(lo, wp.vec2(0.0))
    hi = wp.min(hi, wp.vec2(w - 1.0e-3, h - 1.0e-3))
    box_pixels[item] = (wp.floor(hi[0]) - wp.floor(lo[0]) + 1.0) * (wp.floor(hi[1]) - wp.floor(lo[1]) + 1.0)
    set_span(grid, lo, hi, spans, item)
    # The beam's axis on the screen, when both centroids are in front of the camera.
    axis = wp.vec2(1.0, 0.0)
    cb = (base[b, 0] + base[b, 1] + base[b, 2]) / 3.0 + shift
    ce = cb
    for i in range(3):
        ce += end_m[b, i] * direction[b, i] / 3.0
    zb = wp.dot(cb - cam.position, cam.forward)
    ze = wp.dot(ce - cam.position, cam.forward)
    if zb > NEAR_M and ze > NEAR_M:
        delta = screen_xy(cam, ce, ze) - screen_xy(cam, cb, zb)
        if wp.length(delta) > 1.0:
            axis = wp.normalize(delta)
    olo, ohi = volume_box(cam, lower, upper, axis)
    box_axis[item] = axis
    box_lo[item] = olo
    box_hi[item] = ohi
