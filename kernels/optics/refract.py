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


@wp.kernel
def view_weight(
    positions: wp.array2d[wp.vec3],
    hit_xy: wp.array3d[wp.vec2],
    path_m: wp.array3d[wp.float32],
    floor_z: float,
    axis: wp.vec3,
    cos_half: float,
    transmittance: wp.array3d[wp.float32],
):
    """A radiance sensor's cone (``floor.view_*``, caustics/view.py): scale vertex (iy, ix)'s
    transmittance for group g by 1/|t_z| where its refracted ray t arrives at the floor from within
    the cone about ``axis`` (−t·axis ≥ cos_half), by 0 elsewhere: the deposit then carries ∫ L dω
    over the cone instead of the irradiance."""
    g, iy, ix = wp.tid()
    v = positions[iy, ix]
    h = hit_xy[g, iy, ix]
    ell = path_m[g, iy, ix]
    w = float(0.0)
    if ell > 0.0:
        t = wp.vec3(h[0] - v[0], h[1] - v[1], floor_z - v[2]) / ell
        if -wp.dot(t, axis) >= cos_half and t[2] < 0.0:
            w = 1.0 / (-t[2])
    transmittance[g, iy, ix] = transmittance[g, iy, ix] * w


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


COARSE_CELLS = 64
FINE_CELLS = 8
"""Cells per side of the coarse and fine blocks whose highest vertex lets :func:`sun_visibility`
step over a block at once where its ray already runs above it."""


@wp.kernel
def block_heights(positions: wp.array2d[wp.vec3], cells: int, highest: wp.array2d[wp.float32]):
    """highest[by, bx] = the highest vertex a bilinear lookup whose cell corner (i0, j0) lies in
    block (bx, by) (i0 // cells = bx) can touch, with one vertex more on every side (so that a
    lookup one cell out, by rounding, is covered too); indices wrap (on a walled surface that only
    adds vertices: still an upper bound)."""
    by, bx = wp.tid()
    n = positions.shape[0]
    top = float(-1.0e30)
    for j in range(by * cells - 1, by * cells + cells + 2):
        for i in range(bx * cells - 1, bx * cells + cells + 2):
            top = wp.max(top, positions[((j % n) + n) % n, ((i % n) + n) % n][2])
    highest[by, bx] = top


@wp.func
def clear_steps(highest: wp.array2d[wp.float32], cells: int, i0: int, j0: int, u: float, v: float,
                du: float, dv: float, z: float) -> int:
    """How many steps the ray at lookup (u, v) (cell corner (i0, j0), wrapped), height z, can take
    without a lookup that could hide the sun: 0 if its block of ``cells`` may reach z; else the
    steps (≥ 1) before its lookups leave the block, whose heights lie under z, while z only rises.
    ``du``, ``dv``: the lookup's move per step."""
    bx = i0 / cells
    by = j0 / cells
    top = highest[by, bx]
    if top + 1.0e-6 * (wp.abs(top) + wp.abs(z)) >= z:  # the bilinear lookup's rounding, with room
        return 0
    lo_u = wp.floor(u) - float(i0 - bx * cells)  # the block's first lookup corner, unwrapped
    lo_v = wp.floor(v) - float(j0 - by * cells)
    k = float(1.0e9)
    if du > 0.0:
        k = (lo_u + float(cells) - u) / du
    elif du < 0.0:
        k = (u - lo_u) / (-du)
    if dv > 0.0:
        k = wp.min(k, (lo_v + float(cells) - v) / dv)
    elif dv < 0.0:
        k = wp.min(k, (v - lo_v) / (-dv))
    return wp.max(1, int(wp.min(k, 1.0e9)))


@wp.kernel
def sun_visibility(
    positions: wp.array2d[wp.vec3],
    sun_dir: wp.vec3,
    extent_m: float,
    periodic: int,
    z_range: wp.array[wp.float32],
    coarse: wp.array2d[wp.float32],
    fine: wp.array2d[wp.float32],
    visible: wp.array2d[wp.float32],
):
    """1 where the sun is seen from vertex (iy, ix), 0 where a crest of the surface hides it.

    Marches from the vertex towards the sun in half-cell horizontal steps over the periodic height
    field until the ray rises above the highest crest. Where the ray already runs above the highest
    vertex of the block of cells it is crossing (``coarse`` and ``fine``: :func:`block_heights` with
    ``COARSE_CELLS``, ``FINE_CELLS``), the steps to the block's edge are taken at once: no lookup there could
    hide the sun, so the answer is the step-by-step march's (tested against it, to the bit) at a
    fraction of its lookups where rays graze a wide sea at a low sun.
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
    du = step * sun_dir[0] * float(n) / extent_m  # the lookup's move per step, in cells
    dv = step * sun_dir[1] * float(n) / extent_m
    i = int(1)
    while i <= steps:
        q = p + (float(i) * step) * sun_dir
        if periodic == 0 and (wp.abs(q[0]) > 0.5 * extent_m - 0.5 * cell
                              or wp.abs(q[1]) > 0.5 * extent_m - 0.5 * cell):
            return  # the ray leaves a walled pool over its rim: nothing more to hide the sun
        i0, j0, i1, j1, tu, tv = bilinear_cell(n, extent_m, q[0], q[1])
        u = (q[0] + 0.5 * extent_m) * float(n) / extent_m - 0.5
        v = (q[1] + 0.5 * extent_m) * float(n) / extent_m - 0.5
        z = q[2] + tolerance
        skip = clear_steps(coarse, COARSE_CELLS, i0, j0, u, v, du, dv, z)
        if skip == 0:
            skip = clear_steps(fine, FINE_CELLS, i0, j0, u, v, du, dv, z)
        if skip > 0:
            i += skip
            continue
        if bilerp(positions[j0, i0][2], positions[j0, i1][2], positions[j1, i0][2], positions[j1, i1][2],
                  tu, tv) > z:
            visible[iy, ix] = 0.0
            return
        i += 1
