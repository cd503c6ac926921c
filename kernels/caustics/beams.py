"""Warped beam volumes (Sandberg & Falemo 2005; Ernst et al. 2005; Liktor & Dachsbacher 2011).

One beam per surface triangle (or adaptive leaf quad's triangle) and index group: its base
vertices v_i on the displaced surface, the unit refracted directions d_i of its three edges, the
transmittance T_i at each vertex, the length e_i along each edge to the first receiver (a ray
query on the receivers' BVH), and its flux weight ``w = A⊥`` [m²] (the triangle's area projected
perpendicular to the sun). Beams are stored flat, index ``(g · leaves + leaf) · 2 + half``; the
uniform grid lists its quads row-major, so there ``((g Q + qy) Q + qx) 2 + half``. A beam that
carries nothing (facing away from the sun, no vertex transmitting) has ``w = 0``.

The horizontal section of a beam at height z has vertices ``p_i(z) = v_i + (z − v_iz)/d_iz · d_i``
and signed area ``A(z) = a0 + a1 z + a2 z²`` (DESIGN.md). A point P is in the beam iff it lies in
the section at P_z (a watertight test: a point on an edge shared by two beams counts once); its
barycentrics λ there interpolate the transmittance, the path length ℓ = Σ λ_i (v_iz − P_z)/|d_iz|
and the direction. The flux density on a horizontal plane is
``E_sun(k) · w · Σλ_i T_i · exp(−c(k) ℓ) / |A(P_z)|``; on a receiver with unit normal n it is
multiplied by ``|d·n| / |d_z|`` (``flat`` interpolation: flux spread uniformly in barycentric
terms, so a section receives exactly ``E_sun · w · mean(T)`` without absorption).

A beam ends at the plane through its three edge ends. Where something can shadow a receiver point
(walls, meshes, a relief) a shadow ray through the BVH decides whether the beam reaches it;
otherwise a point more than one beam width beyond the end plane is unlit (``shadow_slack``).

Binning (Laine & Karras 2011; Kerbl et al. 2023): every beam (or periodic copy of a beam) gets a
span of tiles, tiles count their beams (atomics), an exclusive scan gives each tile's start, and
a scatter fills the per-tile lists; each query (texel, receiver point, pixel) then loops only over
its tile's list and adds up additively, so the order of beams never matters except for rounding.
On the GPU the order inside a tile follows the atomics, so sums may differ in the last bits from
run to run; on the CPU launches are serial and the result is deterministic.
"""

import warp as wp

from warpcaustics.kernels.caustics.fluxratio import lift, quad_corner
from warpcaustics.kernels.geometry import clip_side, clip_to_slab, polygon_area, sun_into_water, vec8
from warpcaustics.kernels.optics.phase import phase_value
from warpcaustics.kernels.scene.camera import PinholeCamera

wp.set_module_options({"enable_backward": False})

RAY_LENGTH_M = 1.0e5
"""Longest edge traced to a receiver [m]."""

MIN_AREA_FRACTION = 1.0e-6
"""|A(z)| is floored at this fraction of the beam's base-section area (a focus is a finite peak)."""

PARALLEL_COS = 1.0e-4
"""``|v × d̄|`` below which a view ray counts as running along a beam (DESIGN.md)."""

MAX_CHORD_PIECES = 16
"""Most midpoint pieces a scan-plane chord is split into for the in-scattering integral."""


@wp.func
def corner_ray(
    positions: wp.array2d[wp.vec3],
    normals: wp.array2d[wp.vec3],
    visible: wp.array2d[wp.float32],
    qx: int,
    qy: int,
    level: int,
    half: int,
    corner: int,
    extent_m: float,
    periodic: int,
    sun_dir: wp.vec3,
    eta: float,
):
    """Surface vertex of a triangle corner (periodic wrap / wall offset applied), its refracted
    unit direction and its transmittance (Fresnel × sun visibility). A quad of ``level`` > 0 spans
    2^level cells (periodic seas only): (qx, qy) index the quads of that size."""
    n = positions.shape[0]
    x = int(0)
    y = int(0)
    s = wp.vec2(0.0)
    if level == 0:
        x, y, s = quad_corner(qx, qy, half, corner, n, extent_m, periodic)
    else:
        size = 1 << level
        o = corner_offset(half, corner)
        x = (qx + o[0]) * size
        y = (qy + o[1]) * size
        if x >= n:
            x -= n
            s[0] = extent_m
        if y >= n:
            y -= n
            s[1] = extent_m
    d, t = sun_into_water(normals[y, x], sun_dir, eta)
    if t <= 0.0:
        # No refracted ray of its own (lit from behind, or refracted upwards): its edge follows the
        # sun refracted by still water, the same for every beam at this vertex (so neighbouring beams
        # keep sharing the edge); it carries nothing, so the beam's light fades to zero towards it.
        d, t = sun_into_water(wp.vec3(0.0, 0.0, 1.0), sun_dir, eta)
        t = 0.0
    return lift(positions[y, x], s), d, t * visible[y, x]


@wp.func
def corner_offset(half: int, corner: int) -> wp.vec2i:
    """Lattice offset (dx, dy) of a triangle corner in its quad (kernels/floor.py quad_corner)."""
    if corner == 0:
        return wp.vec2i(0, 0)
    if half == 0:
        if corner == 1:
            return wp.vec2i(1, 0)
        return wp.vec2i(1, 1)
    if corner == 1:
        return wp.vec2i(1, 1)
    return wp.vec2i(0, 1)


@wp.func
def edge_end(mesh: wp.uint64, origin: wp.vec3, d: wp.vec3, plane_z: float) -> float:
    """Length along an edge to the first receiver; a miss ends on the plane z = plane_z."""
    q = wp.mesh_query_ray(mesh, origin, d, RAY_LENGTH_M)
    if q.result:
        return q.t
    return wp.max((origin[2] - plane_z) / wp.max(-d[2], 1.0e-6), 0.0)


@wp.func
def cross2(a: wp.vec2, b: wp.vec2) -> float:
    return a[0] * b[1] - a[1] * b[0]


@wp.func
def xy(v: wp.vec3) -> wp.vec2:
    return wp.vec2(v[0], v[1])


@wp.func
def section_vertex(v: wp.vec3, d: wp.vec3, z: float) -> wp.vec2:
    """p_i(z): where the edge line v + t d crosses height z (d_z < 0 for every kept beam)."""
    return xy(v) + ((z - v[2]) / d[2]) * xy(d)


