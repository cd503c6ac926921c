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

from warpcaustics.kernels.caustics.fluxratio import (
    FloorMap,
    TriangleDeposit,
    grid_corner,
    lift,
    spread_triangle_at,
    wrap_coord,
)
from warpcaustics.kernels.caustics.photon_lattice import (
    MAX_CELL_SPACINGS,
    MIN_CELL_ALIGNMENT,
    grid_neighbour,
    on_receiver,
    photon_lattice,
    stratum_ratio,
)
from warpcaustics.kernels.caustics.photons import Photons, bilinear_vec3
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


@wp.func
def half_flux(flux: wp.array4d[wp.float32], ph: Photons, p: int, k0: int, ell: float):
    """flux[p, 0, 0, k] = ½ w E(k) e^{−c(k) ℓ} in photon p's bands: what each of its cell's two
    triangles spreads after a water path ``ell``."""
    for j in range(ph.wavelengths_per_group):
        k = k0 + j
        flux[p, 0, 0, k] = 0.5 * ph.weight[p] * ph.sun_irradiance[k] * wp.exp(-ph.attenuation_per_m[k] * ell)


# --- the cells on a flat floor in float64 ------------------------------------------------------
# float32 hits 2–4 m from the origin are rounded to ~2.4e-7 m each, so neighbouring cells, each
# placed about its own hit, overlap or leave gaps of that size: 1e-5 of a texel's irradiance. On a
# flat floor (no bounces) the splat recomputes each hit in float64 from the photon's own start on
# the surface (the vertices' float32 positions, interpolated in float64) and direction, and places
# the cell relative to its texel: still water is then exact to float32's flux sums.


@wp.func
def to64(v: wp.vec3) -> wp.vec3d:
    return wp.vec3d(wp.float64(v[0]), wp.float64(v[1]), wp.float64(v[2]))


@wp.func
def plane_hit64(positions: wp.array2d[wp.vec3], ph: Photons, p: int, plane_z: float) -> wp.vec3d:
    """Photon p's hit on the plane z = ``plane_z`` in float64: its start on the bilinear surface
    patch (``emit_photons``) recomputed in float64, moved by the whole periods its trace moved it
    (``periodic_start``), followed along its direction."""
    s = ph.subdivisions
    sub = p % (s * s)
    cell = p / (s * s)
    qx = cell % ph.quads
    qy = (cell / ph.quads) % ph.quads
    n = positions.shape[0]
    x00, y00, h00 = grid_corner(qx, qy, 0, 0, n, ph.extent_m, ph.periodic)
    x10, y10, h10 = grid_corner(qx, qy, 1, 0, n, ph.extent_m, ph.periodic)
    x01, y01, h01 = grid_corner(qx, qy, 0, 1, n, ph.extent_m, ph.periodic)
    x11, y11, h11 = grid_corner(qx, qy, 1, 1, n, ph.extent_m, ph.periodic)
    p00 = lift(positions[y00, x00], h00)
    p10 = lift(positions[y10, x10], h10)
    p01 = lift(positions[y01, x01], h01)
    p11 = lift(positions[y11, x11], h11)
    tu = (float(sub % s) + 0.5) / float(s)
    tv = (float(sub / s) + 0.5) / float(s)
    emitted = bilinear_vec3(p00, p10, p01, p11, tu, tv)  # the float32 start, as emitted
    tu64 = (wp.float64(sub % s) + wp.float64(0.5)) / wp.float64(s)
    tv64 = (wp.float64(sub / s) + wp.float64(0.5)) / wp.float64(s)
    one = wp.float64(1.0)
    start = (one - tv64) * ((one - tu64) * to64(p00) + tu64 * to64(p10)) + tv64 * (
        (one - tu64) * to64(p01) + tu64 * to64(p11))
    if ph.periodic != 0:
        moved = ph.origin[p] - emitted
        period = wp.float64(ph.extent_m)
        start = start + wp.vec3d(period * wp.float64(wp.round(moved[0] / ph.extent_m)),
                                 period * wp.float64(wp.round(moved[1] / ph.extent_m)), wp.float64(0.0))
    d = to64(ph.direction[p])
    return start + ((wp.float64(plane_z) - start[2]) / d[2]) * d


