"""Beams through glass receivers and off mirrors (``caustics.bounces`` > 1): Liktor & Dachsbacher
2011 §6's two-sided refraction and multiple light–surface bounces, for the warped beams.

A beam from the water surface that meets a glass or specular receiver ends there (its end plane
on the object; the points behind it are in its shadow). Each of its three edges is followed on
from where it met the object, exactly on the BVH (``kernels/caustics/bounces.py follow_bounces``,
the photons' own code): through the glass and out, or off the mirror, up to the bounce limit.
Where all three edges took the same way (the same receivers, the same internal reflections, faces
turned alike where they entered and left) and leave downwards, the three rays after the last
bounce are the edges of a new beam, the *bounced beam*: its base the points where they left, its
transmittance the edges' own times their Fresnel transmittances, its water path before the base
kept per edge for the attenuation. It carries the flux of the beam it came from (the same
weight), and the gathers read it as any beam. Where the edges parted (a beam across an object's
silhouette, or across an edge of a box), the beam is cut into SPLIT² congruent sub-beams (Liktor &
Dachsbacher §4.2's refinement at discontinuities, carried past the object): the rays at their
corners are the beam's own interior rays (barycentric interpolation of its edges' lines, as the
gathers read the beam), each sub-beam carries 1/SPLIT² of the beam's weight, and those whose three
rays took the same way become bounced beams; only the sub-beams still across the silhouette lose
the light that entered the object (``BeamStats.parted``; measured against the photons in
docs/validation.md).

The bounced beams are stored after the primaries' slots, in the order of their primaries
(``source``: the primary of each), so the result does not depend on the order the device runs
the threads in.
"""

import warp as wp

from warpcaustics.kernels.caustics.beams.build import edge_end, fill_ends, section_coefficients
from warpcaustics.kernels.caustics.bounces import LANDED, MISSED, BounceTrace, Optics, follow_bounces

wp.set_module_options({"enable_backward": False})

MIN_NORMAL_AGREEMENT = 0.5
"""The edges of a bounced beam entered its first object, and left its last, through faces whose
normals are within 60° of each other (neighbouring facets of a curved surface, not two faces of a
box)."""

MIN_DOWNWARD = 1.0e-3
"""A bounced beam's edges must descend (d_z below −MIN_DOWNWARD): its horizontal sections are
what the gathers read."""

SPLIT = 8
"""A beam whose edges parted at an object is cut into SPLIT² sub-beams."""

NONE = wp.constant(0)
"""How a primary beam's light goes on past the objects: it met none (or is lost in them),"""
WHOLE = wp.constant(1)
"""as one bounced beam,"""
SPLIT_UP = wp.constant(2)
"""or cut into SPLIT² sub-beams."""

BUILT = wp.constant(0)
"""Rows of the bounce counts: bounced beams built,"""
PARTED = wp.constant(1)
"""(sub-)beams whose light met an object but whose edges then parted (their light past it is lost),"""
RISING = wp.constant(2)
"""and bounced beams dropped because an edge leaves upwards (off a mirror, out of a ball's side)."""
BOUNCE_COUNTS = 3


@wp.func
def lost_inside(tr: BounceTrace) -> bool:
    """Whether an edge's light ended in the objects (beyond the bounce limit, or trapped)."""
    return tr.bounces > 0 and tr.end != LANDED and tr.end != MISSED


@wp.func
def same_way(tr: BounceTrace, first: BounceTrace) -> bool:
    """Whether an edge went through the objects as the ``first`` did, and on past them."""
    if tr.bounces == 0 or tr.bounces != first.bounces or tr.signature != first.signature:
        return False
    if lost_inside(tr):
        return False
    if wp.dot(tr.first_normal, first.first_normal) < MIN_NORMAL_AGREEMENT:
        return False
    return wp.dot(tr.last_normal, first.last_normal) >= MIN_NORMAL_AGREEMENT


