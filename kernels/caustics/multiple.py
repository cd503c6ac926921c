"""Multiple scattering (``optics.scattering = "multiple"``): a Monte Carlo photon random walk.

Photons leave the moving surface on a stratified grid (``mc_samples``² per surface cell), each
carrying its share of the refracted light of one direction (the sun's, a point of its disk or of
the sky, taken in turn) in one band; they travel exponential free paths of
mean 1/c(λ), and at each interaction keep the single-scattering albedo b/c of their weight (the
rest is absorbed there) and turn by the phase function, sampled by inverting its cumulative
distribution (a table). A photon ends on the flat floor (its weight is deposited into the map),
above the mean surface going up (it escapes), or after ``mc_max_events`` interactions (its weight
is counted as truncated). Every watt is accounted for in ``tallies``.

A photon whose weight falls below ROULETTE_FRACTION of its starting weight plays Russian roulette
(Veach 1997 §2.5 gives the method; it is unbiased): it survives with probability weight / w_r at
the weight w_r = ROULETTE_FRACTION × its start, or ends. Long paths so end instead of carrying
subnormal weights to ``mc_max_events``; the ``ROULETTE`` tally keeps the books exact, adding the
weight of the photons that end and subtracting what the survivors gain (zero on average).
"""

import warp as wp

from warpcaustics.kernels.geometry import cell_centre, sun_into_water

wp.set_module_options({"enable_backward": False})

TRANSMITTED = wp.constant(0)
FLOOR = wp.constant(1)
ESCAPED = wp.constant(2)
ABSORBED = wp.constant(3)
UNSCATTERED = wp.constant(4)
TRUNCATED = wp.constant(5)
ROULETTE = wp.constant(6)
TALLIES = 7
"""Columns of the (K, TALLIES) float64 tally array [W nm⁻¹]."""

ROULETTE_FRACTION = wp.constant(1.0 / 64.0)
"""A photon plays Russian roulette once its weight is below this fraction of its start."""


@wp.struct
class Walk:
    eta: float
    """n_air / n_water."""
    floor_z: float
    extent_m: float
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
def sample_cosine(table: wp.array[wp.float32], u: float) -> float:
    """cos θ of a scattering angle drawn from the phase function: θ by linear interpolation in the
    inverse cumulative table (θ at equally spaced probabilities)."""
    n = table.shape[0] - 1
    x = u * float(n)
    i = wp.min(int(x), n - 1)
    t = x - float(i)
    return wp.cos((1.0 - t) * table[i] + t * table[i + 1])


@wp.func
def turn(d: wp.vec3, cos_theta: float, phi: float) -> wp.vec3:
    """``d`` turned by the polar angle θ (given by its cosine) at azimuth φ about itself."""
    helper = wp.vec3(1.0, 0.0, 0.0)
    if wp.abs(d[0]) > 0.9:
        helper = wp.vec3(0.0, 1.0, 0.0)
    u = wp.normalize(wp.cross(d, helper))
    v = wp.cross(d, u)
    sin_theta = wp.sqrt(wp.max(1.0 - cos_theta * cos_theta, 0.0))
    return wp.normalize(cos_theta * d + sin_theta * (wp.cos(phi) * u + wp.sin(phi) * v))


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
    for event in range(walk.max_events + 1):
        free = 1.0e30
        if c > 0.0:
            free = -wp.log(1.0 - wp.randf(state)) / c
        if d[2] < 0.0:
            to_floor = (walk.floor_z - pos[2]) / d[2]
            if free >= to_floor:
                hit = pos + to_floor * d
                tx = map_texel(hit[0], walk.map_center[0], walk, m)
                ty = map_texel(hit[1], walk.map_center[1], walk, m)
                if tx >= 0 and ty >= 0:
                    wp.atomic_add(floor_texels, ty, tx, b, weight)
                wp.atomic_add(tallies, b, FLOOR, wp.float64(weight))
                if event == 0:
                    wp.atomic_add(tallies, b, UNSCATTERED, wp.float64(weight))
                return
        elif d[2] > 0.0 and pos[2] + free * d[2] > 0.0:
            wp.atomic_add(tallies, b, ESCAPED, wp.float64(weight))
            return
        pos = pos + free * d
        if event == walk.max_events:
            wp.atomic_add(tallies, b, TRUNCATED, wp.float64(weight))
            return
        wp.atomic_add(tallies, b, ABSORBED, wp.float64(weight * (1.0 - albedo)))
        weight = weight * albedo
        if weight < roulette_weight:  # Russian roulette: on at roulette_weight, or end
            if wp.randf(state) * roulette_weight < weight:
                wp.atomic_add(tallies, b, ROULETTE, wp.float64(weight - roulette_weight))
                weight = roulette_weight
            else:
                wp.atomic_add(tallies, b, ROULETTE, wp.float64(weight))
                return
        d = turn(d, sample_cosine(inverse_cdf, wp.randf(state)), 2.0 * wp.pi * wp.randf(state))