@wp.kernel
def build_beams(
    positions: wp.array2d[wp.vec3],
    normals: wp.array2d[wp.vec3],
    visible: wp.array2d[wp.float32],
    ior: wp.array[wp.float32],
    sun_dir: wp.vec3,
    extent_m: float,
    periodic: int,
    plane_z: float,
    mesh: wp.uint64,
    leaves: wp.array[wp.vec3i],
    base: wp.array2d[wp.vec3],
    direction: wp.array2d[wp.vec3],
    transmit: wp.array2d[wp.float32],
    end_m: wp.array2d[wp.float32],
    ends: wp.array2d[wp.vec3],
    weight: wp.array[wp.float32],
    area_coef: wp.array[wp.vec3],
    dropped: wp.array[wp.int32],
):
    """Build beam (g · leaves + leaf) · 2 + half from the leaf quad (qx, qy, level). The uniform grid
    lists every quad at level 0 in row-major order, so its beam index is ((g Q + qy) Q + qx) 2 + half.
    On a periodic sea the beam is moved by whole periods so that its mean ray lands inside the patch
    on the plane ``plane_z`` (as photons are)."""
    g, leaf, half = wp.tid()
    b = (g * leaves.shape[0] + leaf) * 2 + half
    qx = leaves[leaf][0]
    qy = leaves[leaf][1]
    lv = leaves[leaf][2]
    eta = 1.0 / ior[g]
    p0, d0, t0 = corner_ray(
        positions, normals, visible, qx, qy, lv, half, 0, extent_m, periodic, sun_dir, eta
    )
    p1, d1, t1 = corner_ray(
        positions, normals, visible, qx, qy, lv, half, 1, extent_m, periodic, sun_dir, eta
    )
    p2, d2, t2 = corner_ray(
        positions, normals, visible, qx, qy, lv, half, 2, extent_m, periodic, sun_dir, eta
    )
    a_perp = 0.5 * wp.dot(wp.cross(p1 - p0, p2 - p0), sun_dir)
    w = float(0.0)
    if a_perp > 0.0 and t0 + t1 + t2 > 0.0:
        w = a_perp
    if periodic != 0:
        c = (p0 + p1 + p2) / 3.0
        dm = wp.normalize(d0 + d1 + d2)
        land = c + ((plane_z - c[2]) / wp.min(dm[2], -1.0e-6)) * dm
        shift = wp.vec3(
            -extent_m * wp.floor(land[0] / extent_m + 0.5),
            -extent_m * wp.floor(land[1] / extent_m + 0.5),
            0.0,
        )
        p0 = p0 + shift
        p1 = p1 + shift
        p2 = p2 + shift
    base[b, 0] = p0
    base[b, 1] = p1
    base[b, 2] = p2
    direction[b, 0] = d0
    direction[b, 1] = d1
    direction[b, 2] = d2
    transmit[b, 0] = t0
    transmit[b, 1] = t1
    transmit[b, 2] = t2
    # A(z) = 0.5 cross(p1(z) − p0(z), p2(z) − p0(z)) with p_i(z) = u_i + z r_i, r_i = d_xy / d_z.
    r0 = xy(d0) / d0[2]
    r1 = xy(d1) / d1[2]
    r2 = xy(d2) / d2[2]
    u1 = xy(p1) - p1[2] * r1 - (xy(p0) - p0[2] * r0)
    u2 = xy(p2) - p2[2] * r2 - (xy(p0) - p0[2] * r0)
    q1 = r1 - r0
    q2 = r2 - r0
    area_coef[b] = 0.5 * wp.vec3(cross2(u1, u2), cross2(u1, q2) + cross2(q1, u2), cross2(q1, q2))
    if w > 0.0:
        # Edges are traced from a hair inside the triangle: a wall vertex of a walled pool lies on
        # the wall, and its edge running down the wall would otherwise stop there at once.
        c = (p0 + p1 + p2) / 3.0
        end_m[b, 0] = edge_end(mesh, p0 + 1.0e-5 * (c - p0), d0, plane_z)
        end_m[b, 1] = edge_end(mesh, p1 + 1.0e-5 * (c - p1), d1, plane_z)
        end_m[b, 2] = edge_end(mesh, p2 + 1.0e-5 * (c - p2), d2, plane_z)
    else:
        wp.atomic_add(dropped, 0, 1)
        end_m[b, 0] = 0.0
        end_m[b, 1] = 0.0
        end_m[b, 2] = 0.0
    fill_ends(base, direction, end_m, b, ends)
    weight[b] = w


@wp.kernel
def vertex_rays(
    positions: wp.array2d[wp.vec3],
    normals: wp.array2d[wp.vec3],
    ior: float,
    sun_dir: wp.vec3,
    extent_m: float,
    plane_z: float,
    mesh: wp.uint64,
    direction: wp.array2d[wp.vec3],
    length_m: wp.array2d[wp.float32],
):
    """Refracted direction of every surface vertex and its length to the first receiver (moved by
    whole periods to land in the patch, as beams are): what the refinement criteria look at."""
    j, i = wp.tid()
    d, t = sun_into_water(normals[j, i], sun_dir, 1.0 / ior)
    p = positions[j, i]
    land = p + ((plane_z - p[2]) / wp.min(d[2], -1.0e-6)) * d
    p = p - wp.vec3(
        extent_m * wp.floor(land[0] / extent_m + 0.5), extent_m * wp.floor(land[1] / extent_m + 0.5), 0.0
    )
    direction[j, i] = d
    length_m[j, i] = edge_end(mesh, p, d, plane_z)


@wp.func
def vertex_index(c: int, n: int) -> int:
    return ((c % n) + n) % n


@wp.kernel
def refine_quads(
    quads: wp.array[wp.vec3i],
    positions: wp.array2d[wp.vec3],
    direction: wp.array2d[wp.vec3],
    length_m: wp.array2d[wp.float32],
    tolerance_m: float,
    end_jump: float,
    extent_m: float,
    use_camera: int,
    cam: PinholeCamera,
    max_pixels: float,
    split: wp.array[wp.int32],
):
    """Liktor & Dachsbacher (2011) §4.2, on our lattice: split quad (qx, qy, level) of 2^level cells
    into its four children where (a) some vertex inside it, followed along its own refracted ray to
    its receiver, misses the ray the coarse quad interpolates bilinearly from its corners by more
    than ``tolerance_m`` (curvature: strong focusing, normal discontinuities), (b) its corners'
    lengths to the receivers differ by more than ``end_jump`` (a depth discontinuity: an object's
    edge), or (c) its footprint on the camera's screen spans more than ``max_pixels``."""
    q = wp.tid()
    qx = quads[q][0]
    qy = quads[q][1]
    size = 1 << quads[q][2]
    n = direction.shape[0]
    x0 = qx * size
    y0 = qy * size
    x1 = vertex_index(x0 + size, n)
    y1 = vertex_index(y0 + size, n)
    d00 = direction[y0, x0]
    d10 = direction[y0, x1]
    d01 = direction[y1, x0]
    d11 = direction[y1, x1]
    e00 = length_m[y0, x0]
    e10 = length_m[y0, x1]
    e01 = length_m[y1, x0]
    e11 = length_m[y1, x1]
    lo = wp.min(wp.min(e00, e10), wp.min(e01, e11))
    hi = wp.max(wp.max(e00, e10), wp.max(e01, e11))
    result = int(0)
    if hi > (1.0 + end_jump) * lo + 1.0e-6:
        result = 1
    for jj in range(size + 1):
        for ii in range(size + 1):
            if result == 0:
                u = float(ii) / float(size)
                v = float(jj) / float(size)
                d_int = wp.normalize(
                    (1.0 - v) * ((1.0 - u) * d00 + u * d10) + v * ((1.0 - u) * d01 + u * d11)
                )
                yi = vertex_index(y0 + jj, n)
                xi = vertex_index(x0 + ii, n)
                if length_m[yi, xi] * wp.length(direction[yi, xi] - d_int) > tolerance_m:
                    result = 1
    if result == 0 and use_camera != 0:
        # The periodic copy of the quad nearest the camera, its base and end corners on the screen.
        shift = period_shift(xy(cam.position), xy(positions[y0, x0]), extent_m, 1)
        lo2 = wp.vec2(1.0e30)
        hi2 = wp.vec2(-1.0e30)
        for c in range(4):
            xi = x0 + (c % 2) * size
            yi = y0 + (c / 2) * size
            lift_m = wp.vec3(shift[0], shift[1], 0.0)
            if xi >= n:
                lift_m = lift_m + wp.vec3(extent_m, 0.0, 0.0)
            if yi >= n:
                lift_m = lift_m + wp.vec3(0.0, extent_m, 0.0)
            xi = vertex_index(xi, n)
            yi = vertex_index(yi, n)
            p = positions[yi, xi] + lift_m
            for k in range(2):
                x = p + (float(k) * length_m[yi, xi]) * direction[yi, xi]
                z = wp.dot(x - cam.position, cam.forward)
                if z > NEAR_M:
                    sp = screen_xy(cam, x, z)
                    lo2 = wp.min(lo2, sp)
                    hi2 = wp.max(hi2, sp)
        if hi2[0] > lo2[0] and wp.max(hi2[0] - lo2[0], hi2[1] - lo2[1]) > max_pixels:
            result = 1
    split[q] = result


@wp.func
def section_area(coef: wp.vec3, z: float) -> float:
    """Signed area A(z) of the horizontal section [m²]."""
    return coef[0] + z * (coef[1] + z * coef[2])


@wp.func
def safe_area(coef: wp.vec3, z: float, base_z: float) -> float:
    """|A(z)| floored at MIN_AREA_FRACTION of |A| at the base (a focus stays finite)."""
    return wp.max(
        wp.abs(section_area(coef, z)), MIN_AREA_FRACTION * wp.abs(section_area(coef, base_z)) + 1.0e-20
    )


