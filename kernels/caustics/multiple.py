"""Multiple scattering (``optics.scattering = "multiple"``): a Monte Carlo photon random walk.

Photons leave the moving surface on a stratified grid (``mc_samples``² per surface cell), each
carrying its share of the refracted light of one direction (the sun's, a point of its disk or of
the sky, taken in turn) in one band; they travel exponential free paths of
mean 1/c(λ), and at each interaction keep the single-scattering albedo b/c of their weight (the
rest is absorbed there) and turn by the phase function, sampled by inverting its cumulative
distribution (a table). Every watt is accounted for in ``tallies``.

The boundaries (issue 32): a photon that meets the moving surface from below (its bilinear height
field, the same the photons leave from, found by marching the path through the surface's height
band in half-cell steps and bisecting the crossing) meets it at the local normal: the Fresnel
transmittance (Born & Wolf §1.5.2, water to air) of its weight escapes, the rest is reflected
specularly — all of it past the critical angle (48.6° at n = 1.333), total internal reflection.
A photon that reaches the flat floor adds its weight to the floor map (the map is the downwelling
irradiance *incident* on the floor, as every method's) and walks on with the floor's albedo of it,
reflected Lambertian (a cosine-weighted direction); a black floor (albedo 0) ends it there. The
surface and the floor each count as an event towards ``mc_max_events``, after which a photon's
weight is counted as truncated.

A photon whose weight falls below ROULETTE_FRACTION of its starting weight plays Russian roulette
(Veach 1997 §2.5 gives the method; it is unbiased): it survives with probability weight / w_r at
the weight w_r = ROULETTE_FRACTION × its start, or ends. Long paths so end instead of carrying
subnormal weights to ``mc_max_events``; the ``ROULETTE`` tally keeps the books exact, adding the
weight of the photons that end and subtracting what the survivors gain (zero on average).
"""

import warp as wp

from warpcaustics.kernels.geometry import cell_centre, fresnel_transmittance, grid_bilinear, sun_into_water

wp.set_module_options({"enable_backward": False})

TRANSMITTED = wp.constant(0)
FLOOR = wp.constant(1)
ESCAPED = wp.constant(2)
ABSORBED = wp.constant(3)
UNSCATTERED = wp.constant(4)
TRUNCATED = wp.constant(5)
ROULETTE = wp.constant(6)
FLOOR_REFLECTED = wp.constant(7)
SURFACE_REFLECTED = wp.constant(8)
TALLIES = 9
"""Columns of the (K, TALLIES) float64 tally array [W nm⁻¹]."""

ROULETTE_FRACTION = wp.constant(1.0 / 64.0)
"""A photon plays Russian roulette once its weight is below this fraction of its start."""


@wp.struct
class Walk:
    eta: float
    """n_air / n_water."""
    floor_z: float
    extent_m: float
    surface_low: float
    """The lowest point of the surface this frame [m] (less a margin): below it, no crossing."""
    surface_high: float
    """The highest point of the surface [m] (plus a margin): a photon above it has left the water."""
    surface_slope: wp.vec2
    """The steepest slopes of the surface's bilinear height field along x and y this frame [-]
    (bounds: its steepest cell edges)."""
    surface_reflects: int
    """1: the surface reflects upwelling light (Fresnel, total internal reflection), as in the
    renders; 0: all of it leaves (a transparent top, for comparison with solvers that lack one)."""
    map_center: wp.vec2
    """Centre of the floor map [m] (a window's, or the patch's)."""
    map_extent_m: float
    """Side of the floor map [m]: a window's, or the patch's."""
    map_scale: float
    """Texels per metre of the floor map (M / its side)."""
    samples: int
    """Photons per surface cell side."""
    max_events: int
    seed: int
    """Seed of the random streams (the sun's; the sky's walk is given another)."""
    turn_seed: int
    """Seed of each surface cell's random turn of the directions over its photons."""


@wp.func
def sample_angle(table: wp.array[wp.float32], u: float) -> float:
    """θ [rad] of a scattering angle drawn from the phase function, by linear interpolation in the
    inverse cumulative table (θ at equally spaced probabilities)."""
    n = table.shape[0] - 1
    x = u * float(n)
    i = wp.min(int(x), n - 1)
    t = x - float(i)
    return (1.0 - t) * table[i] + t * table[i + 1]


