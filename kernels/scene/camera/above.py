"""The camera above the water (de la Fuente Caballé 2011 §4.2's scene division, by ray casting):
each pixel's ray meets the moving surface, where Fresnel splits it into the reflected ray (the sky
and the sun's glint, shaded on the host) and the refracted ray, which this module follows down to
the first receiver; rays that miss the water meet the receivers in the air or the sky.

The surface is a triangle mesh of the frame's displaced vertices (a periodic sea gets one more row
and column, the first ones moved by a period, so the seam is closed), traced through
``copies`` × ``copies`` periodic images; beyond them a periodic sea continues as still water at
z = 0. Normals are the vertices' interpolated across each triangle (smooth shading, as the flux
ratio's vertex normals)."""

import warp as wp

from warpcaustics.kernels.geometry import bilerp
from warpcaustics.kernels.optics.phase import phase_value
from warpcaustics.kernels.scene.camera.pinhole import PinholeCamera, pixel_ray

wp.set_module_options({"enable_backward": False})

AIR = wp.constant(0)
"""The ray does not meet the water: the sky, or a receiver in the air."""
WATER = wp.constant(1)
"""The ray meets the moving surface."""
STILL = wp.constant(2)
"""The ray meets the still sea beyond the periodic images traced."""


@wp.kernel
def water_vertices(
    positions: wp.array2d[wp.vec3],
    normals: wp.array2d[wp.vec3],
    periodic: int,
    extent_m: float,
    points: wp.array[wp.vec3],
    point_normals: wp.array[wp.vec3],
):
    """The mesh's vertices, row-major over (N + periodic)²: vertex (j, i) is the surface's; on a
    periodic sea row or column N is row or column 0 moved by a period."""
    j, i = wp.tid()
    n = positions.shape[0]
    side = n + periodic
    p = positions[j % n, i % n]
    if i >= n:
        p = p + wp.vec3(extent_m, 0.0, 0.0)
    if j >= n:
        p = p + wp.vec3(0.0, extent_m, 0.0)
    points[j * side + i] = p
    point_normals[j * side + i] = normals[j % n, i % n]


@wp.func
def smooth_normal(points: wp.array[wp.vec3], point_normals: wp.array[wp.vec3], indices: wp.array[wp.int32],
                  face: int, p: wp.vec3) -> wp.vec3:
    """The vertex normals of ``face`` interpolated at its point ``p`` (barycentrics from the areas)."""
    a = indices[3 * face]
    b = indices[3 * face + 1]
    c = indices[3 * face + 2]
    pa = points[a]
    pb = points[b]
    pc = points[c]
    n = wp.cross(pb - pa, pc - pa)
    den = wp.dot(n, n)
    if den <= 0.0:
        return wp.normalize(point_normals[a])
    la = wp.dot(wp.cross(pb - p, pc - p), n) / den
    lb = wp.dot(wp.cross(pc - p, pa - p), n) / den
    lc = 1.0 - la - lb
    return wp.normalize(la * point_normals[a] + lb * point_normals[b] + lc * point_normals[c])


@wp.kernel
def surface_hits(
    cam: PinholeCamera,
    mesh: wp.uint64,
    points: wp.array[wp.vec3],
    point_normals: wp.array[wp.vec3],
    indices: wp.array[wp.int32],
    extent_m: float,
    periodic: int,
    copies: int,
    rays: wp.array2d[wp.vec3],
    hit: wp.array2d[wp.vec3],
    normal: wp.array2d[wp.vec3],
    kind: wp.array2d[wp.int32],
):
    """Each pixel's ray against the water: the nearest hit over the periodic images, the smooth
    normal there (pointing up, out of the water), and :data:`WATER`, :data:`STILL` or :data:`AIR`."""
    j, i = wp.tid()
    ray = pixel_ray(cam, i, j)
    rays[j, i] = ray
    best = float(1.0e30)
    best_face = int(-1)
    best_shift = wp.vec3(0.0)
    r = copies / 2
    for ky in range(-r, r + 1):
        for kx in range(-r, r + 1):
            shift = wp.vec3(float(kx) * extent_m, float(ky) * extent_m, 0.0)
            q = wp.mesh_query_ray(mesh, cam.position - shift, ray, best)
            if q.result and q.t < best:
                best = q.t
                best_face = q.face
                best_shift = shift
    kind[j, i] = AIR
    hit[j, i] = cam.position
    normal[j, i] = wp.vec3(0.0, 0.0, 1.0)
    if best_face >= 0:
        p = cam.position + best * ray
        kind[j, i] = WATER
        hit[j, i] = p
        normal[j, i] = smooth_normal(points, point_normals, indices, best_face, p - best_shift)
    elif periodic != 0 and ray[2] < 0.0:
        kind[j, i] = STILL
        hit[j, i] = cam.position + (-cam.position[2] / ray[2]) * ray