@wp.func
def barycentrics(a: wp.vec2, b: wp.vec2, c: wp.vec2, p: wp.vec2) -> wp.vec3:
    """Barycentric coordinates of p in triangle (a, b, c), either orientation; (−1, …) if degenerate."""
    det = cross2(b - a, c - a)
    if det == 0.0:
        return wp.vec3(-1.0, 0.0, 0.0)
    l1 = cross2(p - a, c - a) / det
    l2 = cross2(b - a, p - a) / det
    return wp.vec3(1.0 - l1 - l2, l1, l2)


@wp.func
def edge_function(p: wp.vec2, q: wp.vec2, x: wp.vec2) -> float:
    """cross(q − p, x − p), computed from the lexicographically smaller end point so that the two
    triangles sharing an edge get exactly opposite values (a watertight inside test)."""
    if p[0] > q[0] or (p[0] == q[0] and p[1] > q[1]):
        return -cross2(p - q, x - q)
    return cross2(q - p, x - p)


@wp.func
def owns_edge(p: wp.vec2, q: wp.vec2, orientation: float) -> bool:
    """Tie-break for points exactly on edge p → q of a triangle of the given orientation (sign of
    its area): the edge belongs to the triangle if, walked counter-clockwise, it points down, or
    left when horizontal; the neighbour walks it the other way, so exactly one of them owns it."""
    e = (q - p) * orientation
    return e[1] < 0.0 or (e[1] == 0.0 and e[0] < 0.0)


@wp.func
def inside_triangle(a: wp.vec2, b: wp.vec2, c: wp.vec2, x: wp.vec2):
    """(inside, barycentrics) of x in triangle (a, b, c), either orientation. Points on an edge
    shared by two triangles count in exactly one of them (``owns_edge``), so neighbouring beams
    neither double-count nor miss a sample on their common edge."""
    det = cross2(b - a, c - a)
    if det == 0.0:
        return False, wp.vec3(-1.0, 0.0, 0.0)
    o = wp.sign(det)
    e0 = edge_function(b, c, x) * o
    e1 = edge_function(c, a, x) * o
    e2 = edge_function(a, b, x) * o
    inside = True
    if e0 < 0.0 or e1 < 0.0 or e2 < 0.0:
        inside = False
    if e0 == 0.0 and not owns_edge(b, c, o):
        inside = False
    if e1 == 0.0 and not owns_edge(c, a, o):
        inside = False
    if e2 == 0.0 and not owns_edge(a, b, o):
        inside = False
    return inside, wp.vec3(e0, e1, e2) / wp.abs(det)


MAX_COPIES_PER_AXIS = 64
"""A section wider than this many periods of the patch (a beam of near-horizontal rays) is gathered
in its MAX_COPIES_PER_AXIS central copies per axis only."""


@wp.func
def copy_range(lo: float, hi: float, a: float, width: float, extent_m: float, periodic: int):
    """Whole periods k for which the interval [a + k L, a + k L + width] meets [lo, hi] (k = 0 only
    on a walled pool), at most MAX_COPIES_PER_AXIS of them; an empty range has k1 < k0."""
    if periodic == 0:
        return 0, 0
    k0 = wp.ceil((lo - a - width) / extent_m)
    k1 = wp.floor((hi - a) / extent_m)
    if k1 - k0 >= float(MAX_COPIES_PER_AXIS):
        mid = wp.floor(0.5 * (k0 + k1))
        k0 = mid - float(MAX_COPIES_PER_AXIS / 2)
        k1 = k0 + float(MAX_COPIES_PER_AXIS - 1)
    return int(k0), int(k1)


@wp.func
def period_shift(target: wp.vec2, p: wp.vec2, extent_m: float, periodic: int) -> wp.vec2:
    """The whole-period shift that moves p nearest to target (zero on a walled pool)."""
    if periodic == 0:
        return wp.vec2(0.0)
    return wp.vec2(
        extent_m * wp.floor((target[0] - p[0]) / extent_m + 0.5),
        extent_m * wp.floor((target[1] - p[1]) / extent_m + 0.5),
    )


@wp.struct
class BeamSample:
    """A beam seen at one point: inside?, barycentrics, path from the surface ℓ [m], interpolated
    unit direction, Σλ_i T_i, |A(z)| [m²], and how far the point is beyond the beam's end [m]."""

    inside: int
    lam: wp.vec3
    path_m: float
    d: wp.vec3
    transmit: float
    area: float
    beyond_end_m: float


@wp.func
def sample_beam(
    base: wp.array2d[wp.vec3],
    direction: wp.array2d[wp.vec3],
    transmit: wp.array2d[wp.float32],
    ends: wp.array2d[wp.vec3],
    area_coef: wp.array[wp.vec3],
    b: int,
    p: wp.vec3,
) -> BeamSample:
    """The beam b at point p (already moved into the beam's periodic image)."""
    out = BeamSample()
    out.inside = 0
    v0 = base[b, 0]
    v1 = base[b, 1]
    v2 = base[b, 2]
    d0 = direction[b, 0]
    d1 = direction[b, 1]
    d2 = direction[b, 2]
    z = p[2]
    inside, lam = inside_triangle(
        section_vertex(v0, d0, z), section_vertex(v1, d1, z), section_vertex(v2, d2, z), xy(p)
    )
    if not inside:
        return out
    l0 = (v0[2] - z) / -d0[2]
    l1 = (v1[2] - z) / -d1[2]
    l2 = (v2[2] - z) / -d2[2]
    path = lam[0] * l0 + lam[1] * l1 + lam[2] * l2
    if path < 0.0:
        return out  # above the water surface (a wall's top): the beam starts below
    out.inside = 1
    out.lam = lam
    out.path_m = path
    out.d = wp.normalize(lam[0] * d0 + lam[1] * d1 + lam[2] * d2)
    out.transmit = lam[0] * transmit[b, 0] + lam[1] * transmit[b, 1] + lam[2] * transmit[b, 2]
    out.area = safe_area(area_coef[b], z, (v0[2] + v1[2] + v2[2]) / 3.0)
    out.beyond_end_m = beyond_end(ends, b, p)
    return out


@wp.func
def end_plane(
    base: wp.array2d[wp.vec3], direction: wp.array2d[wp.vec3], end_m: wp.array2d[wp.float32], b: int
):
    """A point of the plane through the three edge ends and its unit normal along the beam."""
    e0 = base[b, 0] + end_m[b, 0] * direction[b, 0]
    e1 = base[b, 1] + end_m[b, 1] * direction[b, 1]
    e2 = base[b, 2] + end_m[b, 2] * direction[b, 2]
    along = direction[b, 0] + direction[b, 1] + direction[b, 2]
    nrm = wp.cross(e1 - e0, e2 - e0)
    if wp.length(nrm) <= 1.0e-12 * wp.max(wp.length_sq(e1 - e0) + wp.length_sq(e2 - e0), 1.0e-30):
        nrm = wp.vec3(0.0, 0.0, -1.0)  # collinear ends: a horizontal end plane at their mean
        e0 = (e0 + e1 + e2) / 3.0
    nrm = wp.normalize(nrm)
    if wp.dot(nrm, along) < 0.0:
        nrm = -nrm
    return e0, nrm


@wp.func
def fill_ends(
    base: wp.array2d[wp.vec3],
    direction: wp.array2d[wp.vec3],
    end_m: wp.array2d[wp.float32],
    b: int,
    ends: wp.array2d[wp.vec3],
):
    """ends[b] = (a point of the end plane, its unit normal along the beam, the unit mean edge
    direction d̄, the base plane's unit normal towards d̄): what the shadow test and the scan planes
    read per beam."""
    e0, ne = end_plane(base, direction, end_m, b)
    dbar = wp.normalize(direction[b, 0] + direction[b, 1] + direction[b, 2])
    nb = wp.normalize(wp.cross(base[b, 1] - base[b, 0], base[b, 2] - base[b, 0]))
    if wp.dot(nb, dbar) < 0.0:
        nb = -nb
    ends[b, 0] = e0
    ends[b, 1] = ne
    ends[b, 2] = dbar
    ends[b, 3] = nb


