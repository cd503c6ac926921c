"""The under-water pinhole camera: G-buffer by ray casting, photon splats, light shafts, shading.

Pixel (j, i) (row j from the top) looks along
``normalize(forward + x_i tan(fov/2) aspect right + y_j tan(fov/2) up)`` with
``x_i = 2 (i + ½)/W − 1`` and ``y_j = 1 − 2 (j + ½)/H``. Its solid angle is
``(2 tan(fov/2)/H)² cos³α`` (α off the optical axis), its footprint on a receiver at distance r
with normal n is ``r² Ω / |cos(ray, n)|``.
"""

import warp as wp

from warpcaustics.kernels.optics.phase import phase_value

wp.set_module_options({"enable_backward": False})

INV_PI = 0.3183098861837907

MAX_SPLAT_RADIUS = 8
"""Largest photon splat radius [pixels]."""

MAX_CELL_SPACINGS = 16.0
"""A photon's lattice cell longer than this many surface photon spacings is not a neighbourhood
(its neighbour landed far away, past a silhouette) and gets a Gaussian instead."""

MIN_CELL_ALIGNMENT = 0.7
"""A lattice cell must lie in its receiver's surface: |cos| between the cell's and the face's
normals at least this (neighbours across the edge of a box do not)."""

TENT_PLANE_TOLERANCE = 0.1
"""A pixel's G-buffer point takes part in a photon's tent if it lies within this fraction of the
cell's longer side (plus 1 mm) of the pixel's tangent plane through the photon: depth jumps and
other surfaces of the same receiver are left out, however deep the tent reaches."""

NEAR_M = 1.0e-3
"""Near plane of the camera for clipping tents [m]."""

MIN_SPLAT_SIGMA = 1.0
"""Narrowest photon splat (Gaussian σ) [pixels]: photons closer than a pixel apart would alias
into stripes with anything narrower."""

MAX_SHAFT_STEPS = 2048
"""Most samples along one photon's light-shaft line."""


@wp.struct
class PinholeCamera:
    position: wp.vec3
    right: wp.vec3
    up: wp.vec3
    forward: wp.vec3
    tan_half_fov: float
    aspect: float
    """Width / height."""
    width: int
    height: int


@wp.func
def pixel_ray(cam: PinholeCamera, i: int, j: int) -> wp.vec3:
    x = 2.0 * (float(i) + 0.5) / float(cam.width) - 1.0
    y = 1.0 - 2.0 * (float(j) + 0.5) / float(cam.height)
    return wp.normalize(
        cam.forward + (x * cam.tan_half_fov * cam.aspect) * cam.right + (y * cam.tan_half_fov) * cam.up
    )


@wp.func
def pixel_solid_angle(cam: PinholeCamera, ray: wp.vec3) -> float:
    side = 2.0 * cam.tan_half_fov / float(cam.height)
    c = wp.dot(ray, cam.forward)
    return side * side * c * c * c


@wp.func
def project(cam: PinholeCamera, x: wp.vec3) -> wp.vec3:
    """(column, row, distance) of point x: continuous pixel coordinates; distance < 0 behind."""
    v = x - cam.position
    z = wp.dot(v, cam.forward)
    if z <= 1.0e-6:
        return wp.vec3(-1.0, -1.0, -1.0)
    px = (wp.dot(v, cam.right) / (z * cam.tan_half_fov * cam.aspect) + 1.0) * 0.5 * float(cam.width)
    py = (1.0 - wp.dot(v, cam.up) / (z * cam.tan_half_fov)) * 0.5 * float(cam.height)
    return wp.vec3(px, py, wp.length(v))