@wp.func
def unwrap64(a: wp.vec3d, b: wp.vec3d, periodic: int, extent_m: float) -> wp.vec3d:
    """b − a in float64, with whole periods removed on a periodic sea."""
    e = b - a
    if periodic != 0:
        period = wp.float64(extent_m)
        e = e - wp.vec3d(period * wp.round(e[0] / period), period * wp.round(e[1] / period), wp.float64(0.0))
    return e


@wp.func
def step_neighbour(ph: Photons, face_receiver: wp.array[wp.int32], n: int, r: int, any_landed: int) -> bool:
    """Whether grid neighbour n spans p's cell: it landed on p's receiver r (or, ``any_landed``, on
    any receiver: on a flat floor its ray continued to the plane is as good)."""
    if any_landed != 0:
        return n >= 0 and ph.face[n] >= 0
    return on_receiver(n, r, ph.face, face_receiver)


@wp.func
def lattice_step64(positions: wp.array2d[wp.vec3], ph: Photons, face_receiver: wp.array[wp.int32], p: int,
                   along_v: int, plane_z: float, hit: wp.vec3d, any_landed: int):
    """(e, ok): ``lattice_step`` in float64 on the plane: to the forward grid neighbour that spans
    the cell (:func:`step_neighbour`), or from the backward one; ok = 0 if neither does."""
    r = face_receiver[ph.face[p]]
    n = grid_neighbour(p, along_v, 1, ph.quads, ph.subdivisions, ph.periodic)
    e = wp.vec3d()
    if step_neighbour(ph, face_receiver, n, r, any_landed):
        e = unwrap64(hit, plane_hit64(positions, ph, n, plane_z), ph.periodic, ph.extent_m)
    else:
        n = grid_neighbour(p, along_v, -1, ph.quads, ph.subdivisions, ph.periodic)
        if not step_neighbour(ph, face_receiver, n, r, any_landed):
            return e, int(0)
        e = unwrap64(plane_hit64(positions, ph, n, plane_z), hit, ph.periodic, ph.extent_m)
    return e * wp.float64(stratum_ratio(p, n, along_v, ph.quads, ph.subdivisions, ph.periodic)), int(1)


@wp.func
def flat_cell64(positions: wp.array2d[wp.vec3], ph: Photons, face_receiver: wp.array[wp.int32], p: int,
                plane_z: float, floor_map: FloorMap, m: int, any_landed: int):
    """(base, q0, u, v, ok): photon p's lattice cell on the floor plane z = ``plane_z`` in float64
    (its ray and its grid neighbours' continued to the plane, :func:`lattice_step64`), in texels:
    corner q0 relative to texel ``base`` (wrapped on a periodic map), sides u and v."""
    h64 = plane_hit64(positions, ph, p, plane_z)
    eu64, ok_u = lattice_step64(positions, ph, face_receiver, p, 0, plane_z, h64, any_landed)
    ev64, ok_v = lattice_step64(positions, ph, face_receiver, p, 1, plane_z, h64, any_landed)
    sc = wp.float64(floor_map.scale)
    u64 = wp.vec2d(eu64[0], eu64[1]) * sc
    v64 = wp.vec2d(ev64[0], ev64[1]) * sc
    corner = (wp.vec2d(h64[0], h64[1]) - wp.vec2d(wp.float64(floor_map.origin[0]),
                                                  wp.float64(floor_map.origin[1]))) * sc
    corner = corner - wp.float64(0.5) * (u64 + v64)
    whole = wp.vec2d(wp.floor(corner[0]), wp.floor(corner[1]))
    base = wp.vec2i(int(whole[0]), int(whole[1]))
    if floor_map.wrap != 0:
        base = wp.vec2i(((base[0] % m) + m) % m, ((base[1] % m) + m) % m)
    q0 = wp.vec2(float(corner[0] - whole[0]), float(corner[1] - whole[1]))
    return (base, q0, wp.vec2(float(u64[0]), float(u64[1])), wp.vec2(float(v64[0]), float(v64[1])),
            ok_u * ok_v)