@wp.func
def beyond_end(ends: wp.array2d[wp.vec3], b: int, p: wp.vec3) -> float:
    """How far p lies beyond the beam's end plane (``ends[b] = (point, unit normal)``) [m]."""
    return wp.dot(p - ends[b, 0], ends[b, 1])


@wp.func
def lit(mesh: wp.uint64, occluders: int, s: BeamSample, p: wp.vec3) -> bool:
    """Whether the beam's light reaches receiver point p. With occluders (walls, meshes, a relief)
    a ray from p back along the beam towards the surface must reach it unblocked (exact shadows at
    the resolution of the BVH); with a flat floor alone the beam's end plane decides."""
    if occluders == 0:
        return s.beyond_end_m <= shadow_slack(s.area)
    eps = 1.0e-4 * (1.0 + s.path_m)
    length = s.path_m - 2.0 * eps
    if length <= 0.0:
        return True
    q = wp.mesh_query_ray(mesh, p - eps * s.d, -s.d, length)
    return not q.result


@wp.func
def shadow_slack(area: float) -> float:
    """A point counts as lit up to one beam width (√|A|) beyond the beam's end plane: receivers are
    curved between edge ends, occluders lie well beyond."""
    return wp.sqrt(area) + 1.0e-4


# --- binning ------------------------------------------------------------------------------------


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


# --- queries ------------------------------------------------------------------------------------


@wp.func
def ring_density(
    weight: wp.array[wp.float32],
    area_coef: wp.array[wp.vec3],
    base: wp.array2d[wp.vec3],
    g: int,
    vx: int,
    vy: int,
    quads: int,
    periodic: int,
    z: float,
) -> float:
    """Wave-front density at lattice vertex (vx, vy) and height z: the flux weight of the (up to
    six) carrying beams around the vertex over the area of their sections, Σ w / Σ |A(z)|."""
    num = float(0.0)
    den = float(0.0)
    for r in range(6):
        # The six triangles at a vertex: quads (0,0) both halves, (−1,0) half 0, (−1,−1) both,
        # (0,−1) half 1 (see kernels/floor.py for the corner order of each half).
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
        if weight[bb] > 0.0:
            num += weight[bb]
            den += safe_area(area_coef[bb], z, (base[bb, 0][2] + base[bb, 1][2] + base[bb, 2][2]) / 3.0)
    if den <= 0.0:
        return 0.0
    return num / den


@wp.func
def flux_density(
    weight: wp.array[wp.float32],
    transmit: wp.array2d[wp.float32],
    area_coef: wp.array[wp.vec3],
    base: wp.array2d[wp.vec3],
    b: int,
    s: BeamSample,
    z: float,
    quads: int,
    periodic: int,
    smooth: int,
) -> float:
    """Horizontal flux density at a point of beam b per unit solar irradiance, before attenuation
    [-]. ``smooth == 0``: the beam's own ``w Σλ_i T_i / |A(z)|`` (each section receives exactly its
    flux). ``smooth == 1`` (Ernst et al. 2005's interpolation across beams): ``Σ λ_i T_i ρ_i`` with
    ρ_i the wave-front density of the beams around vertex i at this height, so the irradiance is
    continuous from beam to beam and no triangle edges show; flux is then conserved only to the
    interpolation's accuracy (docs/validation.md)."""
    if smooth == 0:
        return weight[b] * s.transmit / s.area
    per_group = quads * quads * 2
    g = b / per_group
    rest = b - g * per_group
    half = rest % 2
    qx = (rest / 2) % quads
    qy = (rest / 2) / quads
    total = float(0.0)
    for c in range(3):
        o = corner_offset(half, c)
        rho = ring_density(weight, area_coef, base, g, qx + o[0], qy + o[1], quads, periodic, z)
        total += s.lam[c] * transmit[b, c] * rho
    return total


@wp.func
def add_beam_irradiance(
    out: wp.array2d[wp.float32],
    point: int,
    scale: float,
    b: int,
    s: BeamSample,
    density: float,
    beams_per_group: int,
    wavelengths_per_group: int,
    sun_irradiance: wp.array[wp.float32],
    attenuation_per_m: wp.array[wp.float32],
):
    """out[k, point] += scale · E_sun(k) · density · exp(−c(k) ℓ) for the bands of b's group."""
    g = b / beams_per_group
    f = scale * density
    for j in range(wavelengths_per_group):
        k = g * wavelengths_per_group + j
        out[k, point] = out[k, point] + f * sun_irradiance[k] * wp.exp(-attenuation_per_m[k] * s.path_m)


@wp.kernel
def point_irradiance(
    grid: TileGrid,
    tile_start: wp.array[wp.int32],
    tile_count: wp.array[wp.int32],
    tile_items: wp.array[wp.int32],
    base: wp.array2d[wp.vec3],
    direction: wp.array2d[wp.vec3],
    transmit: wp.array2d[wp.float32],
    ends: wp.array2d[wp.vec3],
    weight: wp.array[wp.float32],
    area_coef: wp.array[wp.vec3],
    beams_per_group: int,
    wavelengths_per_group: int,
    sun_irradiance: wp.array[wp.float32],
    attenuation_per_m: wp.array[wp.float32],
    extent_m: float,
    periodic: int,
    mesh: wp.uint64,
    occluders: int,
    quads: int,
    smooth: int,
    points: wp.array[wp.vec3],
    normals: wp.array[wp.vec3],
    point_ids: wp.array[wp.int32],
    out: wp.array2d[wp.float32],
):
    """Irradiance on the receiver at each point (K, P) [W m^-2 nm^-1] (points with id < 0 skipped):
    the sum over the beams of the point's horizontal tile of ``E_h · |d·n| / |d_z|``."""
    p_index = wp.tid()
    for k in range(out.shape[0]):
        out[k, p_index] = 0.0
    if point_ids[p_index] < 0:
        return
    p = points[p_index]
    n = normals[p_index]
    t = tile_of(grid, xy(p))
    if t < 0:
        return
    start = tile_start[t]
    for item in range(tile_count[t]):
        b = tile_items[start + item]
        s0 = section_vertex(base[b, 0], direction[b, 0], p[2])
        s1 = section_vertex(base[b, 1], direction[b, 1], p[2])
        s2 = section_vertex(base[b, 2], direction[b, 2], p[2])
        lo = wp.min(wp.min(s0, s1), s2)
        hi = wp.max(wp.max(s0, s1), s2)
        kx0, kx1 = copy_range(lo[0], hi[0], p[0], 0.0, extent_m, periodic)
        ky0, ky1 = copy_range(lo[1], hi[1], p[1], 0.0, extent_m, periodic)
        for ky in range(ky0, ky1 + 1):
            for kx in range(kx0, kx1 + 1):  # every periodic copy of the point the section may hold
                q = p + wp.vec3(float(kx) * extent_m, float(ky) * extent_m, 0.0)
                s = sample_beam(base, direction, transmit, ends, area_coef, b, q)
                if s.inside == 0:
                    continue
                if not lit(mesh, occluders, s, q):
                    continue
                cos_factor = wp.abs(wp.dot(s.d, n)) / wp.abs(s.d[2])
                density = flux_density(weight, transmit, area_coef, base, b, s, q[2], quads, periodic, smooth)
                add_beam_irradiance(
                    out,
                    p_index,
                    cos_factor,
                    b,
                    s,
                    density,
                    beams_per_group,
                    wavelengths_per_group,
                    sun_irradiance,
                    attenuation_per_m,
                )


@wp.struct
class BeamCorners:
    """What the volume pass reads of beam b, once per beam a thread meets (per pixel on the GPU, per
    tile on the CPU): base vertices v_i, unit edge directions d_i, per-vertex transmittance, A(z)'s
    coefficients, the base centroid's height, ``ends[b]`` (end plane point and normal, d̄, base
    plane normal) and 1/d_z of each edge (for :func:`clamped_sample`)."""

    v0: wp.vec3
    v1: wp.vec3
    v2: wp.vec3
    d0: wp.vec3
    d1: wp.vec3
    d2: wp.vec3
    transmit: wp.vec3
    coef: wp.vec3
    base_z: float
    end_point: wp.vec3
    end_normal: wp.vec3
    dbar: wp.vec3
    base_normal: wp.vec3
    inv_dz: wp.vec3


