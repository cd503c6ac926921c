"""Footprint splats of photons on the floor map (``caustics.photon_splat = "footprint"``).

A photon stands for its stratum of the surface: an s×s share of a surface cell. Carried through
refraction to the floor, the stratum becomes the photon's lattice cell, spanned by the steps to its
grid neighbours' hits (``photon_lattice``: the finite-difference form of the ray differentials of
Igehy 1999 that photon differential splatting uses, Schjøth et al. 2007; Frisvad, Schjøth, Erleben
& Sporring 2014, CGF 33(6), whose footprint the two positional differentials span). The photon's
flux is spread evenly over that parallelogram, centred on its hit, and deposited into the texels
by exact area clipping (``fluxratio.spread_triangle``, two triangles): every texel gets overlap /
cell area of it, so the flux is kept exactly, and the cells of a regular (affine) lattice tile the
plane, so still water gives the analytic irradiance in every texel at any photon density. Focused
light has small cells and stays sharp; spread light has large ones and is smooth. A photon without
a cell (a silhouette, the edge of the lit region, a neighbour on another receiver) keeps the texel
deposit.
"""

import warp as wp

from warpcaustics.kernels.caustics.fluxratio import FloorMap, TriangleDeposit, spread_triangle, wrap_coord
from warpcaustics.kernels.caustics.photon_lattice import photon_lattice
from warpcaustics.kernels.caustics.photons import Photons

wp.set_module_options({"enable_backward": False})


@wp.kernel
def splat_footprints(
    ph: Photons,
    face_receiver: wp.array[wp.int32],
    face_normal: wp.array[wp.vec3],
    spacing_m: float,
    floor_map: FloorMap,
    flux: wp.array4d[wp.float32],
    texels: wp.array3d[wp.float32],
    coarse_count: wp.array[wp.int32],
    splatted: wp.array[wp.int32],
):
    """Photon p on the floor with a lattice cell: its flux ``w E(λ) e^{−c(λ)ℓ}`` (half per triangle,
    kept in ``flux`` (P, 1, 1, K)) spread over the cell's horizontal projection into ``texels``
    (M, M, K) as irradiance per horizontal texel area; ``splatted[p]`` = 1. Other photons, and those
    whose cell reaches past the edge of a map that does not wrap: 0 (the texel deposit takes
    them)."""
    p = wp.tid()
    splatted[p] = 0
    f = ph.face[p]
    if f < 0 or f >= ph.floor_face_count:
        return
    eu, ev, ok = photon_lattice(ph.hit, ph.face, face_receiver, face_normal, p, ph.quads, ph.subdivisions,
                                ph.periodic, ph.extent_m, spacing_m)
    if ok == 0:
        return
    g = p / ph.photons_per_group
    hit = ph.hit[p]
    ell = ph.path_before[p] + wp.length(hit - ph.origin[p])
    k0 = g * ph.wavelengths_per_group
    for j in range(ph.wavelengths_per_group):
        k = k0 + j
        flux[p, 0, 0, k] = 0.5 * ph.weight[p] * ph.sun_irradiance[k] * wp.exp(-ph.attenuation_per_m[k] * ell)
    dep = TriangleDeposit()
    dep.floor_texels = texels
    dep.flux_w_nm = flux
    dep.k_begin = k0
    dep.k_count = ph.wavelengths_per_group
    dep.iy = p
    dep.ix = 0
    dep.half = 0
    m = texels.shape[0]
    scale = floor_map.scale
    u = wp.vec2(eu[0], eu[1]) * scale
    v = wp.vec2(ev[0], ev[1]) * scale
    q0 = (wp.vec2(hit[0], hit[1]) - floor_map.origin) * scale - 0.5 * (u + v)
    if floor_map.wrap != 0:
        q0 = wp.vec2(wrap_coord(q0[0], m), wrap_coord(q0[1], m))
    else:  # a cell reaching past the map's edge (a pool's wall) would lose flux: keep the texel deposit
        lo = wp.min(wp.min(q0, q0 + u), wp.min(q0 + v, q0 + u + v))
        hi = wp.max(wp.max(q0, q0 + u), wp.max(q0 + v, q0 + u + v))
        if lo[0] < 0.0 or lo[1] < 0.0 or hi[0] > float(m) or hi[1] > float(m):
            return
    inv_texel_area = scale * scale
    spread_triangle(dep, q0, u, u + v, m, floor_map.wrap, floor_map.max_clipped, inv_texel_area, coarse_count)
    spread_triangle(dep, q0, u + v, v, m, floor_map.wrap, floor_map.max_clipped, inv_texel_area, coarse_count)
    splatted[p] = 1


@wp.kernel
def add_footprints(
    footprint: wp.array3d[wp.float32],
    texel_area_m2: float,
    floor_inv_area: wp.array2d[wp.float32],
    texels: wp.array3d[wp.float32],
):
    """texels += footprint × (horizontal texel area / the texel's true floor area): the footprint
    splats' irradiance per horizontal area onto the relief's true area, as the texel deposit has it."""
    ty, tx, k = wp.tid()
    texels[ty, tx, k] = texels[ty, tx, k] + footprint[ty, tx, k] * texel_area_m2 * floor_inv_area[ty, tx]