@wp.func
def interior_ray(base: wp.array2d[wp.vec3], direction: wp.array2d[wp.vec3], b: int, lam: wp.vec3):
    """(start, unit direction) of beam b's interior ray at barycentrics ``lam``: the line through
    the points Σ λ_i p_i(z) of its horizontal sections (``section.py``), started on the base plane
    of the three vertices' heights mixed by ``lam``, a hair inside the base triangle as the beam's
    own edges are traced (``build.py``)."""
    u = wp.vec2(0.0)
    r = wp.vec2(0.0)
    z = float(0.0)
    for e in range(3):
        d = direction[b, e]
        re = wp.vec2(d[0], d[1]) / d[2]
        v = base[b, e]
        u += lam[e] * (wp.vec2(v[0], v[1]) - v[2] * re)
        r += lam[e] * re
        z += lam[e] * v[2]
    xy = u + z * r
    start = wp.vec3(xy[0], xy[1], z)
    c = (base[b, 0] + base[b, 1] + base[b, 2]) / 3.0
    return start + 1.0e-5 * (c - start), wp.normalize(wp.vec3(-r[0], -r[1], -1.0))


@wp.func
def follow_interior(mesh: wp.uint64, face_receiver: wp.array[wp.int32], optics: Optics, n_w: float,
                    base: wp.array2d[wp.vec3], direction: wp.array2d[wp.vec3], b: int,
                    lam: wp.vec3) -> BounceTrace:
    """Beam b's interior ray at barycentrics ``lam`` followed through the objects (at a vertex,
    along the edge's own direction)."""
    o, d = interior_ray(base, direction, b, lam)
    if lam[0] == 1.0:
        d = direction[b, 0]  # the edges themselves, exactly
    elif lam[1] == 1.0:
        d = direction[b, 1]
    elif lam[2] == 1.0:
        d = direction[b, 2]
    return follow_bounces(mesh, face_receiver, optics, n_w, o, d)


@wp.kernel
def bounce_needs(
    mesh: wp.uint64,
    face_receiver: wp.array[wp.int32],
    optics: Optics,
    beams_per_group: int,
    base: wp.array2d[wp.vec3],
    direction: wp.array2d[wp.vec3],
    weight: wp.array[wp.float32],
    need: wp.array[wp.int32],
    slots: wp.array[wp.int32],
):
    """How primary beam b's light goes on past the objects (``need``) and the bounced slots it
    takes (``slots``: 0, 1 or SPLIT²)."""
    b = wp.tid()
    need[b] = NONE
    slots[b] = 0
    if weight[b] <= 0.0:
        return
    n_w = optics.water_ior[b / beams_per_group]
    t0 = follow_interior(mesh, face_receiver, optics, n_w, base, direction, b, wp.vec3(1.0, 0.0, 0.0))
    t1 = follow_interior(mesh, face_receiver, optics, n_w, base, direction, b, wp.vec3(0.0, 1.0, 0.0))
    t2 = follow_interior(mesh, face_receiver, optics, n_w, base, direction, b, wp.vec3(0.0, 0.0, 1.0))
    if t0.bounces == 0 and t1.bounces == 0 and t2.bounces == 0:
        return  # the beam met no glass or mirror
    if same_way(t0, t0) and same_way(t1, t0) and same_way(t2, t0):
        need[b] = WHOLE
        slots[b] = 1
        return
    if lost_inside(t0) and lost_inside(t1) and lost_inside(t2):
        return  # beyond the bounce limit or trapped, as a whole
    need[b] = SPLIT_UP
    slots[b] = SPLIT * SPLIT


@wp.kernel
def bounce_sources(slots: wp.array[wp.int32], offset: wp.array[wp.int32], source: wp.array[wp.int32]):
    """source[s] = b for each of primary b's bounced slots s."""
    b = wp.tid()
    for j in range(slots[b]):
        source[offset[b] + j] = b