@wp.func
def edge_corners(
    base: wp.array2d[wp.vec3], direction: wp.array2d[wp.vec3], ends: wp.array2d[wp.vec3], b: int
) -> BeamCorners:
    """The geometry of beam b (all :func:`scan_chord` and :func:`clamped_sample`'s geometry reads):
    vertices, edges, ``ends[b]`` and the edges' 1/d_z."""
    c = BeamCorners()
    c.v0 = base[b, 0]
    c.v1 = base[b, 1]
    c.v2 = base[b, 2]
    c.d0 = direction[b, 0]
    c.d1 = direction[b, 1]
    c.d2 = direction[b, 2]
    c.base_z = (c.v0[2] + c.v1[2] + c.v2[2]) / 3.0
    c.end_point = ends[b, 0]
    c.end_normal = ends[b, 1]
    c.dbar = ends[b, 2]
    c.base_normal = ends[b, 3]
    c.inv_dz = wp.vec3(1.0 / c.d0[2], 1.0 / c.d1[2], 1.0 / c.d2[2])
    return c


@wp.func
def load_corners(
    base: wp.array2d[wp.vec3],
    direction: wp.array2d[wp.vec3],
    transmit: wp.array2d[wp.float32],
    ends: wp.array2d[wp.vec3],
    area_coef: wp.array[wp.vec3],
    b: int,
) -> BeamCorners:
    c = edge_corners(base, direction, ends, b)
    c.transmit = wp.vec3(transmit[b, 0], transmit[b, 1], transmit[b, 2])
    c.coef = area_coef[b]
    return c


@wp.func
def clamped_sample(c: BeamCorners, p: wp.vec3) -> BeamSample:
    """:func:`sample_beam` with the barycentrics clamped to the triangle and renormalised: for points
    on a section's edge to rounding, and for scan-plane samples of a warped beam, whose chord
    follows the edge lines' plane cut rather than the horizontal sections exactly."""
    z = p[2]
    # Distances along the edges to height z: the section's vertices and the path length share them.
    l0 = (z - c.v0[2]) * c.inv_dz[0]
    l1 = (z - c.v1[2]) * c.inv_dz[1]
    l2 = (z - c.v2[2]) * c.inv_dz[2]
    # Barycentrics times the section's signed doubled area: the renormalisation below divides the
    # area out, so only its sign is needed (and a degenerate section takes the centroid).
    a = xy(c.v0) + l0 * xy(c.d0)
    ab = xy(c.v1) + l1 * xy(c.d1) - a
    ac = xy(c.v2) + l2 * xy(c.d2) - a
    ap = xy(p) - a
    det = cross2(ab, ac)
    lam = wp.vec3(1.0)
    if det != 0.0:
        e1 = cross2(ap, ac)
        e2 = cross2(ab, ap)
        lam = wp.vec3(det - e1 - e2, e1, e2) * wp.sign(det)
        lam = wp.vec3(wp.max(lam[0], 0.0), wp.max(lam[1], 0.0), wp.max(lam[2], 0.0))
    total = lam[0] + lam[1] + lam[2]
    # A section narrower than ~1e-8 m (or a NaN total) takes the centroid: 1/total stays finite,
    # and so does 1/|d| below, as |d|² ~ total² stays a normal float32.
    if not (total > 1.0e-15):  # [m²]
        lam = wp.vec3(1.0)
        total = 3.0
    # The direction needs only the barycentrics' ratios, so it is formed from the unnormalised ones:
    # the phase function's chain of dependent operations then does not wait for the division below.
    d = lam[0] * c.d0 + lam[1] * c.d1 + lam[2] * c.d2
    lam = lam * (1.0 / total)
    out = BeamSample()
    out.inside = 1
    out.lam = lam
    out.path_m = lam[0] * l0 + lam[1] * l1 + lam[2] * l2
    out.d = d * (1.0 / wp.length(d))
    out.transmit = lam[0] * c.transmit[0] + lam[1] * c.transmit[1] + lam[2] * c.transmit[2]
    out.area = safe_area(c.coef, z, c.base_z)
    out.beyond_end_m = wp.dot(p - c.end_point, c.end_normal)
    return out


@wp.func
def plane_cut(v: wp.vec3, d: wp.vec3, a: wp.vec3, n: wp.vec3) -> wp.vec2:
    """(x, y) where the edge line v + t d meets the plane through a with normal n."""
    t = wp.dot(a - v, n) / wp.dot(d, n)
    return xy(v + t * d)