@wp.kernel
def gbuffer(
    cam: PinholeCamera,
    mesh: wp.uint64,
    face_receiver: wp.array[wp.int32],
    position: wp.array2d[wp.vec3],
    normal: wp.array2d[wp.vec3],
    depth: wp.array2d[wp.float32],
    receiver: wp.array2d[wp.int32],
    inv_footprint: wp.array2d[wp.float32],
    depth_slack: wp.array2d[wp.float32],
    rays: wp.array2d[wp.vec3],
):
    """First receiver along each pixel's ray: position, normal facing the camera, distance,
    receiver id (−1 and depth 1e30 for none) and 1 / the pixel's footprint area there [m^-2]; and
    the unit ray itself (what the volume pass marches).
    ``depth_slack``: how much the distance of points on the receiver within the pixel's footprint
    can differ from the centre ray's, 1.5 · r · (pixel angle) · tan(incidence) [m]."""
    j, i = wp.tid()
    ray = pixel_ray(cam, i, j)
    rays[j, i] = ray
    q = wp.mesh_query_ray(mesh, cam.position, ray, 1.0e5)
    if q.result:
        n = q.normal
        if wp.dot(n, ray) > 0.0:
            n = -n
        position[j, i] = cam.position + q.t * ray
        normal[j, i] = n
        depth[j, i] = q.t
        receiver[j, i] = face_receiver[q.face]
        cos_r = wp.max(-wp.dot(n, ray), 0.02)
        inv_footprint[j, i] = cos_r / (q.t * q.t * pixel_solid_angle(cam, ray))
        pixel_angle = 2.0 * cam.tan_half_fov / float(cam.height)
        depth_slack[j, i] = 1.5 * q.t * pixel_angle * wp.sqrt(1.0 - cos_r * cos_r) / cos_r
    else:
        position[j, i] = cam.position + 1.0e5 * ray
        normal[j, i] = -ray
        depth[j, i] = 1.0e30
        receiver[j, i] = -1
        inv_footprint[j, i] = 0.0
        depth_slack[j, i] = 0.0


@wp.func
def same_surface(depth_pixel: float, slack: float, distance: float, tolerance: float) -> bool:
    """A point at ``distance`` from the camera lies on the surface a pixel sees (its depth within
    the relative ``tolerance`` plus the spread of depths over the pixel's footprint)."""
    return wp.abs(depth_pixel - distance) <= tolerance * depth_pixel + slack + 1.0e-3


@wp.func
def unwrap(a: wp.vec3, b: wp.vec3, periodic: int, extent_m: float) -> wp.vec3:
    """b − a, with whole periods removed on a periodic sea (neighbours may be shifted differently)."""
    e = b - a
    if periodic != 0:
        e = e - wp.vec3(extent_m * wp.round(e[0] / extent_m), extent_m * wp.round(e[1] / extent_m), 0.0)
    return e


@wp.func
def grid_neighbour(p: int, along_v: int, step: int, quads: int, s: int, periodic: int) -> int:
    """Index of the photon one grid step (``step`` = ±1) along u (along_v = 0) or v from photon p;
    −1 past a wall."""
    sub = p % (s * s)
    cell = p / (s * s)
    qx = cell % quads
    qy = (cell / quads) % quads
    base = cell - qx - qy * quads  # first cell of this index group
    a = sub % s
    b = sub / s
    if along_v == 0:
        a += step
        if a == s:
            a = 0
            qx += 1
        if a < 0:
            a = s - 1
            qx -= 1
    else:
        b += step
        if b == s:
            b = 0
            qy += 1
        if b < 0:
            b = s - 1
            qy -= 1
    if qx == quads or qy == quads or qx < 0 or qy < 0:
        if periodic == 0:
            return -1
        qx = (qx + quads) % quads
        qy = (qy + quads) % quads
    return (base + qy * quads + qx) * s * s + b * s + a


@wp.func
def lattice_step(
    hit: wp.array[wp.vec3],
    face: wp.array[wp.int32],
    face_receiver: wp.array[wp.int32],
    p: int,
    along_v: int,
    quads: int,
    s: int,
    periodic: int,
    extent_m: float,
):
    """(e, ok): the step from photon p's hit to its next grid neighbour's along u or v, taken
    forwards, or backwards (reversed) where the forward neighbour is missing, lost or on another
    receiver; ok = 0 if neither qualifies."""
    r = face_receiver[face[p]]
    n = grid_neighbour(p, along_v, 1, quads, s, periodic)
    if n >= 0:
        if face[n] >= 0:
            if face_receiver[face[n]] == r:
                return unwrap(hit[p], hit[n], periodic, extent_m), int(1)
    n = grid_neighbour(p, along_v, -1, quads, s, periodic)
    if n >= 0:
        if face[n] >= 0:
            if face_receiver[face[n]] == r:
                return unwrap(hit[n], hit[p], periodic, extent_m), int(1)
    return wp.vec3(0.0), int(0)


