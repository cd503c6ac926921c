"""Light through glass receivers and off mirrors (``caustics.bounces`` > 1; Liktor & Dachsbacher
2011 §6's two-sided refraction and multiple light–surface bounces), one ray traced exactly on the
receivers' BVH. The photons follow each photon with it (``kernels/caustics/photons.py
trace_bounces``), the beams each edge of a beam (``kernels/caustics/beams/bounces.py``).

A pass through a glass receiver (in, any total internal reflections, out) is one bounce: the ray
keeps the exact Fresnel transmittance of each face it crosses (the reflected parts are what the
bounce leaves behind), and glass does not attenuate. A mirror reflects all the light it meets.
"""

import warp as wp

from warpcaustics.kernels.geometry import fresnel_transmittance, refract

wp.set_module_options({"enable_backward": False})

RAY_LENGTH_M = 1.0e5
"""Longest ray queried on the BVH [m]."""

MAX_INTERNAL_REFLECTIONS = 4
"""Total internal reflections a ray may make inside a glass receiver before it counts as trapped."""
BOUNCE_OFFSET_M = 1.0e-5
"""How far from a surface a bounced ray starts again [m] (off the face it left)."""
MAX_OBJECT_BOUNCES = 2
"""Bounces after the water surface's (``caustics.bounces`` ≤ 3)."""

LANDED = wp.constant(0)
"""How a ray's bounces ended: on a diffuse receiver,"""
MISSED = wp.constant(1)
"""with no receiver ahead,"""
BEYOND_LIMIT_END = wp.constant(2)
"""at a glass or specular receiver met after the last allowed bounce,"""
TRAPPED_END = wp.constant(3)
"""or inside a glass receiver after MAX_INTERNAL_REFLECTIONS total internal reflections."""


@wp.struct
class Optics:
    """The receivers' optics for the bounces: per receiver id, its refractive index (0: opaque and
    diffuse) and whether it is a mirror; the water's index per index group; bounces allowed after
    the surface's."""

    ior: wp.array[wp.float32]
    specular: wp.array[wp.int32]
    water_ior: wp.array[wp.float32]
    object_bounces: int


@wp.struct
class BounceTrace:
    """Where a ray's bounces took it. ``origin``/``direction``: its last segment (which, LANDED, ends
    at ``hit`` on ``face``); ``transmit``: the product of the Fresnel transmittances it crossed;
    ``path_m``: its water path before the last segment (up to the receiver that ended it, for the
    two ends inside objects). ``loss[j]``: the share of the starting weight reflected at bounce j
    (j < MAX_OBJECT_BOUNCES), met at water path ``loss_path_m[j]``. ``signature``: the receivers
    and internal reflections of each bounce, so that rays that took the same way through the
    objects compare equal; ``first_normal``/``last_normal``: the face normals (facing the ray)
    where it entered its first object and left its last."""

    end: int
    bounces: int
    origin: wp.vec3
    direction: wp.vec3
    hit: wp.vec3
    face: int
    transmit: float
    path_m: float
    loss: wp.vec2
    loss_path_m: wp.vec2
    signature: int
    first_normal: wp.vec3
    last_normal: wp.vec3


@wp.func
def through_glass(mesh: wp.uint64, face_receiver: wp.array[wp.int32], r: int, p: wp.vec3, d: wp.vec3,
                  n: wp.vec3, n_w: float, n_g: float):
    """A ray meeting glass receiver r at p (face normal n facing it), refracted in, totally
    reflected inside as often as needed, refracted out: (origin, direction, transmittance, left,
    internal reflections, exit normal facing the ray). ``left`` = 0: still inside after
    MAX_INTERNAL_REFLECTIONS reflections, with the entry's transmittance."""
    cos_in = -wp.dot(d, n)
    t_in = fresnel_transmittance(cos_in, n_w / n_g)
    d_water = d
    g = wp.normalize(refract(d, n, n_w / n_g))
    x = p
    for reflections in range(MAX_INTERNAL_REFLECTIONS + 1):
        q = wp.mesh_query_ray(mesh, x + BOUNCE_OFFSET_M * g, g, RAY_LENGTH_M)
        if not q.result or face_receiver[q.face] != r:
            # a chord shorter than the offset (a grazing entry): the ray leaves where it entered, as
            # through a thin parallel sheet, with the same transmittance
            return x + BOUNCE_OFFSET_M * d_water, d_water, t_in * t_in, int(1), reflections, n
        x = x + (q.t + BOUNCE_OFFSET_M) * g
        m = q.normal
        if wp.dot(m, g) > 0.0:
            m = -m  # facing the ray, inside
        out = refract(g, m, n_g / n_w)
        if wp.length_sq(out) == 0.0:  # total internal reflection
            g = g - 2.0 * wp.dot(g, m) * m
            continue
        t_out = fresnel_transmittance(-wp.dot(g, m), n_g / n_w)
        e = wp.normalize(out)
        return x + BOUNCE_OFFSET_M * e, e, t_in * t_out, int(1), reflections, -m
    return x, g, t_in, int(0), MAX_INTERNAL_REFLECTIONS, n


@wp.func
def follow_bounces(mesh: wp.uint64, face_receiver: wp.array[wp.int32], optics: Optics, n_w: float,
                   o: wp.vec3, d: wp.vec3) -> BounceTrace:
    """The ray o + t d (in the water, of index ``n_w``) followed through up to
    ``optics.object_bounces`` glass or specular receivers to its end."""
    tr = BounceTrace()
    tr.transmit = 1.0
    tr.face = -1
    tr.first_normal = wp.vec3(0.0, 0.0, 1.0)
    tr.last_normal = wp.vec3(0.0, 0.0, 1.0)
    for _event in range(MAX_OBJECT_BOUNCES + 1):
        tr.origin = o
        tr.direction = d
        q = wp.mesh_query_ray(mesh, o, d, RAY_LENGTH_M)
        if not q.result:
            tr.end = MISSED
            return tr
        r = face_receiver[q.face]
        n_g = optics.ior[r]
        mirror = optics.specular[r]
        p = o + q.t * d
        if n_g <= 0.0 and mirror == 0:  # a diffuse receiver: the ray lands
            tr.end = LANDED
            tr.hit = p
            tr.face = q.face
            return tr
        tr.path_m += q.t
        if tr.bounces >= optics.object_bounces:
            tr.end = BEYOND_LIMIT_END
            return tr
        n = q.normal
        if wp.dot(n, d) > 0.0:
            n = -n  # facing the ray
        if tr.bounces == 0:
            tr.first_normal = n
        reflections = int(0)
        if mirror != 0:
            d = d - 2.0 * wp.dot(d, n) * n
            o = p + BOUNCE_OFFSET_M * d
            tr.last_normal = n
        else:
            o, d, t, left, reflections, exit_normal = through_glass(mesh, face_receiver, r, p, d, n, n_w, n_g)
            tr.loss[tr.bounces] = tr.transmit * (1.0 - t)
            tr.loss_path_m[tr.bounces] = tr.path_m
            tr.last_normal = exit_normal
            tr.transmit = tr.transmit * t
            if left == 0:
                tr.end = TRAPPED_END
                tr.bounces += 1
                return tr
        tr.signature = tr.signature * 4099 + r * 8 + reflections + 1
        tr.bounces += 1
    tr.origin = o
    tr.direction = d
    tr.end = BEYOND_LIMIT_END
    return tr