@wp.kernel
def floor_texels(
    grid: TileGrid,
    tile_start: wp.array[wp.int32],
    tile_count: wp.array[wp.int32],
    tile_items: wp.array[wp.int32],
    texels_per_tile: int,
    base: wp.array2d[wp.vec3],
    direction: wp.array2d[wp.vec3],
    transmit: wp.array2d[wp.float32],
    ends: wp.array2d[wp.vec3],
    weight: wp.array[wp.float32],
    area_coef: wp.array[wp.vec3],
    beams_per_group: int,
    wavelengths_per_group: int,
    sun_irradiance: wp.array[wp.float32],
    attenuation_per_m: wp.array[wp.float32],
    extent_m: float,
    periodic: int,
    mesh: wp.uint64,
    occluders: int,
    quads: int,
    smooth: int,
    corner_z: wp.array2d[wp.float32],
    texel_area_m2: wp.array2d[wp.float32],
    out: wp.array2d[wp.float32],
):
    """Irradiance on the floor's true area over each texel (K, M·M) [W m^-2 nm^-1]. The floor over a
    texel is the two planar triangles on its corners (heights ``corner_z``, (M+1)², as the floor
    mesh; a flat floor is one plane). For each beam of the texel's tile and each triangle, the
    beam's three edge lines cut the triangle's plane in a triangle, which is clipped exactly
    against the triangle's footprint (Sutherland–Hodgman). ``flat``: the piece gets the share of the
    beam's flux that its area is of the cut, with the transmittance at its area centroid (exact for
    the barycentric-linear transmittance: on a flat floor flux is conserved to rounding; on a relief
    to the shadow decisions, made per piece at its centroid, and the cuts of a beam through two
    planes, each normalised on its own); ``smooth``: the interpolated irradiance on the plane at
    the centroid times the piece's area."""
    ty, tx = wp.tid()
    m = texels_per_tile * grid.nx
    texel_m = extent_m / float(m)
    point = ty * m + tx
    for k in range(out.shape[0]):
        out[k, point] = 0.0
    t = tile_index(grid, tx / texels_per_tile, ty / texels_per_tile)
    corner = wp.vec2(float(tx) * texel_m - 0.5 * extent_m, float(ty) * texel_m - 0.5 * extent_m)
    za = corner_z[ty, tx]
    zb = corner_z[ty, tx + 1]
    zc = corner_z[ty + 1, tx]
    zd = corner_z[ty + 1, tx + 1]
    flat = za == zb and za == zc and za == zd
    pieces = 2
    if flat:
        pieces = 1
    inv_area = 1.0 / texel_area_m2[ty, tx]
    z_lo = wp.min(wp.min(za, zb), wp.min(zc, zd))
    z_hi = wp.max(wp.max(za, zb), wp.max(zc, zd))
    # Triangle (a, b, d) below the diagonal a→d (x ≥ y in texel units), (a, d, c) above it.
    a3 = wp.vec3(corner[0], corner[1], za)
    n_lower = wp.vec3(0.0, 0.0, 1.0)
    n_upper = wp.vec3(0.0, 0.0, 1.0)
    if not flat:
        d3 = wp.vec3(corner[0] + texel_m, corner[1] + texel_m, zd)
        n_lower = wp.normalize(wp.cross(wp.vec3(corner[0] + texel_m, corner[1], zb) - a3, d3 - a3))
        n_upper = wp.normalize(wp.cross(d3 - a3, wp.vec3(corner[0], corner[1] + texel_m, zc) - a3))
    start = tile_start[t]
    for item in range(tile_count[t]):
        b = tile_items[start + item]
        # The copies of the texel the beam may reach: its sections between the texel's lowest and
        # highest corners bound its cuts through both triangles (sections are linear in z).
        lo = wp.vec2(1.0e30)
        hi = wp.vec2(-1.0e30)
        for e in range(3):
            for k in range(2):
                zz = z_lo
                if k == 1:
                    zz = z_hi
                sv = section_vertex(base[b, e], direction[b, e], zz)
                lo = wp.min(lo, sv)
                hi = wp.max(hi, sv)
        kx0, kx1 = copy_range(lo[0], hi[0], corner[0], texel_m, extent_m, periodic)
        ky0, ky1 = copy_range(lo[1], hi[1], corner[1], texel_m, extent_m, periodic)
        for piece in range(pieces):
            n = n_lower
            if piece == 1:
                n = n_upper
            # Every edge must cross the plane downwards (grazing or back-facing triangles: skip).
            if (
                wp.dot(direction[b, 0], n) > -1.0e-6
                or wp.dot(direction[b, 1], n) > -1.0e-6
                or wp.dot(direction[b, 2], n) > -1.0e-6
            ):
                continue
            for ky in range(ky0, ky1 + 1):
                for kx in range(kx0, kx1 + 1):  # every periodic copy of the texel the cut may cover
                    shift = wp.vec2(float(kx) * extent_m, float(ky) * extent_m)
                    origin = corner + shift
                    # The copy's own plane (a tilted plane does not repeat with the period).
                    a_copy = a3 + wp.vec3(shift[0], shift[1], 0.0)
                    q0 = plane_cut(base[b, 0], direction[b, 0], a_copy, n)
                    q1 = plane_cut(base[b, 1], direction[b, 1], a_copy, n)
                    q2 = plane_cut(base[b, 2], direction[b, 2], a_copy, n)
                    px = vec8()
                    py = vec8()
                    px[0] = (q0[0] - origin[0]) / texel_m
                    py[0] = (q0[1] - origin[1]) / texel_m
                    px[1] = (q1[0] - origin[0]) / texel_m
                    py[1] = (q1[1] - origin[1]) / texel_m
                    px[2] = (q2[0] - origin[0]) / texel_m
                    py[2] = (q2[1] - origin[1]) / texel_m
                    cx, cy, cn = clip_to_slab(px, py, 3, 0, 0.0, 1.0)
                    if cn < 3:
                        continue
                    rx, ry, rn = clip_to_slab(cx, cy, cn, 1, 0.0, 1.0)
                    if rn < 3:
                        continue
                    if not flat:
                        if piece == 0:
                            rx, ry, rn = clip_side(rx, ry, rn, 1.0, -1.0, 0.0)
                        else:
                            rx, ry, rn = clip_side(rx, ry, rn, -1.0, 1.0, 0.0)
                        if rn < 3:
                            continue
                    share = polygon_area(rx, ry, rn)  # of the texel's horizontal area
                    if not (share > 0.0):
                        continue
                    # Area centroid of the piece: exact for an integrand linear over it.
                    ax = float(0.0)
                    ay = float(0.0)
                    a2 = float(0.0)
                    mx = float(0.0)
                    my = float(0.0)
                    for v in range(rn):
                        vn = (v + 1) % rn
                        cr = rx[v] * ry[vn] - rx[vn] * ry[v]
                        a2 += cr
                        ax += (rx[v] + rx[vn]) * cr
                        ay += (ry[v] + ry[vn]) * cr
                        mx += rx[v]
                        my += ry[v]
                    if wp.abs(a2) > 1.0e-12:
                        mx = ax / (3.0 * a2)
                        my = ay / (3.0 * a2)
                    else:
                        mx = mx / float(rn)
                        my = my / float(rn)
                    x = corner[0] + mx * texel_m
                    y = corner[1] + my * texel_m
                    z = za + ((n[0] * (corner[0] - x) + n[1] * (corner[1] - y)) / n[2])
                    p = wp.vec3(x + shift[0], y + shift[1], z)
                    s = sample_beam(base, direction, transmit, ends, area_coef, b, p)
                    if s.inside == 0:
                        # The centroid sits on the section's boundary to rounding: clamp it in.
                        s = clamped_sample(load_corners(base, direction, transmit, ends, area_coef, b), p)
                    if not lit(mesh, occluders, s, p):
                        continue
                    # The piece's flux over the texel's true area. Flat: the beam's flux w Σλ T spread
                    # evenly over its cut through this plane (exact flux, as a section on a flat
                    # floor). Smooth: its irradiance on the plane, E_h |d·n| / |d_z|, times the
                    # piece's true area.
                    scale = share * texel_m * texel_m * inv_area
                    density = float(0.0)
                    if smooth == 0:
                        cut = 0.5 * wp.abs(cross2(q1 - q0, q2 - q0))
                        density = weight[b] * s.transmit / wp.max(cut, MIN_AREA_FRACTION * s.area)
                    else:
                        cos_factor = wp.abs(wp.dot(s.d, n)) / wp.abs(s.d[2])
                        scale = scale * cos_factor / n[2]
                        density = flux_density(
                            weight, transmit, area_coef, base, b, s, p[2], quads, periodic, smooth
                        )
                    add_beam_irradiance(
                        out,
                        point,
                        scale,
                        b,
                        s,
                        density,
                        beams_per_group,
                        wavelengths_per_group,
                        sun_irradiance,
                        attenuation_per_m,
                    )


# --- volume caustics: scan planes -----------------------------------------------------------------

NEAR_M = 1.0e-3
"""Camera-space depth of the near plane that bounding volumes are clipped against [m]."""


@wp.func
def copy_offset(c: int, copies: int, extent_m: float) -> wp.vec3:
    """Shift of periodic copy c of copies×copies (centred on the patch)."""
    r = copies / 2
    return wp.vec3(float(c % copies - r) * extent_m, float(c / copies - r) * extent_m, 0.0)


@wp.func
def screen_xy(cam: PinholeCamera, x: wp.vec3, depth: float) -> wp.vec2:
    """Continuous pixel coordinates of x at camera-space depth ``depth`` (> 0), kept finite."""
    v = x - cam.position
    px = (wp.dot(v, cam.right) / (depth * cam.tan_half_fov * cam.aspect) + 1.0) * 0.5 * float(cam.width)
    py = (1.0 - wp.dot(v, cam.up) / (depth * cam.tan_half_fov)) * 0.5 * float(cam.height)
    return wp.vec2(wp.clamp(px, -1.0e6, 1.0e6), wp.clamp(py, -1.0e6, 1.0e6))


@wp.func
def perp(axis: wp.vec2) -> wp.vec2:
    return wp.vec2(-axis[1], axis[0])


@wp.func
def in_frame(q: wp.vec2, axis: wp.vec2) -> wp.vec2:
    """q in the frame (axis, perp(axis))."""
    return wp.vec2(wp.dot(q, axis), wp.dot(q, perp(axis)))


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
def hull_box(
    cam: PinholeCamera,
    base: wp.array2d[wp.vec3],
    direction: wp.array2d[wp.vec3],
    end_m: wp.array2d[wp.float32],
    b: int,
    shift: wp.vec3,
    axis: wp.vec2,
):
    """The box, in the screen frame (axis, perp(axis)), of the beam's hull: the convex hull of its
    base and end vertices (which holds its bilinear side patches), clipped to the near plane."""
    lo = wp.vec2(1.0e30)
    hi = wp.vec2(-1.0e30)
    for i in range(3):
        i1 = (i + 1) % 3
        a = base[b, i] + shift
        e = a + end_m[b, i] * direction[b, i]
        a1 = base[b, i1] + shift
        e1 = a1 + end_m[b, i1] * direction[b, i1]
        lo, hi = hull_edge(cam, a, e, axis, lo, hi)
        lo, hi = hull_edge(cam, a, a1, axis, lo, hi)
        lo, hi = hull_edge(cam, e, e1, axis, lo, hi)
    return lo, hi


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
    spans: wp.array2d[wp.int32],
    box_axis: wp.array[wp.vec2],
    box_lo: wp.array[wp.vec2],
    box_hi: wp.array[wp.vec2],
    box_pixels: wp.array[wp.float32],
):
    """Screen bounds of each beam copy ``b · copies² + c``: the tile span of its hull's screen box
    and an oriented box along the beam's projected axis (base centroid → end centroid) that the
    tiles and pixels are then tested against. ``box_pixels``: pixels of the axis-aligned box."""
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
    lo, hi = hull_box(cam, base, direction, end_m, b, shift, wp.vec2(1.0, 0.0))
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
    olo, ohi = hull_box(cam, base, direction, end_m, b, shift, axis)
    box_axis[item] = axis
    box_lo[item] = olo
    box_hi[item] = ohi