@wp.func
def photon_lattice(
    hit: wp.array[wp.vec3],
    face: wp.array[wp.int32],
    face_receiver: wp.array[wp.int32],
    face_normal: wp.array[wp.vec3],
    p: int,
    quads: int,
    s: int,
    periodic: int,
    extent_m: float,
    spacing_m: float,
):
    """(e_u, e_v, ok): photon p's lattice cell on its receiver [m]. ok = 0 (use a Gaussian) where
    no neighbour on the same receiver exists along u or v, or where the cell does not lie in the
    receiver's surface (neighbours across an edge of a box) or is implausibly large."""
    eu, ok_u = lattice_step(hit, face, face_receiver, p, 0, quads, s, periodic, extent_m)
    ev, ok_v = lattice_step(hit, face, face_receiver, p, 1, quads, s, periodic, extent_m)
    if ok_u == 0 or ok_v == 0:
        return eu, ev, int(0)
    normal = wp.cross(eu, ev)
    area = wp.length(normal)
    longest = wp.max(wp.length(eu), wp.length(ev))
    if area <= 1.0e-6 * longest * longest or longest > MAX_CELL_SPACINGS * spacing_m:
        return eu, ev, int(0)
    if wp.abs(wp.dot(normal, face_normal[face[p]])) < MIN_CELL_ALIGNMENT * area:
        return eu, ev, int(0)
    return eu, ev, int(1)


@wp.func
def add_flux(
    caustic: wp.array3d[wp.float32],
    j: int,
    i: int,
    irradiance: float,
    g: int,
    wavelengths_per_group: int,
    sun_irradiance: wp.array[wp.float32],
    attenuation_per_m: wp.array[wp.float32],
    ell: float,
):
    """Add ``irradiance`` (per unit E_sun) × E_sun(λ) e^{-c(λ) ℓ} to pixel (j, i) in each band of
    group g."""
    for jj in range(wavelengths_per_group):
        k = g * wavelengths_per_group + jj
        wp.atomic_add(caustic, k, j, i, irradiance * sun_irradiance[k] * wp.exp(-attenuation_per_m[k] * ell))