@wp.func
def turn(d: wp.vec3, theta: float, phi: float) -> wp.vec3:
    """``d`` turned by the polar angle ``theta`` at azimuth φ about itself (sin θ and cos θ from θ
    itself, so that the forward peak's angles below float32's ~0.02° in cos θ still turn)."""
    helper = wp.vec3(1.0, 0.0, 0.0)
    if wp.abs(d[0]) > 0.9:
        helper = wp.vec3(0.0, 1.0, 0.0)
    u = wp.normalize(wp.cross(d, helper))
    v = wp.cross(d, u)
    return wp.normalize(wp.cos(theta) * d + wp.sin(theta) * (wp.cos(phi) * u + wp.sin(phi) * v))


SURFACE_STEPS_PER_CELL = wp.constant(2.0)
"""The finest sampling of the surface's height along a photon's path: this many per cell side."""

MAX_SURFACE_STEPS = wp.constant(4096)
"""Most samples along one path segment (a grazing path through the band is cut at this)."""

BISECTIONS = 16
"""Halvings of the step in which a path crosses the surface (to 1/65536 of a step)."""


@wp.func
def below_surface(positions: wp.array2d[wp.vec3], extent_m: float, p: wp.vec3) -> float:
    """Height of the surface above the point p [m] (positive under the water): the bilinear height
    field of the cell-centre grid (periodic), the one the photons leave from."""
    return grid_bilinear(positions, extent_m, 1, p[0], p[1])[2] - p[2]


@wp.func
def surface_crossing(walk: Walk, positions: wp.array2d[wp.vec3], pos: wp.vec3, d: wp.vec3,
                     t_end: float) -> float:
    """Distance along ``d`` from ``pos`` at which the path first leaves the water through the
    surface, within (0, t_end]; −1 if it does not. Only the part of the path inside the surface's
    height band is searched, in steps of at least half a cell and, far under the surface, of the
    gap over the fastest rate at which the path can close it (|d_x| and |d_y| times the field's
    steepest slopes along x and y, plus d_z: the step cannot pass the surface); the first step
    from under the surface to on or above it is bisected, and the last point found under it is
    returned (so a reflected photon starts in the water). A path that starts on the surface (a
    photon just refracted or reflected there) is followed until it is under it before a crossing
    counts."""
    t0 = float(0.0)
    t1 = t_end
    if d[2] > 0.0:
        t0 = wp.max(t0, (walk.surface_low - pos[2]) / d[2])
        t1 = wp.min(t1, (walk.surface_high - pos[2]) / d[2])
    elif d[2] < 0.0:
        t0 = wp.max(t0, (walk.surface_high - pos[2]) / d[2])
        t1 = wp.min(t1, (walk.surface_low - pos[2]) / d[2])
    elif pos[2] < walk.surface_low or pos[2] > walk.surface_high:
        return -1.0
    if t1 <= t0:
        return -1.0
    across = wp.sqrt(d[0] * d[0] + d[1] * d[1])
    # the fastest the gap can shrink per metre of path
    closing = wp.abs(d[0]) * walk.surface_slope[0] + wp.abs(d[1]) * walk.surface_slope[1] + d[2]
    if closing <= 0.0:
        return -1.0  # heading down more steeply than any slope: it cannot reach the surface
    cell = walk.extent_m / float(positions.shape[0])
    fine = cell / (SURFACE_STEPS_PER_CELL * wp.max(across, 1.0e-6))
    fine = wp.max(fine, (t1 - t0) / float(MAX_SURFACE_STEPS))
    t_prev = t0
    gap = below_surface(positions, walk.extent_m, pos + t0 * d)
    under = gap > 0.0
    t = t0
    while t < t1:
        step = fine
        if under:
            step = wp.max(fine, gap / closing)
        t = wp.min(t + step, t1)
        gap = below_surface(positions, walk.extent_m, pos + t * d)
        if under and gap <= 0.0:
            lo = t_prev
            hi = t
            for _k in range(BISECTIONS):
                mid = 0.5 * (lo + hi)
                if below_surface(positions, walk.extent_m, pos + mid * d) > 0.0:
                    lo = mid
                else:
                    hi = mid
            return lo
        if gap > 0.0:
            under = True
        t_prev = t
    return -1.0