@wp.func
def add_face_flux(face_flux: wp.array2d[wp.float32], row: int, w: float, ph: Photons, k0: int, ell: float):
    """face_flux[row, k] += w E(k) e^{−c(k) ℓ} for the photon's bands."""
    for j in range(ph.wavelengths_per_group):
        k = k0 + j
        wp.atomic_add(face_flux, row, k, w * ph.sun_irradiance[k] * wp.exp(-ph.attenuation_per_m[k] * ell))


MAP_EDGE_SLACK = 1.0e-3
"""A cell at most this share outside the map (one ending at a pool's wall, to rounding) is spread
over its inside part, its flux kept."""


@wp.func
def wall_neighbour_face(ph: Photons, face_receiver: wp.array[wp.int32], p: int, walls_id: int) -> int:
    """The face of the first of photon p's four grid neighbours that landed on a pool's wall, or −1."""
    for k in range(4):
        n = grid_neighbour(p, k / 2, 2 * (k % 2) - 1, ph.quads, ph.subdivisions, ph.periodic)
        if n >= 0:
            f = ph.face[n]
            if f >= 0 and face_receiver[f] == walls_id:
                return f
    return -1


@wp.func
def floor_neighbour(ph: Photons, p: int) -> int:
    """1 if one of photon p's eight grid neighbours (the diagonal ones too: the photon in a corner
    between two walls) landed on the floor, else 0."""
    for k in range(9):
        n = p
        if k % 3 != 1:
            n = grid_neighbour(n, 0, k % 3 - 1, ph.quads, ph.subdivisions, ph.periodic)
        if k / 3 != 1 and n >= 0:
            n = grid_neighbour(n, 1, k / 3 - 1, ph.quads, ph.subdivisions, ph.periodic)
        if n >= 0 and n != p:
            f = ph.face[n]
            if f >= 0 and f < ph.floor_face_count:
                return 1
    return 0


@wp.func
def inside_map(at: wp.vec2, u: wp.vec2, v: wp.vec2, m: int) -> float:
    """Share of the parallelogram (at, at + u, at + u + v, at + v) [texels] inside the map [0, m]²."""
    px = vec8()
    py = vec8()
    px[0] = at[0]
    py[0] = at[1]
    px[1] = at[0] + u[0]
    py[1] = at[1] + u[1]
    px[2] = at[0] + u[0] + v[0]
    py[2] = at[1] + u[1] + v[1]
    px[3] = at[0] + v[0]
    py[3] = at[1] + v[1]
    cx, cy, cn = clip_to_slab(px, py, 4, 0, 0.0, float(m))
    if cn < 3:
        return 0.0
    rx, ry, rn = clip_to_slab(cx, cy, cn, 1, 0.0, float(m))
    if rn < 3:
        return 0.0
    return polygon_area(rx, ry, rn) / wp.abs(u[0] * v[1] - u[1] * v[0])