@wp.kernel
def splat_photons(
    cam: PinholeCamera,
    hit: wp.array[wp.vec3],
    face: wp.array[wp.int32],
    origin: wp.array[wp.vec3],
    weight: wp.array[wp.float32],
    photons_per_group: int,
    sun_irradiance: wp.array[wp.float32],
    attenuation_per_m: wp.array[wp.float32],
    wavelengths_per_group: int,
    quads: int,
    subdivisions: int,
    periodic: int,
    extent_m: float,
    floor_face_count: int,
    photon_spacing_m: float,
    face_receiver: wp.array[wp.int32],
    face_normal: wp.array[wp.vec3],
    position: wp.array2d[wp.vec3],
    normal: wp.array2d[wp.vec3],
    receiver: wp.array2d[wp.int32],
    depth: wp.array2d[wp.float32],
    inv_footprint: wp.array2d[wp.float32],
    depth_slack: wp.array2d[wp.float32],
    depth_tolerance: float,
    caustic: wp.array3d[wp.float32],
):
    """Splat photon p into the camera caustic map (K, H, W) [W m^-2 nm^-1] over the pixels that see
    the same surface (depth test: occluded photons add nothing). Point size follows the photon's
    spacing on the receiver seen at its distance (de la Fuente 2011 §4.5), from its grid neighbours'
    hits e_u, e_v, so splats shrink in focused light and widen where it spreads:

    - a photon with a neighbour on its receiver along u and along v (forwards, else backwards):
      the tent (bilinear hat) over ±e_u, ±e_v on the receiver, evaluated at each pixel's G-buffer
      point, irradiance ``Φ hat / |e_u × e_v|`` (:func:`splat_tent`). The hats of a regular
      (affine) lattice of photons sum to one at every point, so each pixel samples the
      piecewise-bilinear irradiance the photons imply, however sparse, sheared (grazing light on a
      wall) or dense (sub-pixel detail is then point-sampled, as any rasteriser without
      supersampling does) they are; where the lattice bends (focusing, the half-width quads at a
      pool's walls) the hats sum to one only approximately;
    - a photon without such neighbours (the edge of the lit region, a silhouette): a Gaussian of
      σ = MIN_SPLAT_SIGMA pixels normalised as a density on the receiver,
      ``Φ G_q / Σ_q' G_q' A_q'`` (A: pixel footprint), so its flux is kept.

    On a periodic sea a floor photon is also splatted at its eight copies one period away (the light
    of the neighbouring tiles), so the floor around the patch is lit and the patch edge does not
    show; the depth test drops copies that are not on the floor the camera sees."""
    p, copy = wp.tid()
    f = face[p]
    if f < 0:
        return
    if copy != 4 and (periodic == 0 or f >= floor_face_count):
        return
    x = hit[p] + wp.vec3(float(copy % 3 - 1) * extent_m, float(copy / 3 - 1) * extent_m, 0.0)
    c = project(cam, x)
    ell = wp.length(hit[p] - origin[p])  # the copy's path is the photon's own
    g = p / photons_per_group
    w = weight[p]
    eu, ev, ok = photon_lattice(
        hit, face, face_receiver, face_normal, p, quads, subdivisions, periodic, extent_m, photon_spacing_m
    )
    if ok != 0:
        n_lit = face_normal[f]  # the face's normal on the side the photon came from
        if wp.dot(n_lit, origin[p] - hit[p]) < 0.0:
            n_lit = -n_lit
        splat_tent(
            cam,
            x,
            eu,
            ev,
            n_lit,
            face_receiver[f],
            position,
            normal,
            receiver,
            w,
            g,
            wavelengths_per_group,
            sun_irradiance,
            attenuation_per_m,
            ell,
            caustic,
        )
        return
    ci = int(wp.floor(c[0]))
    cj = int(wp.floor(c[1]))
    if c[2] < 0.0 or ci < 0 or cj < 0 or ci >= cam.width or cj >= cam.height:
        return
    if not same_surface(depth[cj, ci], depth_slack[cj, ci], c[2], depth_tolerance):
        return  # hidden behind something nearer the camera
    r = wp.min(int(wp.ceil(2.0 * MIN_SPLAT_SIGMA)), MAX_SPLAT_RADIUS)
    total = float(0.0)
    for dj in range(-r, r + 1):
        for di in range(-r, r + 1):
            g_q = gaussian_on_surface(cam, depth, depth_slack, depth_tolerance, c, ci + di, cj + dj)
            if g_q > 0.0:
                total += g_q / inv_footprint[cj + dj, ci + di]
    if total <= 0.0:
        return
    for dj in range(-r, r + 1):
        for di in range(-r, r + 1):
            g_q = gaussian_on_surface(cam, depth, depth_slack, depth_tolerance, c, ci + di, cj + dj)
            if g_q > 0.0:
                add_flux(
                    caustic,
                    cj + dj,
                    ci + di,
                    w * g_q / total,
                    g,
                    wavelengths_per_group,
                    sun_irradiance,
                    attenuation_per_m,
                    ell,
                )


@wp.func
def tent_corner(x: wp.vec3, eu: wp.vec3, ev: wp.vec3, k: int) -> wp.vec3:
    """Corner k (0…3, in order round the parallelogram) of a tent's support x ± e_u ± e_v."""
    su = float(1)
    sv = float(1)
    if k == 0 or k == 3:
        su = -1.0
    if k < 2:
        sv = -1.0
    return x + su * eu + sv * ev


