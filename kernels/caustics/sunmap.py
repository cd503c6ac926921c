"""Sun-map caustics (Guardado & Sánchez-Crespo, GPU Gems ch. 2, §2.3): backward rays from the floor.

For each vertex of a fine floor mesh (a texel centre of the floor map), a ray goes up to the
water surface, is refracted out into the air by Snell's law, and the sun's brightness is looked up
from the angle γ between that ray and the direction to the sun: a soft sun map that is 1 on the
sun's disk and falls to 0 across its halo (the chapter: the disk is 0.53° across, its halo "most
days covering an arc 10 times larger"). The chapter's sun is overhead and its rays vertical; for
any sun we cast the backward ray along the sun's still-water refracted direction, so a flat sea
sends every ray exactly to the sun's centre (and the chapter's case is the overhead sun).
"""

import warp as wp

from warpcaustics.kernels.geometry import cell_centre, grid_bilinear, refract
from warpcaustics.kernels.water.procedural import OctaveWaves, octave_wave

wp.set_module_options({"enable_backward": False})

RAY_ITERATIONS = 4
"""Fixed-point steps for the ray–surface meeting point: each moves it to the height found at the
last one (for the chapter's vertical ray the first step is exact). For an oblique ray over a
surface whose slope along the ray exceeds the ray's own, the steps need not converge: the point
found is then near, not on, the surface."""


@wp.struct
class SunMap:
    up: wp.vec3
    """Unit backward ray from the floor towards the surface (minus the sun's refracted direction)."""
    sun_dir: wp.vec3
    """Unit vector towards the sun, in the air."""
    eta: float
    """n_water / n_air for the ray leaving the water [-]."""
    cos_disk: float
    """cos of the sun disk's angular radius."""
    disk_rad: float
    """Angular radius of the disk [rad]."""
    halo_rad: float
    """Angular radius of the halo, where the brightness reaches 0 [rad]."""
    floor_z: float
    """Height of the (flat) floor [m]."""
    extent_m: float
    """Side of the water patch and of the map [m]."""
    periodic: int
    """1: the surface tiles; 0: rays meeting the surface outside the patch see no sun."""
    light_scale: float
    """``per_pixel``: angle from the sun [rad] per metre of the light-map offset, (n − 1)/H for
    the still depth H: Snell's small-tilt deviation at the mean depth (our calibration of the
    chapter's light map, whose own scale is its demo's constants)."""


@wp.func
def brightness_at(params: SunMap, gamma: float) -> float:
    """The soft sun map at the angle ``gamma`` [rad] from the sun's centre."""
    if gamma <= params.disk_rad:
        return 1.0
    if gamma >= params.halo_rad:
        return 0.0
    t = (gamma - params.disk_rad) / (params.halo_rad - params.disk_rad)
    return 0.5 * (1.0 + wp.cos(wp.pi * t))


@wp.func
def sun_brightness(params: SunMap, ray: wp.vec3) -> float:
    """The soft sun map: 1 inside the disk, a raised-cosine fall-off to 0 at the halo's edge."""
    c = wp.dot(ray, params.sun_dir)
    if c >= params.cos_disk:
        return 1.0
    # atan2, not acos: exact near 0
    return brightness_at(params, wp.atan2(wp.length(wp.cross(ray, params.sun_dir)), c))


@wp.func
def leave_water(params: SunMap, normal: wp.vec3) -> float:
    """Brightness seen along the backward ray after it refracts out through a surface with unit
    upward ``normal``; 0 on total internal reflection."""
    out = refract(params.up, -normal, params.eta)
    if wp.length_sq(out) == 0.0:
        return 0.0
    return sun_brightness(params, wp.normalize(out))


@wp.func
def inside_patch(params: SunMap, p: wp.vec3) -> bool:
    half = 0.5 * params.extent_m
    return params.periodic != 0 or (wp.abs(p[0]) <= half and wp.abs(p[1]) <= half)


@wp.kernel
def sunmap_grid(
    params: SunMap,
    positions: wp.array2d[wp.vec3],
    normals: wp.array2d[wp.vec3],
    brightness: wp.array2d[wp.float32],
):
    """Sun map at each texel from the surface grid: heights and normals (spectral for the FFT ocean,
    differences for height fields and pools) bilinearly interpolated where the backward ray meets
    the surface. The grid is looked up at the undisplaced (x, y): choppy displacement is ignored."""
    j, i = wp.tid()
    xy = cell_centre(i, j, brightness.shape[0], params.extent_m)
    start = wp.vec3(xy[0], xy[1], params.floor_z)
    p = start + params.up * ((0.0 - params.floor_z) / params.up[2])
    for _k in range(RAY_ITERATIONS):
        z = grid_bilinear(positions, params.extent_m, params.periodic, p[0], p[1])[2]
        p = start + params.up * ((z - params.floor_z) / params.up[2])
    value = float(0.0)
    if inside_patch(params, p):
        n = wp.normalize(grid_bilinear(normals, params.extent_m, params.periodic, p[0], p[1]))
        value = leave_water(params, n)
    brightness[j, i] = value


