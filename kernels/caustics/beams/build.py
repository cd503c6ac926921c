"""Beams from the displaced water surface: corner rays (refracted direction, transmittance), edge
ends on the receivers' BVH, the end plane, the section's area quadratic; and the adaptive
refinement of the surface quads (Liktor & Dachsbacher 2011 §4.2).
"""

import warp as wp

from warpcaustics.kernels.caustics.beams.raster import NEAR_M, screen_xy
from warpcaustics.kernels.caustics.beams.section import cross2, period_shift, xy
from warpcaustics.kernels.caustics.fluxratio import lift, quad_corner
from warpcaustics.kernels.geometry import sun_into_water
from warpcaustics.kernels.scene.camera.pinhole import PinholeCamera

wp.set_module_options({"enable_backward": False})

RAY_LENGTH_M = 1.0e5
"""Longest edge traced to a receiver [m]."""


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
    """Lattice offset (dx, dy) of a triangle corner in its quad (fluxratio.py quad_corner)."""
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
def section_coefficients(p0: wp.vec3, p1: wp.vec3, p2: wp.vec3, d0: wp.vec3, d1: wp.vec3,
                         d2: wp.vec3) -> wp.vec3:
    """(a0, a1, a2) of the signed section area A(z) = a0 + a1 z + a2 z² of the beam with base
    vertices p_i and edge directions d_i: A(z) = ½ cross(p1(z) − p0(z), p2(z) − p0(z)) with
    p_i(z) = u_i + z r_i, r_i = d_xy / d_z."""
    r0 = xy(d0) / d0[2]
    r1 = xy(d1) / d1[2]
    r2 = xy(d2) / d2[2]
    u1 = xy(p1) - p1[2] * r1 - (xy(p0) - p0[2] * r0)
    u2 = xy(p2) - p2[2] * r2 - (xy(p0) - p0[2] * r0)
    q1 = r1 - r0
    q2 = r2 - r0
    return 0.5 * wp.vec3(cross2(u1, u2), cross2(u1, q2) + cross2(q1, u2), cross2(q1, q2))


@wp.func
def edge_end(mesh: wp.uint64, origin: wp.vec3, d: wp.vec3, plane_z: float) -> float:
    """Length along an edge to the first receiver; a miss ends on the plane z = plane_z."""
    q = wp.mesh_query_ray(mesh, origin, d, RAY_LENGTH_M)
    if q.result:
        return q.t
    return wp.max((origin[2] - plane_z) / wp.max(-d[2], 1.0e-6), 0.0)


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
    area_coef[b] = section_coefficients(p0, p1, p2, d0, d1, d2)
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
