"""Volume caustics: single scattering of the beams into camera rays, by scan planes (Ernst et al.
2005; Liktor & Dachsbacher 2011): each ray's chord through a beam, integrated in midpoint pieces.
"""

import warp as wp

from warpcaustics.kernels.caustics.beams.irradiance import flux_density
from warpcaustics.kernels.caustics.beams.raster import TileGrid, in_frame, tile_index, tile_of
from warpcaustics.kernels.caustics.beams.section import (
    BeamCorners,
    Beams,
    barycentrics,
    beam_group,
    clamped_sample,
    copy_offset,
    load_corners,
    safe_area,
    sample_beam,
    section_copies,
    shadow_slack,
    water_path,
    xy,
)
from warpcaustics.kernels.optics.phase import phase_value
from warpcaustics.kernels.scene.camera.pinhole import PinholeCamera

wp.set_module_options({"enable_backward": False})

PARALLEL_COS = 1.0e-4
"""``|v × d̄|`` below which a view ray counts as running along a beam (DESIGN.md)."""

MAX_CHORD_PIECES = 16
"""Most midpoint pieces a scan-plane chord is split into for the in-scattering integral."""


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
    """What the volume pass reads besides the camera and the tile lists: the pass's beams
    (:class:`Beams`), ``copies`` × ``copies`` periodic copies of each ``extent_m`` apart, and the
    medium's scattering per band [1/m] and phase function (kind 0: Henyey–Greenstein with
    ``hg_g``; 1: the table)."""

    beams: Beams
    copies: int
    soft_fade_m: float
    """Liktor & Dachsbacher 2011 §5.2's soft fade distance [m]; 0 = off."""
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
    fade = float(1.0)
    if sb.soft_fade_m > 0.0:  # §5.2: the near face's distance in front of the receiver, over the fade
        fade = wp.min((s_max - s_a) / sb.soft_fade_m, 1.0)
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
    bm = sb.beams
    g = beam_group(bm, b)
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
        density = flux_density(bm, b, smp, x[2], lattice_wraps)
        e_perp = density / wp.abs(smp.d[2])
        f = piece * phase * e_perp
        if sb.soft_fade_m > 0.0:
            f = f * fade
        path = water_path(bm, b, smp) + s_m
        for jj in range(bm.wavelengths_per_group):
            k = g * bm.wavelengths_per_group + jj
            scattered = f * sb.scattering_per_m[k]
            radiance[k, j, i] = radiance[k, j, i] + scattered * bm.sun_irradiance[k] * wp.exp(
                -bm.attenuation_per_m[k] * path
            )
    return 1


@wp.func
def copy_corners(sb: ShaftBeams, bc: int):
    """Beam copy ``bc = b · copies² + c``: the beam b, its shift and its corners."""
    per_beam = sb.copies * sb.copies
    b = bc / per_beam
    corners = load_corners(sb.beams, b)
    return b, copy_offset(bc % per_beam, sb.copies, sb.beams.extent_m), corners


@wp.func
def outside_box(q: wp.vec2, lo: wp.vec2, hi: wp.vec2) -> bool:
    """Whether a pixel centre q (in the box's frame) is outside the oriented box [lo, hi]."""
    return q[0] < lo[0] - 1.0e-3 or q[0] > hi[0] + 1.0e-3 or q[1] < lo[1] - 1.0e-3 or q[1] > hi[1] + 1.0e-3


@wp.struct
class ScreenBins:
    """The beam copies binned into screen tiles of ``tile_pixels`` pixels (``grid``, each tile's list
    ``items[start[t] : start[t] + count[t]]``) with each copy's oriented box (``box_axis``,
    ``box_lo``, ``box_hi``, in pixels)."""

    grid: TileGrid
    start: wp.array[wp.int32]
    count: wp.array[wp.int32]
    items: wp.array[wp.int32]
    tile_pixels: int
    box_axis: wp.array[wp.vec2]
    box_lo: wp.array[wp.vec2]
    box_hi: wp.array[wp.vec2]


@wp.func
def pixel_chords(
    bins: ScreenBins, cam: PinholeCamera, rays: wp.array2d[wp.vec3], depth: wp.array2d[wp.float32],
    sb: ShaftBeams, j: int, i: int, radiance: wp.array3d[wp.float32], pairs: wp.array[wp.int32]
):
    """Pixel (j, i)'s radiance from the beam copies of its tile whose oriented box holds its centre
    (a thread per pixel: the GPU's form)."""
    for k in range(radiance.shape[0]):
        radiance[k, j, i] = 0.0
    v = rays[j, i]
    o = cam.position
    s_max = depth[j, i]
    t = tile_index(bins.grid, i / bins.tile_pixels, j / bins.tile_pixels)
    start = bins.start[t]
    centre = wp.vec2(float(i) + 0.5, float(j) + 0.5)
    count = bins.count[t]
    boxed = int(0)
    chords = int(0)
    for item in range(count):
        bc = bins.items[start + item]
        if outside_box(in_frame(centre, bins.box_axis[bc]), bins.box_lo[bc], bins.box_hi[bc]):
            continue  # the ray passes outside the beam's hull
        boxed += 1
        b, shift, corners = copy_corners(sb, bc)
        frame = chord_frame(corners, shift, o)
        chords += chord_radiance(sb, corners, frame, b, shift, o, v, s_max, j, i, radiance)
    wp.atomic_add(pairs, 0, count)
    wp.atomic_add(pairs, 1, boxed)
    wp.atomic_add(pairs, 2, chords)