@wp.kernel
def sunmap_procedural(
    params: SunMap,
    waves: OctaveWaves,
    time_s: float,
    brightness: wp.array2d[wp.float32],
):
    """Sun map at each texel from the procedural waves' analytic height and gradient where the
    backward ray meets the surface (the chapter's own shader evaluates ``gradwave`` there)."""
    j, i = wp.tid()
    xy = cell_centre(i, j, brightness.shape[0], params.extent_m)
    start = wp.vec3(xy[0], xy[1], params.floor_z)
    p = start + params.up * ((0.0 - params.floor_z) / params.up[2])
    w = octave_wave(waves, p[0], p[1], time_s)
    for _k in range(RAY_ITERATIONS):
        p = start + params.up * ((w[0] - params.floor_z) / params.up[2])
        w = octave_wave(waves, p[0], p[1], time_s)
    value = float(0.0)
    if inside_patch(params, p):
        value = leave_water(params, wp.normalize(wp.vec3(-w[1], -w[2], 1.0)))
    brightness[j, i] = value


@wp.func
def light_map(params: SunMap, normal: wp.vec3, depth: float) -> float:
    """§2.5's per-pixel lookup (Listing 2-2): the line from the floor along the wave ``normal``
    meets the plane ``depth`` above (``line_plane_intercept``) at the horizontal offset
    depth·tan θ_n, and the light map (the sun overhead as an environment map, Fig. 2-7) is read
    there: the sun map at the angle ``light_scale`` × offset. No Snell's law, no total internal
    reflection; the same tilt reads farther out, so a sharper sun, the deeper the floor."""
    tilt = wp.sqrt(normal[0] * normal[0] + normal[1] * normal[1]) / wp.max(normal[2], 1.0e-6)
    return brightness_at(params, params.light_scale * wp.max(depth, 0.0) * tilt)


@wp.func
def pixel_point(params: SunMap, i: int, j: int, m: int) -> wp.vec3:
    """Where §2.5 evaluates the wave for texel (i, j): directly above it for the chapter's overhead
    sun; for any sun, where the sun's still-water refracted ray through the texel crosses the
    mean water level (no search for the moving surface)."""
    xy = cell_centre(i, j, m, params.extent_m)
    start = wp.vec3(xy[0], xy[1], params.floor_z)
    return start + params.up * ((0.0 - params.floor_z) / params.up[2])


@wp.kernel
def sunmap_pixel_grid(
    params: SunMap,
    positions: wp.array2d[wp.vec3],
    normals: wp.array2d[wp.vec3],
    brightness: wp.array2d[wp.float32],
):
    """GPU Gems §2.5's per-pixel variant from the surface grid: height and normal bilinearly
    interpolated at :func:`pixel_point`, looked up by :func:`light_map`."""
    j, i = wp.tid()
    p = pixel_point(params, i, j, brightness.shape[0])
    value = float(0.0)
    if inside_patch(params, p):
        z = grid_bilinear(positions, params.extent_m, params.periodic, p[0], p[1])[2]
        n = wp.normalize(grid_bilinear(normals, params.extent_m, params.periodic, p[0], p[1]))
        value = light_map(params, n, z - params.floor_z)
    brightness[j, i] = value


@wp.kernel
def sunmap_pixel_procedural(
    params: SunMap,
    waves: OctaveWaves,
    time_s: float,
    brightness: wp.array2d[wp.float32],
):
    """GPU Gems §2.5's per-pixel variant from the analytic ``wave`` and ``gradwave`` (Listing 2-1)
    at :func:`pixel_point`, looked up by :func:`light_map`."""
    j, i = wp.tid()
    p = pixel_point(params, i, j, brightness.shape[0])
    value = float(0.0)
    if inside_patch(params, p):
        w = octave_wave(waves, p[0], p[1], time_s)
        value = light_map(params, wp.vec3(-w[1], -w[2], 1.0), w[0] - params.floor_z)
    brightness[j, i] = value