@wp.func
def reflect_at_surface(walk: Walk, normals: wp.array2d[wp.vec3], pos: wp.vec3, d: wp.vec3):
    """(share of the weight reflected back into the water, direction after the reflection) of a
    photon leaving through the surface at ``pos``: Fresnel at the interpolated normal, water to air,
    1 past the critical angle; nothing is kept where the surface does not reflect
    (``walk.surface_reflects = 0``) or the normal faces away from the crossing (it leaves)."""
    nrm = wp.normalize(grid_bilinear(normals, walk.extent_m, 1, pos[0], pos[1]))
    cos_i = wp.dot(d, nrm)
    kept = float(0.0)
    if cos_i > 0.0 and walk.surface_reflects != 0:
        kept = 1.0 - fresnel_transmittance(cos_i, 1.0 / walk.eta)
    return kept, wp.normalize(d - 2.0 * cos_i * nrm)


@wp.func
def lambertian_up(u1: float, u2: float) -> wp.vec3:
    """An upward direction from a horizontal Lambertian reflector: cosine-weighted (Malley's method,
    Pharr, Jakob & Humphreys, PBRT 3rd ed. §13.6.3)."""
    r = wp.sqrt(u1)
    phi = 2.0 * wp.pi * u2
    return wp.vec3(r * wp.cos(phi), r * wp.sin(phi), wp.sqrt(wp.max(1.0 - u1, 0.0)))


@wp.func
def map_texel(x: float, centre: float, walk: Walk, m: int) -> int:
    """Texel of coordinate x [m] on the floor map, from the periodic image of x nearest the map's
    centre (the whole patch, or a window at most half of it); −1 outside a window. On the whole
    patch every x has a texel: one rounded onto the far edge of the seam is kept on the map."""
    d = x - centre
    d = d - walk.extent_m * wp.floor(d / walk.extent_m + 0.5)
    u = (d + 0.5 * walk.map_extent_m) * walk.map_scale
    if walk.map_extent_m < walk.extent_m and (u < 0.0 or u >= float(m)):
        return -1
    return wp.clamp(int(u), 0, m - 1)