@wp.func
def splat_tent(
    cam: PinholeCamera,
    x: wp.vec3,
    eu: wp.vec3,
    ev: wp.vec3,
    n_lit: wp.vec3,
    rid: int,
    position: wp.array2d[wp.vec3],
    normal: wp.array2d[wp.vec3],
    receiver: wp.array2d[wp.int32],
    w: float,
    g: int,
    wavelengths_per_group: int,
    sun_irradiance: wp.array[wp.float32],
    attenuation_per_m: wp.array[wp.float32],
    ell: float,
    caustic: wp.array3d[wp.float32],
):
    """Add the tent of a photon at x with lattice cell (e_u, e_v) to every pixel whose G-buffer
    point lies in its support: same receiver, its lit side (``n_lit``, the face normal towards the
    light, within 60° of the pixel's normal: the back of a one-sided plate or a slab's shaded
    underside stays dark), on the pixel's tangent plane through x within TENT_PLANE_TOLERANCE plus
    the curvature between the two normals, and (X − x) = α e_u + β e_v (least squares) with
    |α|, |β| < 1; irradiance ``w hat / |e_u × e_v|``.

    The pixels searched are the screen box of the support x ± e_u ± e_v clipped by the camera's
    near plane, then by the frame, so photons just outside the frame, or right at the lens, still
    light what they should."""
    # Screen box of the support clipped by the near plane: the corners in front of it and the
    # points where the support's edges cross it (points just in front project far off-screen, so
    # the box opens only towards the side that reaches behind the camera).
    lo = wp.vec2(1.0e30, 1.0e30)
    hi = wp.vec2(-1.0e30, -1.0e30)
    seen = int(0)
    for k in range(4):
        c0 = tent_corner(x, eu, ev, k)
        c1 = tent_corner(x, eu, ev, (k + 1) % 4)
        d0 = wp.dot(c0 - cam.position, cam.forward) - NEAR_M
        d1 = wp.dot(c1 - cam.position, cam.forward) - NEAR_M
        if d0 > 0.0:
            q = project(cam, c0)
            lo = wp.vec2(wp.min(lo[0], q[0]), wp.min(lo[1], q[1]))
            hi = wp.vec2(wp.max(hi[0], q[0]), wp.max(hi[1], q[1]))
            seen = 1
        if d0 * d1 < 0.0:
            q = project(cam, c0 + (d0 / (d0 - d1)) * (c1 - c0))
            lo = wp.vec2(wp.min(lo[0], q[0]), wp.min(lo[1], q[1]))
            hi = wp.vec2(wp.max(hi[0], q[0]), wp.max(hi[1], q[1]))
            seen = 1
    if seen == 0:
        return  # wholly behind the camera
    i0 = wp.max(int(wp.floor(lo[0])), 0)
    j0 = wp.max(int(wp.floor(lo[1])), 0)
    i1 = wp.min(int(wp.floor(hi[0])), cam.width - 1)
    j1 = wp.min(int(wp.floor(hi[1])), cam.height - 1)
    a = wp.dot(eu, eu)
    b = wp.dot(eu, ev)
    d = wp.dot(ev, ev)
    det = a * d - b * b
    area = wp.length(wp.cross(eu, ev))
    tolerance = TENT_PLANE_TOLERANCE * wp.sqrt(wp.max(a, d)) + 1.0e-3
    for j in range(j0, j1 + 1):
        for i in range(i0, i1 + 1):
            if receiver[j, i] == rid:
                q = position[j, i] - x
                n_px = normal[j, i]
                # The pixel must see the lit side, near the tangent plane through x (allowing for
                # the surface's curvature: the normals' difference grows with it).
                bend = 0.5 * wp.length(q) * wp.length(n_px - n_lit)
                if wp.dot(n_px, n_lit) >= 0.5 and wp.abs(wp.dot(q, n_px)) <= tolerance + bend:
                    pu = wp.dot(q, eu)
                    pv = wp.dot(q, ev)
                    alpha = (d * pu - b * pv) / det
                    beta = (a * pv - b * pu) / det
                    hat = wp.max(1.0 - wp.abs(alpha), 0.0) * wp.max(1.0 - wp.abs(beta), 0.0)
                    if hat > 0.0:
                        add_flux(
                            caustic,
                            j,
                            i,
                            w * hat / area,
                            g,
                            wavelengths_per_group,
                            sun_irradiance,
                            attenuation_per_m,
                            ell,
                        )


@wp.func
def gaussian_on_surface(
    cam: PinholeCamera,
    depth: wp.array2d[wp.float32],
    depth_slack: wp.array2d[wp.float32],
    depth_tolerance: float,
    c: wp.vec3,
    i: int,
    j: int,
) -> float:
    """Weight of pixel (j, i) in a Gaussian splat (σ = MIN_SPLAT_SIGMA) centred at the projected
    point c; 0 outside the image or where the pixel sees another surface."""
    if i < 0 or j < 0 or i >= cam.width or j >= cam.height:
        return 0.0
    if not same_surface(depth[j, i], depth_slack[j, i], c[2], depth_tolerance):
        return 0.0
    dx = float(i) + 0.5 - c[0]
    dy = float(j) + 0.5 - c[1]
    return wp.exp(-(dx * dx + dy * dy) * (0.5 / (MIN_SPLAT_SIGMA * MIN_SPLAT_SIGMA)))


SHAFT_LEVELS = 7
"""Levels of the shaft pyramid: level l has pixels 2^l fine pixels wide."""


