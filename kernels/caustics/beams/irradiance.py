"""Flux density of a beam at a point (the beam's own, or Ernst et al. 2005's smooth interpolation
across beams) and the irradiance at receiver points: the surface gather over a tile's beams.
"""

import warp as wp

from warpcaustics.kernels.caustics.beams.build import corner_offset
from warpcaustics.kernels.caustics.beams.raster import TileGrid, tile_of
from warpcaustics.kernels.caustics.beams.section import (
    Beams,
    BeamSample,
    beam_group,
    lit,
    safe_area,
    sample_beam,
    section_copies,
    water_path,
    xy,
)

wp.set_module_options({"enable_backward": False})


@wp.func
def ring_density(bm: Beams, g: int, vx: int, vy: int, periodic: int, z: float) -> float:
    """Wave-front density at lattice vertex (vx, vy) and height z: the flux weight of the (up to
    six) carrying beams around the vertex over the area of their sections, Σ w / Σ |A(z)|
    (``periodic``: the lattice wraps)."""
    quads = bm.quads
    num = float(0.0)
    den = float(0.0)
    for r in range(6):
        # The six triangles at a vertex: quads (0,0) both halves, (−1,0) half 0, (−1,−1) both,
        # (0,−1) half 1 (see fluxratio.py quad_corner for the corner order of each half).
        dx = int(0)
        dy = int(0)
        half = int(0)
        if r == 1:
            half = 1
        elif r == 2:
            dx = -1
        elif r == 3:
            dx = -1
            dy = -1
        elif r == 4:
            dx = -1
            dy = -1
            half = 1
        elif r == 5:
            dy = -1
            half = 1
        qx = vx + dx
        qy = vy + dy
        if periodic != 0:
            qx = (qx + quads) % quads
            qy = (qy + quads) % quads
        elif qx < 0 or qy < 0 or qx >= quads or qy >= quads:
            continue
        bb = ((g * quads + qy) * quads + qx) * 2 + half
        if bm.weight[bb] > 0.0:
            num += bm.weight[bb]
            base_z = (bm.base[bb, 0][2] + bm.base[bb, 1][2] + bm.base[bb, 2][2]) / 3.0
            den += safe_area(bm.area_coef[bb], z, base_z)
    if den <= 0.0:
        return 0.0
    return num / den


@wp.func
def flux_density(bm: Beams, b: int, s: BeamSample, z: float, periodic: int) -> float:
    """Horizontal flux density at a point of beam b per unit solar irradiance, before attenuation
    [-]. ``smooth == 0``: the beam's own ``w Σλ_i T_i / |A(z)|`` (each section receives exactly its
    flux). ``smooth == 1`` (Ernst et al. 2005's interpolation across beams): ``Σ λ_i T_i ρ_i`` with
    ρ_i the wave-front density of the beams around vertex i at this height, so the irradiance is
    continuous from beam to beam and no triangle edges show; flux is then conserved only to the
    interpolation's accuracy (docs/validation.md). ``periodic``: the lattice wraps."""
    if bm.smooth == 0 or b >= bm.primaries:  # a bounced beam is on no lattice: its own density
        return bm.weight[b] * s.transmit / s.area
    quads = bm.quads
    per_group = quads * quads * 2
    g = b / per_group
    rest = b - g * per_group
    half = rest % 2
    qx = (rest / 2) % quads
    qy = (rest / 2) / quads
    total = float(0.0)
    for c in range(3):
        o = corner_offset(half, c)
        rho = ring_density(bm, g, qx + o[0], qy + o[1], periodic, z)
        total += s.lam[c] * bm.transmit[b, c] * rho
    return total


@wp.func
def add_beam_irradiance(
    out: wp.array2d[wp.float32], point: int, scale: float, bm: Beams, b: int, s: BeamSample, density: float
):
    """out[k, point] += scale · E_sun(k) · density · exp(−c(k) ℓ) for the bands of b's group."""
    g = beam_group(bm, b)
    f = scale * density
    path = water_path(bm, b, s)
    for j in range(bm.wavelengths_per_group):
        k = g * bm.wavelengths_per_group + j
        out[k, point] = out[k, point] + f * bm.sun_irradiance[k] * wp.exp(-bm.attenuation_per_m[k] * path)


@wp.kernel
def point_irradiance(
    grid: TileGrid,
    tile_start: wp.array[wp.int32],
    tile_count: wp.array[wp.int32],
    tile_items: wp.array[wp.int32],
    bm: Beams,
    points: wp.array[wp.vec3],
    normals: wp.array[wp.vec3],
    point_ids: wp.array[wp.int32],
    out: wp.array2d[wp.float32],
):
    """Irradiance on the receiver at each point (K, P) [W m^-2 nm^-1] (``point_ids``: each point's
    receiver id; ids < 0 and receivers that gather no light are skipped):
    the sum over the beams of the point's horizontal tile of ``E_h · |d·n| / |d_z|``."""
    p_index = wp.tid()
    for k in range(out.shape[0]):
        out[k, p_index] = 0.0
    if point_ids[p_index] < 0:
        return
    if bm.unlit_receiver[point_ids[p_index]] != 0:
        return
    p = points[p_index]
    n = normals[p_index]
    t = tile_of(grid, xy(p))
    if t < 0:
        return
    start = tile_start[t]
    for item in range(tile_count[t]):
        b = tile_items[start + item]
        kx0, kx1, ky0, ky1 = section_copies(bm, b, p)
        for ky in range(ky0, ky1 + 1):
            for kx in range(kx0, kx1 + 1):  # every periodic copy of the point the section may hold
                q = p + wp.vec3(float(kx) * bm.extent_m, float(ky) * bm.extent_m, 0.0)
                s = sample_beam(bm, b, q)
                if s.inside == 0:
                    continue
                if not lit(bm, b, s, q):
                    continue
                cos_factor = wp.abs(wp.dot(s.d, n)) / wp.abs(s.d[2])
                density = flux_density(bm, b, s, q[2], bm.periodic)
                add_beam_irradiance(out, p_index, cos_factor, bm, b, s, density)