@wp.kernel
def random_walk(
    walk: Walk,
    positions: wp.array2d[wp.vec3],
    normals: wp.array2d[wp.vec3],
    visible: wp.array3d[wp.float32],
    light_dirs: wp.array[wp.vec3],
    light_irradiance: wp.array2d[wp.float32],
    absorption_per_m: wp.array[wp.float32],
    scattering_per_m: wp.array[wp.float32],
    inverse_cdf: wp.array[wp.float32],
    floor_albedo: wp.array[wp.float32],
    floor_texels: wp.array3d[wp.float32],
    tallies: wp.array2d[wp.float64],
):
    """One photon in band b from sub-sample q of surface cell (iy, ix) of a periodic sea. The
    photons of the surface take the D directions ``light_dirs`` in turn (a point sun is one; the
    sun's disk or the sky are several), each direction j bringing ``light_irradiance[j, b]`` on a
    plane perpendicular to it [W m⁻² nm⁻¹], so a photon stands for D times its direction's share.
    ``visible`` (V, N, N) is the crests' shading: V = 1 shades every direction alike (the sun's
    disk by its centre), V = D one shading per direction (the sky)."""
    b, iy, ix, q = wp.tid()
    n = positions.shape[0]
    m = floor_texels.shape[0]
    state = wp.rand_init(walk.seed, ((b * n + iy) * n + ix) * walk.samples * walk.samples + q)
    s = walk.samples
    tu = (float(q % s) + wp.randf(state)) / float(s)
    tv = (float(q / s) + wp.randf(state)) / float(s)
    # the surface at (tu, tv) inside the cell between vertex (ix, iy) and its periodic neighbours
    ix1 = (ix + 1) % n
    iy1 = (iy + 1) % n
    cell = walk.extent_m / float(n)
    xy = cell_centre(ix, iy, n, walk.extent_m)
    z = ((1.0 - tv) * ((1.0 - tu) * positions[iy, ix][2] + tu * positions[iy, ix1][2])
         + tv * ((1.0 - tu) * positions[iy1, ix][2] + tu * positions[iy1, ix1][2]))
    nrm = wp.normalize((1.0 - tv) * ((1.0 - tu) * normals[iy, ix] + tu * normals[iy, ix1])
                       + tv * ((1.0 - tu) * normals[iy1, ix] + tu * normals[iy1, ix1]))
    pos = wp.vec3(xy[0] + tu * cell, xy[1] + tv * cell, z)
    count = light_dirs.shape[0]
    j = int(0)
    if count > 1:
        # The cell's photons take the directions in turn from a random start drawn per cell (and
        # band), so no direction is tied to one part of every cell: the expected map is unbiased.
        cell_rng = wp.rand_init(walk.turn_seed, (b * n + iy) * n + ix)
        j = (q + wp.randi(cell_rng, 0, count)) % count
    sun_dir = light_dirs[j]
    v = visible[j % visible.shape[0]]
    cos_i = wp.dot(nrm, sun_dir)
    lit = ((1.0 - tv) * ((1.0 - tu) * v[iy, ix] + tu * v[iy, ix1])
           + tv * ((1.0 - tu) * v[iy1, ix] + tu * v[iy1, ix1]))
    d, transmitted = sun_into_water(nrm, sun_dir, walk.eta)
    weight = light_irradiance[j, b] * float(count) * wp.max(cos_i, 0.0) * transmitted * lit * cell * cell / (
        float(s * s) * nrm[2])
    if weight <= 0.0:
        return
    wp.atomic_add(tallies, b, TRANSMITTED, wp.float64(weight))
    roulette_weight = ROULETTE_FRACTION * weight
    c = absorption_per_m[b] + scattering_per_m[b]
    albedo = float(0.0)
    if c > 0.0:
        albedo = scattering_per_m[b] / c
    direct = bool(True)  # neither scattered nor reflected yet
    for event in range(walk.max_events + 1):
        free = 1.0e30
        if c > 0.0:
            free = -wp.log(1.0 - wp.randf(state)) / c
        reach = free
        to_floor = float(-1.0)
        if d[2] < 0.0:
            to_floor = (walk.floor_z - pos[2]) / d[2]
            reach = wp.min(free, to_floor)
        out = surface_crossing(walk, positions, pos, d, reach)
        if out < 0.0 and d[2] > 0.0 and pos[2] + reach * d[2] > walk.surface_high:
            # above the highest crest without a crossing found (a grazing path): it has left
            wp.atomic_add(tallies, b, ESCAPED, wp.float64(weight))
            return
        if out < 0.0 and to_floor >= 0.0 and free >= to_floor:  # the floor: deposit, then reflect
            pos = pos + to_floor * d
            tx = map_texel(pos[0], walk.map_center[0], walk, m)
            ty = map_texel(pos[1], walk.map_center[1], walk, m)
            if tx >= 0 and ty >= 0:
                wp.atomic_add(floor_texels, ty, tx, b, weight)
            wp.atomic_add(tallies, b, FLOOR, wp.float64(weight))
            if direct:
                wp.atomic_add(tallies, b, UNSCATTERED, wp.float64(weight))
            reflected = weight * floor_albedo[b]
            if reflected <= 0.0:
                return
            wp.atomic_add(tallies, b, FLOOR_REFLECTED, wp.float64(reflected))
            weight = reflected
            d = lambertian_up(wp.randf(state), wp.randf(state))
        elif out >= 0.0:  # the surface from below: Fresnel, or total internal reflection
            pos = pos + out * d
            kept, d = reflect_at_surface(walk, normals, pos, d)
            wp.atomic_add(tallies, b, ESCAPED, wp.float64(weight * (1.0 - kept)))
            if kept <= 0.0:
                return
            wp.atomic_add(tallies, b, SURFACE_REFLECTED, wp.float64(weight * kept))
            weight = weight * kept
        else:  # an interaction in the water
            pos = pos + free * d
            if event < walk.max_events:
                wp.atomic_add(tallies, b, ABSORBED, wp.float64(weight * (1.0 - albedo)))
                weight = weight * albedo
                d = turn(d, sample_angle(inverse_cdf, wp.randf(state)), 2.0 * wp.pi * wp.randf(state))
        direct = False
        if event == walk.max_events:
            wp.atomic_add(tallies, b, TRUNCATED, wp.float64(weight))
            return
        if weight < roulette_weight:  # Russian roulette: on at roulette_weight, or end
            if wp.randf(state) * roulette_weight < weight:
                wp.atomic_add(tallies, b, ROULETTE, wp.float64(weight - roulette_weight))
                weight = roulette_weight
            else:
                wp.atomic_add(tallies, b, ROULETTE, wp.float64(weight))
                return
