"""Crest shading of a periodic surface by a sweep along the light's azimuth (two kernels).

A vertex p sees the light when no point of the surface ahead of it along the light's azimuth rises
above the ray: with â the light's horizontal direction, k the ray's rise per horizontal metre and δ
the step, the march (``refract.sun_visibility``) tests h(p + iδâ) − iδk > h(p) for i = 1, 2, … .
The largest of those, M(p), obeys along any line parallel to â the recurrence

    F(x) = max(h(x), F(x + δâ) − δk),      M(p) = F(p + δâ) − δk,

so one sweep down each line of a lattice aligned with â (δ apart along and across) gives F at every
lattice point in O(1) a point, instead of a march of hundreds of lookups per vertex at a low light;
each vertex then reads M at its own position, bilinear in the lattice. The lattice covers the patch
turned to â, and each line starts far enough upstream (the surface's height range over k) that
nothing before its start could rise above a ray.
"""

import warp as wp

from warpcaustics.kernels.geometry import bilerp

wp.set_module_options({"enable_backward": False})


@wp.struct
class Lattice:
    """The sweep's lattice for one light direction: points start + iδ along ``along`` (the light's
    horizontal direction) and start + jδ along ``across``, about the patch's centre; ``rise`` = δk."""

    extent_m: float
    along: wp.vec2
    across: wp.vec2
    start: float
    spacing: float
    rise: float


@wp.kernel
def surface_heights(positions: wp.array2d[wp.vec3], heights: wp.array2d[wp.float32]):
    """heights[iy, ix] = the vertex's height: the sweep's lookups read 4 bytes a vertex, not 12."""
    iy, ix = wp.tid()
    heights[iy, ix] = positions[iy, ix][2]


@wp.kernel
def horizon_sweep(heights: wp.array2d[wp.float32], lattice: Lattice, steps: int,
                  horizon: wp.array2d[wp.float32]):
    """Line j of the lattice (its points at start + iδ along ``along``, start + jδ along ``across``):
    horizon[j, i] = F at its point i (a line's points side by side, where one thread writes them),
    for the points the array holds, by the recurrence swept from point ``steps`` − 1 down to 0 (the
    surface's heights bilinear between its cell centres, periodic). F is carried as the max over
    the points beyond of h − (their index)·rise, plus the point's own index·rise, so that no
    rounding accumulates; a point's cell coordinates are the line's start plus its index times the
    step (no accumulation either)."""
    j = wp.tid()
    n = heights.shape[0]
    extent_m = lattice.extent_m
    along = lattice.along
    across = lattice.across
    start = lattice.start
    rise = lattice.rise
    scale = float(n) / extent_m
    r = start + float(j) * lattice.spacing
    u0 = (start * along[0] + r * across[0] + 0.5 * extent_m) * scale - 0.5  # cell coordinates of point 0
    v0 = (start * along[1] + r * across[1] + 0.5 * extent_m) * scale - 0.5
    du = lattice.spacing * along[0] * scale
    dv = lattice.spacing * along[1] * scale
    stored = horizon.shape[1]
    best = float(-1.0e30)
    for k in range(steps):
        i = steps - 1 - k
        u = u0 + float(i) * du
        v = v0 + float(i) * dv
        fu = wp.floor(u)
        fv = wp.floor(v)
        i0 = int(fu) % n
        j0 = int(fv) % n
        if i0 < 0:
            i0 += n
        if j0 < 0:
            j0 += n
        i1 = i0 + 1
        j1 = j0 + 1
        if i1 == n:
            i1 = 0
        if j1 == n:
            j1 = 0
        h = bilerp(heights[j0, i0], heights[j0, i1], heights[j1, i0], heights[j1, i1], u - fu, v - fv)
        best = wp.max(best, h - float(i) * rise)
        if i < stored:
            horizon[j, i] = best + float(i) * rise


@wp.kernel
def horizon_visibility(positions: wp.array2d[wp.vec3], lattice: Lattice, horizon: wp.array2d[wp.float32],
                       visible: wp.array2d[wp.float32]):
    """1 where vertex (iy, ix) sees the light, 0 where the highest point ahead, M = F(p + δâ) − δk
    (bilinear in the lattice, p wrapped into the patch), rises above it by more than the march's
    tolerance (1e-4 of a cell)."""
    iy, ix = wp.tid()
    extent_m = lattice.extent_m
    along = lattice.along
    across = lattice.across
    spacing = lattice.spacing
    start = lattice.start
    p = positions[iy, ix]
    x = p[0] - extent_m * wp.floor((p[0] + 0.5 * extent_m) / extent_m)
    y = p[1] - extent_m * wp.floor((p[1] + 0.5 * extent_m) / extent_m)
    u = (x * along[0] + y * along[1] + spacing - start) / spacing
    v = (x * across[0] + y * across[1] - start) / spacing
    i0 = wp.clamp(int(wp.floor(u)), 0, horizon.shape[1] - 2)
    j0 = wp.clamp(int(wp.floor(v)), 0, horizon.shape[0] - 2)
    tu = u - float(i0)
    tv = v - float(j0)
    highest = bilerp(horizon[j0, i0], horizon[j0, i0 + 1], horizon[j0 + 1, i0], horizon[j0 + 1, i0 + 1],
                     tu, tv)
    cell = extent_m / float(positions.shape[0])
    visible[iy, ix] = wp.where(highest - lattice.rise > p[2] + 1.0e-4 * cell, 0.0, 1.0)