@wp.kernel
def first_receiver(
    mesh: wp.uint64,
    face_receiver: wp.array[wp.int32],
    origins: wp.array2d[wp.vec3],
    directions: wp.array2d[wp.vec3],
    position: wp.array2d[wp.vec3],
    normal: wp.array2d[wp.vec3],
    depth: wp.array2d[wp.float32],
    receiver: wp.array2d[wp.int32],
    face: wp.array2d[wp.int32],
):
    """The first receiver along each pixel's ray from ``origins`` along the unit ``directions``
    (below the surface: the refracted ray; in the air: the camera's): position, normal facing the
    ray, distance, receiver id and face (−1 and depth 1e30 for none)."""
    j, i = wp.tid()
    o = origins[j, i]
    d = directions[j, i]
    q = wp.mesh_query_ray(mesh, o, d, 1.0e5)
    if q.result:
        n = q.normal
        if wp.dot(n, d) > 0.0:
            n = -n
        position[j, i] = o + q.t * d
        normal[j, i] = n
        depth[j, i] = q.t
        receiver[j, i] = face_receiver[q.face]
        face[j, i] = q.face
    else:
        position[j, i] = o + 1.0e5 * d
        normal[j, i] = -d
        depth[j, i] = 1.0e30
        receiver[j, i] = -1
        face[j, i] = -1


@wp.kernel
def segment_samples(
    origins: wp.array2d[wp.vec3],
    directions: wp.array2d[wp.vec3],
    length_m: wp.array2d[wp.float32],
    samples: int,
    n: int,
    points: wp.array[wp.vec3],
    views: wp.array[wp.vec3],
    along_m: wp.array[wp.float32],
    piece_m: wp.array[wp.float32],
):
    """Sample ``n`` of ``samples`` midpoints along each pixel's underwater segment (flat, pixel-major):
    the point, the view ray's direction, its distance from the surface and the piece's length (0
    where the pixel has no segment)."""
    j, i = wp.tid()
    w = origins.shape[1]
    p = j * w + i
    length = length_m[j, i]
    piece = length / float(samples)
    s = (float(n) + 0.5) * piece
    points[p] = origins[j, i] + s * directions[j, i]
    views[p] = directions[j, i]
    along_m[p] = s
    piece_m[p] = piece


@wp.kernel
def scale_by(factor: wp.array3d[wp.float32], values: wp.array3d[wp.float32]):
    """values *= factor, element by element (the water's radiance leaving through the surface)."""
    k, j, i = wp.tid()
    values[k, j, i] = values[k, j, i] * factor[k, j, i]


@wp.func
def map_texel(coord: float, m: int, periodic: int) -> int:
    """Texel index of a map coordinate [texels]: wrapped on a periodic sea, clamped in a pool."""
    t = int(wp.floor(coord))
    if periodic != 0:
        return ((t % m) + m) % m
    return wp.clamp(t, 0, m - 1)


@wp.func
def map_cell(x: wp.vec3, m: int, extent_m: float, periodic: int):
    """(x0, x1, y0, y1, tu, tv): the four texels of an M × M map over the patch ±extent/2 around
    x's (x, y), between texel centres, and the bilinear weights (wrapped on a periodic sea, clamped
    in a pool)."""
    u = (x[0] / extent_m + 0.5) * float(m) - 0.5
    v = (x[1] / extent_m + 0.5) * float(m) - 0.5
    return (map_texel(u, m, periodic), map_texel(u + 1.0, m, periodic), map_texel(v, m, periodic),
            map_texel(v + 1.0, m, periodic), u - wp.floor(u), v - wp.floor(v))