@wp.func
def tile_chords(
    bins: ScreenBins, cam: PinholeCamera, rays: wp.array2d[wp.vec3], depth: wp.array2d[wp.float32],
    sb: ShaftBeams, tj: int, ti: int, radiance: wp.array3d[wp.float32], pairs: wp.array[wp.int32]
):
    """:func:`pixel_chords` for every pixel of tile (tj, ti) (a thread per tile: the CPU's form,
    the same result to the bit): the tile's list is walked once, not once per pixel, and each beam
    copy's oriented box is tested at the tile's pixel centres. Every pixel still adds its beams in
    list order. (Narrowing each copy's rows and per-row pixel spans to the box first cost more than
    the tests it saved: the pass takes 0.94–0.98× the time without it at 160×120, same shafts.)"""
    tile_pixels = bins.tile_pixels
    x0 = ti * tile_pixels
    y0 = tj * tile_pixels
    x1 = wp.min(x0 + tile_pixels, radiance.shape[2])
    y1 = wp.min(y0 + tile_pixels, radiance.shape[1])
    for j in range(y0, y1):
        for i in range(x0, x1):
            for k in range(radiance.shape[0]):
                radiance[k, j, i] = 0.0
    o = cam.position
    t = tile_index(bins.grid, ti, tj)
    start = bins.start[t]
    count = bins.count[t]
    boxed = int(0)
    chords = int(0)
    for item in range(count):
        bc = bins.items[start + item]
        axis = bins.box_axis[bc]
        lo = bins.box_lo[bc]
        hi = bins.box_hi[bc]
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


@wp.kernel
def scan_plane_radiance(
    bins: ScreenBins,
    cam: PinholeCamera,
    rays: wp.array2d[wp.vec3],
    depth: wp.array2d[wp.float32],
    sb: ShaftBeams,
    per_tile: int,
    radiance: wp.array3d[wp.float32],
    pairs: wp.array[wp.int32],
):
    """Single-scattered radiance of the beams along each pixel's ray (K, H, W) [W m^-2 sr^-1
    nm^-1]: the chords (:func:`chord_radiance`) of the beam copies in the pixel's tile list whose
    oriented box holds the pixel centre. Launched over the pixels (H, W) with ``per_tile = 0``
    (:func:`pixel_chords`, the GPU's form) or over the screen tiles with ``per_tile = 1``
    (:func:`tile_chords`, the CPU's; the same result to the bit). ``pairs`` counts (pixel, beam
    copy) pairs: [0] in the tile lists, [1] inside the oriented box (scan plane computed), [2]
    with a chord."""
    j, i = wp.tid()
    if per_tile == 0:
        pixel_chords(bins, cam, rays, depth, sb, j, i, radiance, pairs)
    else:
        tile_chords(bins, cam, rays, depth, sb, j, i, radiance, pairs)


@wp.kernel
def point_inscatter(
    grid: TileGrid,
    tile_start: wp.array[wp.int32],
    tile_count: wp.array[wp.int32],
    tile_items: wp.array[wp.int32],
    sb: ShaftBeams,
    points: wp.array[wp.vec3],
    views: wp.array[wp.vec3],
    along_m: wp.array[wp.float32],
    piece_m: wp.array[wp.float32],
    radiance: wp.array2d[wp.float32],
):
    """One midpoint piece of a view ray's in-scattering integral, added to ``radiance`` (K, P): at
    each point x of a ray seen along ``views`` (unit, away from the eye), ``piece · σ_s p(cos θ)
    E⊥(x) exp(−c (ℓ(x) + s))`` summed over the beams of the point's horizontal tile (and their
    periodic images) that hold it before their end: the same integrand as :func:`chord_radiance`,
    sampled along a ray that does not start at the pinhole (the view from above the water, whose
    rays refract at the surface). ``along_m``: s, the distance from where the ray entered the water."""
    p_index = wp.tid()
    piece = piece_m[p_index]
    if piece <= 0.0:
        return
    x = points[p_index]
    v = views[p_index]
    t = tile_of(grid, xy(x))
    if t < 0:
        return
    bm = sb.beams
    start = tile_start[t]
    for item in range(tile_count[t]):
        b = tile_items[start + item]
        kx0, kx1, ky0, ky1 = section_copies(bm, b, x)
        for ky in range(ky0, ky1 + 1):
            for kx in range(kx0, kx1 + 1):
                q = x + wp.vec3(float(kx) * bm.extent_m, float(ky) * bm.extent_m, 0.0)
                smp = sample_beam(bm, b, q)
                if smp.inside == 0 or smp.beyond_end_m > shadow_slack(smp.area):
                    continue
                phase = phase_value(sb.phase_kind, sb.hg_g, sb.angles_rad, sb.log_phase, sb.cone_phase,
                                    -wp.dot(smp.d, v))
                f = piece * phase * flux_density(bm, b, smp, q[2], bm.periodic) / wp.abs(smp.d[2])
                g = beam_group(bm, b)
                before = water_path(bm, b, smp)
                for jj in range(bm.wavelengths_per_group):
                    k = g * bm.wavelengths_per_group + jj
                    path = before + along_m[p_index]
                    light = bm.sun_irradiance[k] * wp.exp(-bm.attenuation_per_m[k] * path)
                    radiance[k, p_index] = radiance[k, p_index] + f * sb.scattering_per_m[k] * light