@wp.func
def clip_halfspace(s_a: float, s_b: float, a: float, k: float):
    """Clip [s_a, s_b] to the points where a + s k >= 0."""
    if wp.abs(k) < 1.0e-20:
        if a < 0.0:
            return 1.0, 0.0
        return s_a, s_b
    root = -a / k
    if k > 0.0:
        return wp.max(s_a, root), s_b
    return s_a, wp.min(s_b, root)


@wp.struct
class ChordFrame:
    """What :func:`scan_chord` needs of a beam copy for rays from one origin o, formed once per beam
    copy and tile on the CPU (per pixel and beam copy in the GPU's per-pixel kernel): the base
    vertices from o, p_i = v_i + shift − o, and the signed distances of o from the base and end
    planes, (v_0 + shift − o)·n_b and (e + shift − o)·n_e."""

    p0: wp.vec3
    p1: wp.vec3
    p2: wp.vec3
    base_offset: float
    end_offset: float


@wp.func
def chord_frame(c: BeamCorners, shift: wp.vec3, o: wp.vec3) -> ChordFrame:
    """The :class:`ChordFrame` of beam copy (c, shift) for rays from o."""
    f = ChordFrame()
    f.p0 = c.v0 + shift - o
    f.p1 = c.v1 + shift - o
    f.p2 = c.v2 + shift - o
    f.base_offset = wp.dot(f.p0, c.base_normal)
    f.end_offset = wp.dot(c.end_point + shift - o, c.end_normal)
    return f


@wp.func
def edge_cut(p: wp.vec3, d: wp.vec3, v: wp.vec3, m: wp.vec3, e: wp.vec3, sin2_beam: float):
    """Where the edge line o + p + t d meets the scan plane of the ray v, whose normal is
    m = (v × d̄) × v = d̄ − (v·d̄) v and whose direction across the ray is e = v × m (both of
    length sin_beam = |v × d̄|; ``sin2_beam`` is its square): (distance along the ray, distance
    across it × sin_beam, ok): the cut point q = p + t d with t = (p·m)/(−d·m), projected on v and
    e. An edge within 1e-12 (relative) of parallel to the plane is not ok."""
    den = wp.dot(d, m)
    if den * den < 1.0e-24 * sin2_beam:
        return 0.0, 0.0, False
    q = p - (wp.dot(p, m) / den) * d
    return wp.dot(q, v), wp.dot(q, e), True


@wp.func
def scan_chord(c: BeamCorners, shift: wp.vec3, o: wp.vec3, v: wp.vec3):
    """[s_a, s_b] of the ray o + s v inside beam b moved by ``shift``, by the scan plane (Ernst
    2005, Liktor & Dachsbacher 2011): the plane through the ray most nearly perpendicular to the
    beam cuts the three edge lines in a triangle; the ray's chord through it is clipped to the
    beam's base and end planes. Returns s_a > s_b for a miss. Exact for a straight prism."""
    return framed_chord(c, chord_frame(c, shift, o), shift, o, v)


@wp.func
def framed_chord(c: BeamCorners, f: ChordFrame, shift: wp.vec3, o: wp.vec3, v: wp.vec3):
    """:func:`scan_chord` with the beam copy's :class:`ChordFrame` formed already."""
    w = wp.cross(v, c.dbar)
    sin2_beam = wp.dot(w, w)  # |v × d̄|²: compared squared, so no square root delays the chord
    s_a = float(-1.0e30)
    s_b = float(1.0e30)
    if sin2_beam < PARALLEL_COS * PARALLEL_COS:
        # Along the beam: inside iff the ray's point on the base plane is in the base triangle.
        v0 = c.v0 + shift
        v1 = c.v1 + shift
        v2 = c.v2 + shift
        nb = wp.cross(v1 - v0, v2 - v0)
        den = wp.dot(v, nb)
        if wp.abs(den) < 1.0e-20:
            return 1.0, 0.0
        x = o + (wp.dot(v0 - o, nb) / den) * v
        lam = barycentrics(xy(v0), xy(v1), xy(v2), xy(x))
        if lam[0] < 0.0 or lam[1] < 0.0 or lam[2] < 0.0:
            return 1.0, 0.0
    else:
        # The scan plane holds the ray and is most nearly perpendicular to d̄: its normal is
        # m = w × v, of length sin_beam. Each edge line's cut: its distance along the ray (a)
        # and across it in the plane (h, along e = v × m, scaled by sin_beam, which only the
        # signs and ratios below see). m and e are cross products with v, so both stay
        # perpendicular to the ray to rounding even for rays nearly along the beam: d̄ − (v·d̄) v
        # for m, or w itself for e (w·v is ~1e-7, not 0), would tilt the plane, or the line
        # h = 0 in it, off the ray by ~1e-7/sin_beam.
        m = wp.cross(w, v)
        e = wp.cross(v, m)
        a0, h0, ok0 = edge_cut(f.p0, c.d0, v, m, e, sin2_beam)
        a1, h1, ok1 = edge_cut(f.p1, c.d1, v, m, e, sin2_beam)
        a2, h2, ok2 = edge_cut(f.p2, c.d2, v, m, e, sin2_beam)
        if not (ok0 and ok1 and ok2):
            return 1.0, 0.0
        a = wp.vec3(a0, a1, a2)
        h = wp.vec3(h0, h1, h2)
        lo = float(1.0e30)
        hi = float(-1.0e30)
        for i in range(3):
            j = (i + 1) % 3
            if (h[i] >= 0.0) != (h[j] >= 0.0):
                s = a[i] + (a[j] - a[i]) * h[i] / (h[i] - h[j])
                lo = wp.min(lo, s)
                hi = wp.max(hi, s)
        if lo > hi:
            return 1.0, 0.0
        s_a = lo
        s_b = hi
    # Base plane: keep the side the beam goes to.
    s_a, s_b = clip_halfspace(s_a, s_b, -f.base_offset, wp.dot(v, c.base_normal))
    s_a, s_b = clip_halfspace(s_a, s_b, f.end_offset, -wp.dot(v, c.end_normal))
    return s_a, s_b


@wp.struct
class ShaftBeams:
    """What the volume pass reads besides the camera and the tile lists: the beams (see the module
    docstring; ``copies`` × ``copies`` periodic copies ``extent_m`` apart, ``quads`` per side of
    the uniform grid for ``smooth`` interpolation), their index groups, and the medium: the sun's
    irradiance, attenuation and scattering per band [1/m], the phase function (kind 0:
    Henyey–Greenstein with ``hg_g``; 1: the table)."""

    base: wp.array2d[wp.vec3]
    direction: wp.array2d[wp.vec3]
    transmit: wp.array2d[wp.float32]
    ends: wp.array2d[wp.vec3]
    weight: wp.array[wp.float32]
    area_coef: wp.array[wp.vec3]
    copies: int
    extent_m: float
    quads: int
    smooth: int
    beams_per_group: int
    wavelengths_per_group: int
    sun_irradiance: wp.array[wp.float32]
    attenuation_per_m: wp.array[wp.float32]
    scattering_per_m: wp.array[wp.float32]
    phase_kind: int
    hg_g: float
    angles_rad: wp.array[wp.float32]
    log_phase: wp.array[wp.float32]
    cone_phase: float