@wp.func
def level_size(n: int, level: int) -> int:
    """Pixels along one side of level ``level`` of an n-pixel side: ceil(n / 2^level)."""
    return (n + (1 << level) - 1) >> level


@wp.func
def level_offset(width: int, height: int, level: int) -> int:
    """Start of level ``level`` in the packed pyramid (levels stored one after the other)."""
    offset = int(0)
    for l in range(level):
        offset += level_size(width, l) * level_size(height, l)
    return offset


@wp.kernel
def shaft_lines(
    cam: PinholeCamera,
    hit: wp.array[wp.vec3],
    face: wp.array[wp.int32],
    origin: wp.array[wp.vec3],
    direction: wp.array[wp.vec3],
    weight: wp.array[wp.float32],
    stride: int,
    tube_width_m: float,
    periodic: int,
    extent_m: float,
    floor_face_count: int,
    photons_per_group: int,
    sun_irradiance: wp.array[wp.float32],
    attenuation_per_m: wp.array[wp.float32],
    scattering_per_m: wp.array[wp.float32],
    wavelengths_per_group: int,
    phase_kind: int,
    hg_g: float,
    angles_rad: wp.array[wp.float32],
    log_phase: wp.array[wp.float32],
    cone_phase: float,
    depth: wp.array2d[wp.float32],
    pyramid: wp.array2d[wp.float32],
):
    """Light shafts (de la Fuente 2011 §4.6; Papadopoulos & Papaioannou 2009): photon ``i·stride``
    stands for ``stride`` photons and its path from the surface to its receiver is a line of
    scattering sources. A step dℓ at ℓ from the surface and s from the camera adds
    ``Φ(λ) σ_s(λ) p(cosθ) e^{−c(ℓ+s)} dℓ / (s² Ω)`` to the radiance of the pixel it falls in
    [W m^-2 sr^-1 nm^-1], unless the G-buffer says a receiver hides it.

    The line stands for a tube ``tube_width_m`` across. Where the tube looks wider than a pixel
    (near the camera), the step goes into the level of a pixel pyramid (``pyramid``: (K, packed
    levels)) whose pixels are at least as wide as the tube, Ω being that coarse pixel's solid angle;
    :func:`collapse_pyramid` adds the levels back up, so near lines neither streak nor spike.

    On a periodic sea the lines of floor photons are also drawn at their eight copies one period
    away, so the water beyond the patch holds light shafts too (``copy`` 4 is the line itself).
    """
    t, copy = wp.tid()
    p = t * stride
    f = face[p]
    if f < 0:
        return
    if copy != 4 and (periodic == 0 or f >= floor_face_count):
        return
    shift = wp.vec3(float(copy % 3 - 1) * extent_m, float(copy / 3 - 1) * extent_m, 0.0)
    o = origin[p] + shift
    x1 = hit[p] + shift
    d = direction[p]
    length = wp.length(x1 - o)
    a = project(cam, o)
    b = project(cam, x1)
    if a[2] <= 0.0 and b[2] <= 0.0:
        return  # wholly behind the camera
    if a[2] > 0.0 and b[2] > 0.0:  # a line wholly off one side of the frame adds nothing
        w_px = float(cam.width)
        h_px = float(cam.height)
        if (a[0] < 0.0 and b[0] < 0.0) or (a[0] > w_px and b[0] > w_px):
            return
        if (a[1] < 0.0 and b[1] < 0.0) or (a[1] > h_px and b[1] > h_px):
            return
    pixels = float(MAX_SHAFT_STEPS)
    if a[2] > 0.0 and b[2] > 0.0:
        pixels = wp.length(wp.vec2(b[0] - a[0], b[1] - a[1]))
    steps = wp.clamp(int(wp.ceil(2.0 * pixels)) + 1, 1, MAX_SHAFT_STEPS)
    dl = length / float(steps)
    g = p / photons_per_group
    w = weight[p] * float(stride) * dl
    angle = 2.0 * cam.tan_half_fov / float(cam.height)
    for step in range(steps):
        ell = (float(step) + 0.5) * dl
        x = o + ell * d
        c = project(cam, x)
        if c[2] > 0.0:
            i = int(wp.floor(c[0]))
            j = int(wp.floor(c[1]))
            if in_front(depth, i, j, c[2]):
                s = c[2]
                to_cam = (cam.position - x) / s
                cos_theta = wp.dot(d, to_cam)
                phase = phase_value(phase_kind, hg_g, angles_rad, log_phase, cone_phase, cos_theta)
                level = int(0)
                tube_pixels = tube_width_m / (s * angle)
                while level < SHAFT_LEVELS - 1 and float(1 << level) < tube_pixels:
                    level += 1
                scale = float(1 << level)
                geometry = w * phase / (s * s * pixel_solid_angle(cam, -to_cam) * scale * scale)
                index = (
                    level_offset(cam.width, cam.height, level)
                    + (j >> level) * level_size(cam.width, level)
                    + (i >> level)
                )
                for jj in range(wavelengths_per_group):
                    k = g * wavelengths_per_group + jj
                    wp.atomic_add(
                        pyramid,
                        k,
                        index,
                        geometry
                        * sun_irradiance[k]
                        * scattering_per_m[k]
                        * wp.exp(-attenuation_per_m[k] * (ell + s)),
                    )


