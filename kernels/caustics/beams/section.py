"""One beam as a solid: its horizontal sections, the watertight inside test, its sample at a point,
its shadows, and its periodic copies.

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
"""

import warp as wp

wp.set_module_options({"enable_backward": False})

MIN_AREA_FRACTION = 1.0e-6
"""|A(z)| is floored at this fraction of the beam's base-section area (a focus is a finite peak)."""

MAX_COPIES_PER_AXIS = 64
"""A section wider than this many periods of the patch (a beam of near-horizontal rays) is gathered
in its MAX_COPIES_PER_AXIS central copies per axis only."""


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


@wp.struct
class Beams:
    """A pass's beams as the gathers read them (see the package docstring for the arrays), with
    their spectrum and what the lookups need: ``beams_per_group`` beams per index group, each
    group ``wavelengths_per_group`` bands of ``sun_irradiance`` and ``attenuation_per_m``; the
    patch ``extent_m`` (``periodic``: the sea repeats), ``quads`` per side of the uniform grid
    (``smooth`` interpolation reads the beams around a lattice vertex), and the receivers' BVH
    ``mesh`` casting shadows where ``occluders`` is set. With ``caustics.bounces`` > 1 the beams from
    ``primaries`` on are bounced beams (``bounces.py``), each edge with its water path ``before``
    its base, ``source`` the primary beam each came from; ``unlit_receiver[r]`` = 1 for a receiver
    that gathers no light (glass, mirrors)."""

    base: wp.array2d[wp.vec3]
    direction: wp.array2d[wp.vec3]
    transmit: wp.array2d[wp.float32]
    ends: wp.array2d[wp.vec3]
    weight: wp.array[wp.float32]
    area_coef: wp.array[wp.vec3]
    beams_per_group: int
    wavelengths_per_group: int
    sun_irradiance: wp.array[wp.float32]
    attenuation_per_m: wp.array[wp.float32]
    extent_m: float
    periodic: int
    quads: int
    smooth: int
    mesh: wp.uint64
    occluders: int
    primaries: int
    before: wp.array2d[wp.float32]
    source: wp.array[wp.int32]
    unlit_receiver: wp.array[wp.int32]


@wp.func
def beam_group(bm: Beams, b: int) -> int:
    """Index group of beam b (a bounced beam's is that of the primary it came from)."""
    if b >= bm.primaries:
        return bm.source[b - bm.primaries] / bm.beams_per_group
    return b / bm.beams_per_group


@wp.func
def water_path(bm: Beams, b: int, s: BeamSample) -> float:
    """Water path from the surface to the sample [m]: a bounced beam's path from its base plus its
    edges' paths before it (glass does not attenuate)."""
    if b < bm.primaries:
        return s.path_m
    return s.path_m + s.lam[0] * bm.before[b, 0] + s.lam[1] * bm.before[b, 1] + s.lam[2] * bm.before[b, 2]


@wp.func
def sample_beam(bm: Beams, b: int, p: wp.vec3) -> BeamSample:
    """The beam b at point p (already moved into the beam's periodic image)."""
    out = BeamSample()
    out.inside = 0
    v0 = bm.base[b, 0]
    v1 = bm.base[b, 1]
    v2 = bm.base[b, 2]
    d0 = bm.direction[b, 0]
    d1 = bm.direction[b, 1]
    d2 = bm.direction[b, 2]
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
    out.transmit = lam[0] * bm.transmit[b, 0] + lam[1] * bm.transmit[b, 1] + lam[2] * bm.transmit[b, 2]
    out.area = safe_area(bm.area_coef[b], z, (v0[2] + v1[2] + v2[2]) / 3.0)
    out.beyond_end_m = beyond_end(bm.ends, b, p)
    return out


@wp.func
def beyond_end(ends: wp.array2d[wp.vec3], b: int, p: wp.vec3) -> float:
    """How far p lies beyond the beam's end plane (``ends[b] = (point, unit normal)``) [m]."""
    return wp.dot(p - ends[b, 0], ends[b, 1])


@wp.func
def shadow_slack(area: float) -> float:
    """A point counts as lit up to one beam width (√|A|) beyond the beam's end plane: receivers are
    curved between edge ends, occluders lie well beyond."""
    return wp.sqrt(area) + 1.0e-4


@wp.func
def lit(bm: Beams, b: int, s: BeamSample, p: wp.vec3) -> bool:
    """Whether beam b's light reaches receiver point p. With occluders (walls, meshes, a relief)
    a ray from p back along the beam towards its base must reach it unblocked (exact shadows at
    the resolution of the BVH); with a flat floor alone the beam's end plane decides. A bounced
    beam's base spans the points where its edges left a curved object, whose surface bulges past
    that triangle (by less than half its longest side, for an object wider than the triangle): the
    ray stops that side's length short of the base."""
    if bm.occluders == 0:
        return s.beyond_end_m <= shadow_slack(s.area)
    eps = 1.0e-4 * (1.0 + s.path_m)
    length = s.path_m - 2.0 * eps
    if b >= bm.primaries:
        v0 = bm.base[b, 0]
        v1 = bm.base[b, 1]
        v2 = bm.base[b, 2]
        length -= wp.max(wp.length(v1 - v0), wp.max(wp.length(v2 - v0), wp.length(v2 - v1)))
    if length <= 0.0:
        return True
    q = wp.mesh_query_ray(bm.mesh, p - eps * s.d, -s.d, length)
    return not q.result


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
def load_corners(bm: Beams, b: int) -> BeamCorners:
    c = edge_corners(bm.base, bm.direction, bm.ends, b)
    c.transmit = wp.vec3(bm.transmit[b, 0], bm.transmit[b, 1], bm.transmit[b, 2])
    c.coef = bm.area_coef[b]
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


# --- periodic copies ----------------------------------------------------------------------------


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
def section_copies(bm: Beams, b: int, p: wp.vec3):
    """(kx0, kx1, ky0, ky1): the whole periods k for which point p moved by k L may lie in beam b's
    horizontal section at p's height (its box; k = 0 only on a walled pool)."""
    s0 = section_vertex(bm.base[b, 0], bm.direction[b, 0], p[2])
    s1 = section_vertex(bm.base[b, 1], bm.direction[b, 1], p[2])
    s2 = section_vertex(bm.base[b, 2], bm.direction[b, 2], p[2])
    lo = wp.min(wp.min(s0, s1), s2)
    hi = wp.max(wp.max(s0, s1), s2)
    kx0, kx1 = copy_range(lo[0], hi[0], p[0], 0.0, bm.extent_m, bm.periodic)
    ky0, ky1 = copy_range(lo[1], hi[1], p[1], 0.0, bm.extent_m, bm.periodic)
    return kx0, kx1, ky0, ky1


@wp.func
def period_shift(target: wp.vec2, p: wp.vec2, extent_m: float, periodic: int) -> wp.vec2:
    """The whole-period shift that moves p nearest to target (zero on a walled pool)."""
    if periodic == 0:
        return wp.vec2(0.0)
    return wp.vec2(
        extent_m * wp.floor((target[0] - p[0]) / extent_m + 0.5),
        extent_m * wp.floor((target[1] - p[1]) / extent_m + 0.5),
    )


@wp.func
def copy_offset(c: int, copies: int, extent_m: float) -> wp.vec3:
    """Shift of periodic copy c of copies×copies (centred on the patch)."""
    r = copies / 2
    return wp.vec3(float(c % copies - r) * extent_m, float(c / copies - r) * extent_m, 0.0)