@wp.func
def chord_radiance(
    sb: ShaftBeams,
    corners: BeamCorners,
    frame: ChordFrame,
    b: int,
    shift: wp.vec3,
    o: wp.vec3,
    v: wp.vec3,
    s_max: float,
    j: int,
    i: int,
    radiance: wp.array3d[wp.float32],
) -> int:
    """Add to pixel (j, i) the radiance scattered into its ray o + s v (cut at the receiver,
    s_max) by beam b moved by ``shift``: ``Σ Δs σ_s p(cos θ) E⊥(x_m) exp(−c (ℓ(x_m) + s_m))`` over
    up to MAX_CHORD_PIECES midpoint pieces of the scan-plane chord. Returns 1 if the ray has a
    chord through the beam, else 0."""
    s_a, s_b = framed_chord(corners, frame, shift, o, v)
    s_a = wp.max(s_a, 0.0)
    s_b = wp.min(s_b, s_max)
    if s_b <= s_a:
        return 0
    ds = s_b - s_a
    # About one piece per beam width √|A| at the chord's midpoint. Most chords are shorter than
    # that: ds² < |A| finds them without the square root and two divisions that would otherwise
    # sit on every chord's chain of dependent operations (docs/benchmarks.md). The test's margin
    # (a relative 1e-6, far above the rounding of ds² and √|A|) sends every chord the count below
    # would split to the count, so the two agree exactly.
    mid = o + (0.5 * (s_a + s_b)) * v - shift
    area_mid = safe_area(corners.coef, mid[2], corners.v0[2])
    pieces = int(1)
    piece = ds
    if ds * ds >= 0.999999 * area_mid:
        pieces = wp.clamp(int(ds / wp.max(wp.sqrt(area_mid), 1.0e-6)) + 1, 1, MAX_CHORD_PIECES)
        piece = ds / float(pieces)
    g = b / sb.beams_per_group
    lattice_wraps = int(0)
    if sb.copies > 1:
        lattice_wraps = 1  # a periodic sea
    for n in range(pieces):
        s_m = s_a + (float(n) + 0.5) * piece
        x = o + s_m * v - shift
        smp = clamped_sample(corners, x)
        if smp.beyond_end_m > shadow_slack(smp.area):
            continue
        cos_theta = -wp.dot(smp.d, v)
        phase = phase_value(sb.phase_kind, sb.hg_g, sb.angles_rad, sb.log_phase, sb.cone_phase, cos_theta)
        density = flux_density(
            sb.weight, sb.transmit, sb.area_coef, sb.base, b, smp, x[2], sb.quads, lattice_wraps, sb.smooth
        )
        e_perp = density / wp.abs(smp.d[2])
        f = piece * phase * e_perp
        for jj in range(sb.wavelengths_per_group):
            k = g * sb.wavelengths_per_group + jj
            scattered = f * sb.scattering_per_m[k]
            radiance[k, j, i] = radiance[k, j, i] + scattered * sb.sun_irradiance[k] * wp.exp(
                -sb.attenuation_per_m[k] * (smp.path_m + s_m)
            )
    return 1


@wp.func
def copy_corners(sb: ShaftBeams, bc: int):
    """Beam copy ``bc = b · copies² + c``: the beam b, its shift and its corners."""
    per_beam = sb.copies * sb.copies
    b = bc / per_beam
    corners = load_corners(sb.base, sb.direction, sb.transmit, sb.ends, sb.area_coef, b)
    return b, copy_offset(bc % per_beam, sb.copies, sb.extent_m), corners


@wp.func
def outside_box(q: wp.vec2, lo: wp.vec2, hi: wp.vec2) -> bool:
    """Whether a pixel centre q (in the box's frame) is outside the oriented box [lo, hi]."""
    return q[0] < lo[0] - 1.0e-3 or q[0] > hi[0] + 1.0e-3 or q[1] < lo[1] - 1.0e-3 or q[1] > hi[1] + 1.0e-3


@wp.kernel
def scan_plane_radiance(
    grid: TileGrid,
    tile_start: wp.array[wp.int32],
    tile_count: wp.array[wp.int32],
    tile_items: wp.array[wp.int32],
    tile_pixels: int,
    cam: PinholeCamera,
    rays: wp.array2d[wp.vec3],
    depth: wp.array2d[wp.float32],
    sb: ShaftBeams,
    box_axis: wp.array[wp.vec2],
    box_lo: wp.array[wp.vec2],
    box_hi: wp.array[wp.vec2],
    radiance: wp.array3d[wp.float32],
    pairs: wp.array[wp.int32],
):
    """Single-scattered radiance of the beams along each pixel's ray (K, H, W) [W m^-2 sr^-1
    nm^-1], a thread per pixel (the GPU's form): the chords (:func:`chord_radiance`) of the beam
    copies in the pixel's tile list whose oriented box holds the pixel centre. ``pairs`` counts
    (pixel, beam copy) pairs: [0] in the tile lists, [1] inside the oriented box (scan plane
    computed), [2] with a chord."""
    j, i = wp.tid()
    for k in range(radiance.shape[0]):
        radiance[k, j, i] = 0.0
    v = rays[j, i]
    o = cam.position
    s_max = depth[j, i]
    t = tile_index(grid, i / tile_pixels, j / tile_pixels)
    start = tile_start[t]
    centre = wp.vec2(float(i) + 0.5, float(j) + 0.5)
    count = tile_count[t]
    boxed = int(0)
    chords = int(0)
    for item in range(count):
        bc = tile_items[start + item]
        if outside_box(in_frame(centre, box_axis[bc]), box_lo[bc], box_hi[bc]):
            continue  # the ray passes outside the beam's hull
        boxed += 1
        b, shift, corners = copy_corners(sb, bc)
        frame = chord_frame(corners, shift, o)
        chords += chord_radiance(sb, corners, frame, b, shift, o, v, s_max, j, i, radiance)
    wp.atomic_add(pairs, 0, count)
    wp.atomic_add(pairs, 1, boxed)
    wp.atomic_add(pairs, 2, chords)


@wp.kernel
def scan_plane_radiance_tiles(
    grid: TileGrid,
    tile_start: wp.array[wp.int32],
    tile_count: wp.array[wp.int32],
    tile_items: wp.array[wp.int32],
    tile_pixels: int,
    cam: PinholeCamera,
    rays: wp.array2d[wp.vec3],
    depth: wp.array2d[wp.float32],
    sb: ShaftBeams,
    box_axis: wp.array[wp.vec2],
    box_lo: wp.array[wp.vec2],
    box_hi: wp.array[wp.vec2],
    radiance: wp.array3d[wp.float32],
    pairs: wp.array[wp.int32],
):
    """:func:`scan_plane_radiance` with a thread per tile (the CPU's form, same result to the bit):
    the tile's list is walked once, not once per pixel, and each beam copy's oriented box is tested
    at the tile's pixel centres. Every pixel still adds its beams in list order. (Narrowing each
    copy's rows and per-row pixel spans to the box first cost more than the tests it saved: the
    pass takes 0.94–0.98× the time without it at 160×120, same shafts.)"""
    tj, ti = wp.tid()
    x0 = ti * tile_pixels
    y0 = tj * tile_pixels
    x1 = wp.min(x0 + tile_pixels, radiance.shape[2])
    y1 = wp.min(y0 + tile_pixels, radiance.shape[1])
    for j in range(y0, y1):
        for i in range(x0, x1):
            for k in range(radiance.shape[0]):
                radiance[k, j, i] = 0.0
    o = cam.position
    t = tile_index(grid, ti, tj)
    start = tile_start[t]
    count = tile_count[t]
    boxed = int(0)
    chords = int(0)
    for item in range(count):
        bc = tile_items[start + item]
        axis = box_axis[bc]
        lo = box_lo[bc]
        hi = box_hi[bc]
        b, shift, corners = copy_corners(sb, bc)
        frame = chord_frame(corners, shift, o)
        for j in range(y0, y1):
            yc = float(j) + 0.5
            for i in range(x0, x1):
                if outside_box(in_frame(wp.vec2(float(i) + 0.5, yc), axis), lo, hi):
                    continue
                boxed += 1
                chords += chord_radiance(
                    sb, corners, frame, b, shift, o, rays[j, i], depth[j, i], j, i, radiance
                )
    wp.atomic_add(pairs, 0, count * (x1 - x0) * (y1 - y0))
    wp.atomic_add(pairs, 1, boxed)
    wp.atomic_add(pairs, 2, chords)