@wp.kernel
def build_bounced(
    mesh: wp.uint64,
    face_receiver: wp.array[wp.int32],
    optics: Optics,
    plane_z: float,
    beams_per_group: int,
    first: int,
    sub_corners: wp.array2d[wp.vec3],
    need: wp.array[wp.int32],
    offset: wp.array[wp.int32],
    source: wp.array[wp.int32],
    base: wp.array2d[wp.vec3],
    direction: wp.array2d[wp.vec3],
    transmit: wp.array2d[wp.float32],
    end_m: wp.array2d[wp.float32],
    ends: wp.array2d[wp.vec3],
    weight: wp.array[wp.float32],
    area_coef: wp.array[wp.vec3],
    before: wp.array2d[wp.float32],
    counts: wp.array[wp.int32],
):
    """Bounced slot ``first + s``: the whole beam past the objects, or sub-beam j of its SPLIT²
    (``sub_corners[j]``: its corners' barycentrics in the primary); weight 0 where its rays parted
    or one leaves upwards."""
    s = wp.tid()
    b = source[s]
    j = s - offset[b]
    out = first + s
    weight[out] = 0.0
    lam0 = wp.vec3(1.0, 0.0, 0.0)
    lam1 = wp.vec3(0.0, 1.0, 0.0)
    lam2 = wp.vec3(0.0, 0.0, 1.0)
    share = float(1.0)
    if need[b] == SPLIT_UP:
        lam0 = sub_corners[j, 0]
        lam1 = sub_corners[j, 1]
        lam2 = sub_corners[j, 2]
        share = 1.0 / float(SPLIT * SPLIT)
    n_w = optics.water_ior[b / beams_per_group]
    t0 = follow_interior(mesh, face_receiver, optics, n_w, base, direction, b, lam0)
    t1 = follow_interior(mesh, face_receiver, optics, n_w, base, direction, b, lam1)
    t2 = follow_interior(mesh, face_receiver, optics, n_w, base, direction, b, lam2)
    # finite geometry for the slot whatever happens (it is binned only with weight > 0)
    for e in range(3):
        base[out, e] = base[b, e]
        direction[out, e] = direction[b, e]
        transmit[out, e] = 0.0
        end_m[out, e] = 0.0
        before[out, e] = 0.0
    area_coef[out] = area_coef[b]
    if t0.bounces == 0 and t1.bounces == 0 and t2.bounces == 0:
        return  # a sub-beam beside the object: the primary delivers its light
    if not (same_way(t0, t0) and same_way(t1, t0) and same_way(t2, t0)):
        wp.atomic_add(counts, PARTED, 1)
        return
    if t0.direction[2] > -MIN_DOWNWARD or t1.direction[2] > -MIN_DOWNWARD or t2.direction[2] > -MIN_DOWNWARD:
        wp.atomic_add(counts, RISING, 1)
        return
    base[out, 0] = t0.origin
    base[out, 1] = t1.origin
    base[out, 2] = t2.origin
    direction[out, 0] = t0.direction
    direction[out, 1] = t1.direction
    direction[out, 2] = t2.direction
    tb = wp.vec3(transmit[b, 0], transmit[b, 1], transmit[b, 2])
    transmit[out, 0] = wp.dot(lam0, tb) * t0.transmit
    transmit[out, 1] = wp.dot(lam1, tb) * t1.transmit
    transmit[out, 2] = wp.dot(lam2, tb) * t2.transmit
    before[out, 0] = t0.path_m
    before[out, 1] = t1.path_m
    before[out, 2] = t2.path_m
    area_coef[out] = section_coefficients(t0.origin, t1.origin, t2.origin, t0.direction, t1.direction,
                                          t2.direction)
    end_m[out, 0] = edge_end(mesh, t0.origin, t0.direction, plane_z)
    end_m[out, 1] = edge_end(mesh, t1.origin, t1.direction, plane_z)
    end_m[out, 2] = edge_end(mesh, t2.origin, t2.direction, plane_z)
    fill_ends(base, direction, end_m, out, ends)
    weight[out] = share * weight[b]
    wp.atomic_add(counts, BUILT, 1)