@wp.kernel
def photon_point_irradiance(
    water_receiver: wp.array2d[wp.int32],
    position: wp.array2d[wp.vec3],
    face: wp.array2d[wp.int32],
    floor_face_count: int,
    floor_irradiance: wp.array3d[wp.float32],
    extent_m: float,
    periodic: int,
    face_flux: wp.array2d[wp.float32],
    face_area_m2: wp.array[wp.float32],
    caustic: wp.array3d[wp.float32],
):
    """Irradiance (K, H, W) from a photon pass where each refracted ray meets a receiver: on the
    floor, the photons' floor map (K, M, M) bilinear between texel centres at the point's (x, y)
    (over the patch ±extent/2; wrapped on a periodic sea, clamped at a pool's walls); on another
    receiver, its face's flux over the face's area. 0 where the pixel sees no receiver in the water."""
    k, j, i = wp.tid()
    caustic[k, j, i] = 0.0
    if water_receiver[j, i] < 0:
        return
    f = face[j, i]
    if f >= floor_face_count:
        caustic[k, j, i] = face_flux[f - floor_face_count, k] / face_area_m2[f - floor_face_count]
        return
    x0, x1, y0, y1, tu, tv = map_cell(position[j, i], floor_irradiance.shape[1], extent_m, periodic)
    e = floor_irradiance
    caustic[k, j, i] = bilerp(e[k, y0, x0], e[k, y0, x1], e[k, y1, x0], e[k, y1, x1], tu, tv)


@wp.func
def map_bilinear(maps: wp.array4d[wp.float32], s: int, x: wp.vec3, k: int, extent_m: float,
                 periodic: int) -> float:
    """Map s of ``maps`` (S, M, M, K) in band k at x (:func:`map_cell`)."""
    x0, x1, y0, y1, tu, tv = map_cell(x, maps.shape[1], extent_m, periodic)
    return bilerp(maps[s, y0, x0, k], maps[s, y0, x1, k], maps[s, y1, x0, k], maps[s, y1, x1, k], tu, tv)


@wp.kernel
def slice_inscatter(
    slices: wp.array4d[wp.float32],
    top_z: float,
    step_z: float,
    extent_m: float,
    periodic: int,
    light_dir: wp.vec3,
    phase_kind: int,
    hg_g: float,
    angles_rad: wp.array[wp.float32],
    log_phase: wp.array[wp.float32],
    cone_phase: float,
    scattering_per_m: wp.array[wp.float32],
    attenuation_per_m: wp.array[wp.float32],
    points: wp.array[wp.vec3],
    views: wp.array[wp.vec3],
    along_m: wp.array[wp.float32],
    piece_m: wp.array[wp.float32],
    radiance: wp.array2d[wp.float32],
):
    """One midpoint piece of each refracted view ray's in-scattering from the photons' slices
    (S, M, M, K) of E⊥ (already attenuated along the light's path), plane s at z = top_z − s step_z:
    ``piece σ_s p(cos θ) E⊥(x) e^{−c s}``, E⊥ bilinear in (x, y) and linear in z between planes
    (held at the first and last), cos θ = −light_dir·view with ``light_dir`` the pass's refracted
    direction under still water, added to ``radiance`` (K, P)."""
    p, k = wp.tid()
    piece = piece_m[p]
    if piece <= 0.0:
        return
    x = points[p]
    count = slices.shape[0]
    f = wp.clamp((top_z - x[2]) / step_z, 0.0, float(count - 1))
    s0 = wp.min(int(f), count - 1)
    s1 = wp.min(s0 + 1, count - 1)
    t = f - float(s0)
    e = (1.0 - t) * map_bilinear(slices, s0, x, k, extent_m, periodic) + t * map_bilinear(
        slices, s1, x, k, extent_m, periodic)
    phase = phase_value(phase_kind, hg_g, angles_rad, log_phase, cone_phase, -wp.dot(light_dir, views[p]))
    radiance[k, p] = radiance[k, p] + piece * scattering_per_m[k] * phase * e * wp.exp(
        -attenuation_per_m[k] * along_m[p])