@wp.kernel
def splat_footprints(
    ph: Photons,
    face_receiver: wp.array[wp.int32],
    face_normal: wp.array[wp.vec3],
    spacing_m: float,
    floor_map: FloorMap,
    positions: wp.array2d[wp.vec3],
    flat_plane: int,
    plane_z: float,
    walls_id: int,
    flux: wp.array4d[wp.float32],
    texels: wp.array3d[wp.float32],
    face_flux: wp.array2d[wp.float32],
    coarse_count: wp.array[wp.int32],
    splatted: wp.array[wp.int32],
):
    """Photon p on the floor with a lattice cell: its flux ``w E(λ) e^{−c(λ)ℓ}`` (half per triangle,
    kept in ``flux`` (P, 1, 1, K)) spread over the cell's horizontal projection into ``texels``
    (M, M, K) as irradiance per horizontal texel area; ``splatted[p]`` = 1. Other photons, and those
    whose cell reaches past the edge of a map that does not wrap: 0 (the texel deposit takes
    them), unless a grid neighbour landed on a pool's wall (receiver ``walls_id``): then the part of
    the cell inside the map is spread over it as usual and the rest goes to that wall face's flux
    ``face_flux`` (F_other, K), so that the texels along the wall are exact and the flux is kept.
    ``flat_plane``: the floor is the plane z = ``plane_z`` and the photons come straight from the
    surface ``positions``: the cell is placed in float64 (above)."""
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
    half_flux(flux, ph, p, k0, ell)
    dep = photon_deposit(texels, flux, k0, ph.wavelengths_per_group, p)
    m = texels.shape[0]
    scale = floor_map.scale
    u = wp.vec2(eu[0], eu[1]) * scale
    v = wp.vec2(ev[0], ev[1]) * scale
    base = wp.vec2i(0, 0)
    q0 = wp.vec2(0.0)
    if flat_plane != 0:
        base, q0, u, v, ok = flat_cell64(positions, ph, face_receiver, p, plane_z, floor_map, m, 0)
    else:
        q0 = (wp.vec2(hit[0], hit[1]) - floor_map.origin) * scale - 0.5 * (u + v)
        if floor_map.wrap != 0:
            q0 = wp.vec2(wrap_coord(q0[0], m), wrap_coord(q0[1], m))
    if floor_map.wrap == 0:  # a cell reaching past the map's edge
        at = q0 + wp.vec2(float(base[0]), float(base[1]))
        lo = wp.min(wp.min(at, at + u), wp.min(at + v, at + u + v))
        hi = wp.max(wp.max(at, at + u), wp.max(at + v, at + u + v))
        if lo[0] < 0.0 or lo[1] < 0.0 or hi[0] > float(m) or hi[1] > float(m):
            wall = wall_neighbour_face(ph, face_receiver, p, walls_id)
            share = inside_map(at, u, v, m)
            if wall >= 0 and share > 0.0:
                rest = (1.0 - share) * ph.weight[p]  # the cell's part beyond the map: the wall's
                add_face_flux(face_flux, wall - ph.floor_face_count, rest, ph, k0, ell)
            elif share >= 1.0 - MAP_EDGE_SLACK:  # a cell ending at the map's edge, to rounding
                for j in range(ph.wavelengths_per_group):
                    flux[p, 0, 0, k0 + j] = flux[p, 0, 0, k0 + j] / share
            else:
                return  # keep the texel deposit (no wall to give the rest to: the flux would be lost)
    inv_texel_area = scale * scale
    spread_triangle_at(dep, base, q0, u, u + v, m, floor_map.wrap, floor_map.max_clipped, inv_texel_area,
                       coarse_count)
    spread_triangle_at(dep, base, q0, u + v, v, m, floor_map.wrap, floor_map.max_clipped, inv_texel_area,
                       coarse_count)
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


@wp.func
def floor_part(positions: wp.array2d[wp.vec3], ph: Photons, face_receiver: wp.array[wp.int32], p: int,
               plane_z: float, floor_map: FloorMap, flux: wp.array4d[wp.float32],
               texels: wp.array3d[wp.float32], coarse_count: wp.array[wp.int32], k0: int,
               spacing_m: float) -> float:
    """A wall photon's cell continued along the rays to the floor plane (:func:`flat_cell64`): the
    part inside the map is spread over it as a floor photon's cell is (the rest lies beyond the
    wall and is dropped); returns that part's share of the cell (0: nothing spread). A cell that
    ``photon_lattice`` would refuse on the floor (flat, or longer than ``MAX_CELL_SPACINGS``
    spacings: a fold of the light) is not spread."""
    m = texels.shape[0]
    base, q0, u, v, ok = flat_cell64(positions, ph, face_receiver, p, plane_z, floor_map, m, 1)
    if ok == 0:
        return 0.0
    longest = wp.max(wp.length(u), wp.length(v))
    if wp.abs(u[0] * v[1] - u[1] * v[0]) <= 1.0e-6 * longest * longest:
        return 0.0
    if longest > MAX_CELL_SPACINGS * spacing_m * floor_map.scale:
        return 0.0
    share = wp.min(inside_map(q0 + wp.vec2(float(base[0]), float(base[1])), u, v, m), 1.0)
    if not (share > 0.0):  # NaN too
        return 0.0
    h64 = plane_hit64(positions, ph, p, plane_z)  # the ray continued to the floor
    ell = ph.path_before[p] + wp.length(wp.vec3(float(h64[0]), float(h64[1]), float(h64[2])) - ph.origin[p])
    half_flux(flux, ph, p, k0, ell)
    dep = photon_deposit(texels, flux, k0, ph.wavelengths_per_group, p)
    inv_texel_area = floor_map.scale * floor_map.scale
    spread_triangle_at(dep, base, q0, u, u + v, m, 0, floor_map.max_clipped, inv_texel_area, coarse_count)
    spread_triangle_at(dep, base, q0, u + v, v, m, 0, floor_map.max_clipped, inv_texel_area, coarse_count)
    return share

