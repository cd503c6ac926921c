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

On the other receivers (``[[receivers]]`` meshes, a pool's walls) the "texels" are the faces: the
cell is spread over the faces of the photon's receiver that it covers, each face's share its
overlap with the cell in the cell's plane (the face projected along the cell's normal, clipped to
the cell), the shares normalised to one so that the flux is kept exactly.
"""

import warp as wp

from warpcaustics.kernels.caustics.fluxratio import FloorMap, TriangleDeposit, spread_triangle, wrap_coord
from warpcaustics.kernels.caustics.photon_lattice import MIN_CELL_ALIGNMENT, photon_lattice
from warpcaustics.kernels.caustics.photons import Photons
from warpcaustics.kernels.geometry import clip_to_slab, polygon_area, vec8

wp.set_module_options({"enable_backward": False})


@wp.func
def photon_deposit(texels: wp.array3d[wp.float32], flux: wp.array4d[wp.float32], k0: int, bands: int,
                   p: int) -> TriangleDeposit:
    """The flux-ratio map's deposit record for photon p: its flux ``flux[p, 0, 0, k]`` in bands k0 …
    k0 + bands − 1 into ``texels`` (M, M, K)."""
    dep = TriangleDeposit()
    dep.floor_texels = texels
    dep.flux_w_nm = flux
    dep.k_begin = k0
    dep.k_count = bands
    dep.iy = p
    dep.ix = 0
    dep.half = 0
    return dep


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
    dep = photon_deposit(texels, flux, k0, ph.wavelengths_per_group, p)
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


MIN_CELL_COVER = 0.5
"""A receiver photon's cell must be at least this much covered by its receiver's faces (in the
cell's plane); less (the cell hangs over a silhouette or a gap in the mesh): the face deposit."""
CELL_REACH = 0.5
"""The faces searched for a receiver photon's cell: those whose boxes meet the cell's box grown by
this many of its longest sides (a curved receiver bends away from the cell's plane)."""


@wp.func
def face_in_cell(points: wp.array[wp.vec3], indices: wp.array[wp.int32], g: int, c: wp.vec3, a_axis: wp.vec3,
                 b_axis: wp.vec3) -> float:
    """Area of face g's overlap with the cell [−½, ½]² in the cell's coordinates (a, b) =
    ((x − c)·a_axis, (x − c)·b_axis) (the face projected along the cell's normal), in cell areas."""
    px = vec8()
    py = vec8()
    for j in range(3):
        x = points[indices[3 * g + j]] - c
        px[j] = wp.dot(x, a_axis)
        py[j] = wp.dot(x, b_axis)
    cx, cy, cn = clip_to_slab(px, py, 3, 0, -0.5, 0.5)
    if cn < 3:
        return 0.0
    rx, ry, rn = clip_to_slab(cx, cy, cn, 1, -0.5, 0.5)
    if rn < 3:
        return 0.0
    return polygon_area(rx, ry, rn)


@wp.func
def cell_axes(eu: wp.vec3, ev: wp.vec3, normal: wp.vec3):
    """(a_axis, b_axis): x ↦ ((x − c)·a_axis, (x − c)·b_axis) are x's coordinates in the basis
    (e_u, e_v) after projection along ``normal`` onto the cell's plane."""
    a_axis = wp.cross(ev, normal)
    b_axis = wp.cross(normal, eu)
    return a_axis / wp.dot(eu, a_axis), b_axis / wp.dot(ev, b_axis)


@wp.func
def add_face_flux(face_flux: wp.array2d[wp.float32], row: int, w: float, ph: Photons, k0: int, ell: float):
    """face_flux[row, k] += w E(k) e^{−c(k) ℓ} for the photon's bands."""
    for j in range(ph.wavelengths_per_group):
        k = k0 + j
        wp.atomic_add(face_flux, row, k, w * ph.sun_irradiance[k] * wp.exp(-ph.attenuation_per_m[k] * ell))


@wp.func
def cell_faces(mesh: wp.uint64, points: wp.array[wp.vec3], indices: wp.array[wp.int32],
               face_receiver: wp.array[wp.int32], face_normal: wp.array[wp.vec3], r: int, normal: wp.vec3,
               c: wp.vec3, a_axis: wp.vec3, b_axis: wp.vec3, lo: wp.vec3, hi: wp.vec3, w: float,
               face_flux: wp.array2d[wp.float32], ph: Photons, k0: int, ell: float) -> float:
    """How much of the cell (in cell areas) receiver r's faces that face along ``normal`` cover;
    with ``w`` > 0 each such face also gets w × its overlap of the photon's flux (:func:`add_face_flux`)."""
    total = float(0.0)
    query = wp.mesh_query_aabb(mesh, lo, hi)
    g = int(0)
    while wp.mesh_query_next(query, g):
        if face_receiver[g] == r and wp.dot(face_normal[g], normal) >= MIN_CELL_ALIGNMENT:
            a = face_in_cell(points, indices, g, c, a_axis, b_axis)
            if a > 0.0:
                total += a
                if w > 0.0:
                    add_face_flux(face_flux, g - ph.floor_face_count, w * a, ph, k0, ell)
    return total


@wp.kernel
def splat_receiver_footprints(
    ph: Photons,
    mesh: wp.uint64,
    points: wp.array[wp.vec3],
    indices: wp.array[wp.int32],
    face_receiver: wp.array[wp.int32],
    face_normal: wp.array[wp.vec3],
    spacing_m: float,
    face_flux: wp.array2d[wp.float32],
    splatted: wp.array[wp.int32],
):
    """Photon p on a receiver other than the floor with a lattice cell: its flux spread over the
    receiver's faces that the cell covers (``face_flux`` (F_other, K) [W nm^-1]), each its overlap
    / the cell's covered area; ``splatted[p]`` = 1. Runs after :func:`splat_footprints`, which
    clears ``splatted``; photons it leaves keep the face deposit."""
    p = wp.tid()
    f = ph.face[p]
    if f < ph.floor_face_count:  # the floor's, or no receiver
        return
    eu, ev, ok = photon_lattice(ph.hit, ph.face, face_receiver, face_normal, p, ph.quads, ph.subdivisions,
                                ph.periodic, ph.extent_m, spacing_m)
    if ok == 0:
        return
    normal = wp.normalize(wp.cross(eu, ev))
    if wp.dot(normal, face_normal[f]) < 0.0:
        normal = -normal
    c = ph.hit[p]
    corner = 0.5 * (wp.abs(eu) + wp.abs(ev))  # half the cell's box
    reach = CELL_REACH * wp.max(wp.length(eu), wp.length(ev))
    lo = c - corner - wp.vec3(reach)
    hi = c + corner + wp.vec3(reach)
    r = face_receiver[f]
    a_axis, b_axis = cell_axes(eu, ev, normal)
    ell = ph.path_before[p] + wp.length(c - ph.origin[p])
    k0 = (p / ph.photons_per_group) * ph.wavelengths_per_group
    covered = cell_faces(mesh, points, indices, face_receiver, face_normal, r, normal, c, a_axis, b_axis, lo,
                         hi, 0.0, face_flux, ph, k0, ell)  # the cover alone
    if covered < MIN_CELL_COVER:
        return
    cell_faces(mesh, points, indices, face_receiver, face_normal, r, normal, c, a_axis, b_axis, lo, hi,
               ph.weight[p] / covered, face_flux, ph, k0, ell)  # the deposit, over the same faces
    splatted[p] = 1