@wp.func
def in_front(depth: wp.array2d[wp.float32], i: int, j: int, s: float) -> bool:
    """Pixel (j, i) exists and its receiver lies beyond distance s."""
    if i < 0 or j < 0 or i >= depth.shape[1] or j >= depth.shape[0]:
        return False
    return s < depth[j, i]


@wp.kernel
def collapse_pyramid(pyramid: wp.array2d[wp.float32], shafts: wp.array3d[wp.float32]):
    """shafts[k, j, i] = Σ_l level l bilinearly interpolated at the pixel's centre (coarse pixels
    hold mean radiance over their block, so every level adds radiance, not flux)."""
    k, j, i = wp.tid()
    height = shafts.shape[1]
    width = shafts.shape[2]
    total = float(0.0)
    for level in range(SHAFT_LEVELS):
        w = level_size(width, level)
        h = level_size(height, level)
        offset = level_offset(width, height, level)
        scale = 1.0 / float(1 << level)
        u = (float(i) + 0.5) * scale - 0.5
        v = (float(j) + 0.5) * scale - 0.5
        i0 = wp.clamp(int(wp.floor(u)), 0, w - 1)
        j0 = wp.clamp(int(wp.floor(v)), 0, h - 1)
        i1 = wp.min(i0 + 1, w - 1)
        j1 = wp.min(j0 + 1, h - 1)
        tu = wp.clamp(u - float(i0), 0.0, 1.0)
        tv = wp.clamp(v - float(j0), 0.0, 1.0)
        total += (1.0 - tv) * (
            (1.0 - tu) * pyramid[k, offset + j0 * w + i0] + tu * pyramid[k, offset + j0 * w + i1]
        ) + tv * ((1.0 - tu) * pyramid[k, offset + j1 * w + i0] + tu * pyramid[k, offset + j1 * w + i1])
    shafts[k, j, i] = total


@wp.kernel
def blur3(src: wp.array3d[wp.float32], dst: wp.array3d[wp.float32]):
    """3×3 binomial filter [1 2 1]ᵀ[1 2 1]/16 per band, edges renormalised (flux kept)."""
    k, j, i = wp.tid()
    h = src.shape[1]
    w = src.shape[2]
    total = float(0.0)
    norm = float(0.0)
    for dj in range(-1, 2):
        for di in range(-1, 2):
            jj = j + dj
            ii = i + di
            if jj >= 0 and ii >= 0 and jj < h and ii < w:
                wgt = float((2 - wp.abs(dj)) * (2 - wp.abs(di)))
                total += wgt * src[k, jj, ii]
                norm += wgt
    dst[k, j, i] = total / norm


@wp.kernel
def shade(
    receiver: wp.array2d[wp.int32],
    depth: wp.array2d[wp.float32],
    caustic: wp.array3d[wp.float32],
    shafts: wp.array3d[wp.float32],
    albedo: wp.array2d[wp.float32],
    attenuation_per_m: wp.array[wp.float32],
    radiance: wp.array3d[wp.float32],
):
    """Radiance at the camera: a Lambertian receiver's ``albedo · E / π`` attenuated over the
    distance to the camera, plus the light shafts in front of it."""
    k, j, i = wp.tid()
    value = shafts[k, j, i]
    r = receiver[j, i]
    if r >= 0:
        value += albedo[r, k] * caustic[k, j, i] * INV_PI * wp.exp(-attenuation_per_m[k] * depth[j, i])
    radiance[k, j, i] = value