@wp.kernel
def splat_receiver_footprints(
    ph: Photons,
    mesh: wp.uint64,
    points: wp.array[wp.vec3],
    indices: wp.array[wp.int32],
    face_receiver: wp.array[wp.int32],
    face_normal: wp.array[wp.vec3],
    spacing_m: float,
    floor_map: FloorMap,
    positions: wp.array2d[wp.vec3],
    flat_plane: int,
    plane_z: float,
    walls_id: int,
    flux: wp.array4d[wp.float32],
    texels: wp.array3d[wp.float32],
    face_flux: wp.array2d[wp.float32],
    coarse_count: wp.array[wp.int32],
    splatted: wp.array[wp.int32],
):
    """Photon p on a receiver other than the floor with a lattice cell: its flux spread over the
    receiver's faces that the cell covers (``face_flux`` (F_other, K) [W nm^-1]), each its overlap
    / the cell's covered area; ``splatted[p]`` = 1. Runs after :func:`splat_footprints`, which
    clears ``splatted``; photons it leaves keep the face deposit.

    On a pool's wall (receiver ``walls_id``) above a flat floor (``flat_plane``, as in
    :func:`splat_footprints`) the cell of a photon next to one on the floor may reach below the
    floor: that part is the strip of floor between the wall and the floor photons' cells. Its share
    is the part of the cell, continued along the rays to the floor plane, that lies inside the map;
    it is spread over the map as a floor photon's cell is (the rest of the continued cell lies
    beyond the wall and is dropped), and the wall's faces share the rest."""
    p = wp.tid()
    f = ph.face[p]
    if f < ph.floor_face_count:  # the floor's, or no receiver
        return
    r = face_receiver[f]
    k0 = (p / ph.photons_per_group) * ph.wavelengths_per_group
    share = float(0.0)  # the floor's
    if flat_plane != 0 and r == walls_id and floor_map.wrap == 0 and floor_neighbour(ph, p) != 0:
        share = floor_part(positions, ph, face_receiver, p, plane_z, floor_map, flux, texels, coarse_count,
                           k0, spacing_m)
    c = ph.hit[p]
    ell = ph.path_before[p] + wp.length(c - ph.origin[p])
    rest = ph.weight[p] * (1.0 - share)
    eu, ev, ok = photon_lattice(ph.hit, ph.face, face_receiver, face_normal, p, ph.quads, ph.subdivisions,
                                ph.periodic, ph.extent_m, spacing_m)
    if ok != 0:
        normal = wp.normalize(wp.cross(eu, ev))
        if wp.dot(normal, face_normal[f]) < 0.0:
            normal = -normal
        corner = 0.5 * (wp.abs(eu) + wp.abs(ev))  # half the cell's box
        reach = CELL_REACH * wp.max(wp.length(eu), wp.length(ev))
        lo = c - corner - wp.vec3(reach)
        hi = c + corner + wp.vec3(reach)
        a_axis, b_axis = cell_axes(eu, ev, normal)
        covered = cell_faces(mesh, points, indices, face_receiver, face_normal, r, normal, c, a_axis, b_axis,
                             lo, hi, 0.0, face_flux, ph, k0, ell)  # the cover alone
        if covered >= MIN_CELL_COVER * (1.0 - share) and covered > 0.0:
            cell_faces(mesh, points, indices, face_receiver, face_normal, r, normal, c, a_axis, b_axis, lo,
                       hi, rest / covered, face_flux, ph, k0, ell)  # the deposit, over the same faces
            splatted[p] = 1
            return
    if share > 0.0:  # the floor took its part: the rest goes to the photon's face
        add_face_flux(face_flux, f - ph.floor_face_count, rest, ph, k0, ell)
        splatted[p] = 1
