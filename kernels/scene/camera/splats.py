"""Photon splats into the camera's caustic map (de la Fuente 2011 §4.5): the tent over a photon's
lattice cell on its receiver, or a Gaussian where it has none.
"""

import warp as wp

from warpcaustics.kernels.caustics.photon_lattice import photon_lattice
from warpcaustics.kernels.caustics.photons import Photons
from warpcaustics.kernels.scene.camera.pinhole import PinholeCamera, project

wp.set_module_options({"enable_backward": False})

MAX_SPLAT_RADIUS = 8
"""Largest photon splat radius [pixels]."""

TENT_PLANE_TOLERANCE = 0.1
"""A pixel's G-buffer point takes part in a photon's tent if it lies within this fraction of the
cell's longer side (plus 1 mm) of the pixel's tangent plane through the photon: depth jumps and
other surfaces of the same receiver are left out, however deep the tent reaches."""

NEAR_M = 1.0e-3
"""Near plane of the camera for clipping tents [m]."""

MIN_SPLAT_SIGMA = 1.0
"""Narrowest photon splat (Gaussian σ) [pixels]: photons closer than a pixel apart would alias
into stripes with anything narrower."""


@wp.func
def same_surface(depth_pixel: float, slack: float, distance: float, tolerance: float) -> bool:
    """A point at ``distance`` from the camera lies on the surface a pixel sees (its depth within
    the relative ``tolerance`` plus the spread of depths over the pixel's footprint)."""
    return wp.abs(depth_pixel - distance) <= tolerance * depth_pixel + slack + 1.0e-3


@wp.func
def add_flux(
    caustic: wp.array3d[wp.float32], j: int, i: int, irradiance: float, ph: Photons, g: int, ell: float
):
    """Add ``irradiance`` (per unit E_sun) × E_sun(λ) e^{-c(λ) ℓ} to pixel (j, i) in each band of
    group g."""
    for jj in range(ph.wavelengths_per_group):
        k = g * ph.wavelengths_per_group + jj
        attenuation = wp.exp(-ph.attenuation_per_m[k] * ell)
        wp.atomic_add(caustic, k, j, i, irradiance * ph.sun_irradiance[k] * attenuation)


@wp.kernel
def splat_photons(
    cam: PinholeCamera,
    ph: Photons,
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
    f = ph.face[p]
    if f < 0:
        return
    extent_m = ph.extent_m
    if copy != 4 and (ph.periodic == 0 or f >= ph.floor_face_count):
        return
    x = ph.hit[p] + wp.vec3(float(copy % 3 - 1) * extent_m, float(copy / 3 - 1) * extent_m, 0.0)
    c = project(cam, x)
    ell = ph.path_before[p] + wp.length(ph.hit[p] - ph.origin[p])  # the copy's path is the photon's own
    g = p / ph.photons_per_group
    w = ph.weight[p]
    eu, ev, ok = photon_lattice(
        ph.hit, ph.face, face_receiver, face_normal, p, ph.quads, ph.subdivisions, ph.periodic, extent_m,
        photon_spacing_m,
    )
    if ok != 0:
        n_lit = face_normal[f]  # the face's normal on the side the photon came from
        if wp.dot(n_lit, ph.origin[p] - ph.hit[p]) < 0.0:
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
            ph,
            g,
            ell,
            caustic,
        )
        return
    splat_gaussian(
        cam,
        c,
        depth,
        depth_slack,
        depth_tolerance,
        inv_footprint,
        w,
        ph,
        g,
        ell,
        caustic,
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
    ph: Photons,
    g: int,
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
                        add_flux(caustic, j, i, w * hat / area, ph, g, ell)


@wp.func
def splat_gaussian(
    cam: PinholeCamera,
    c: wp.vec3,
    depth: wp.array2d[wp.float32],
    depth_slack: wp.array2d[wp.float32],
    depth_tolerance: float,
    inv_footprint: wp.array2d[wp.float32],
    w: float,
    ph: Photons,
    g: int,
    ell: float,
    caustic: wp.array3d[wp.float32],
):
    """Add a photon projected at c (column, row, distance) as a Gaussian of σ = MIN_SPLAT_SIGMA
    pixels over the pixels that see its surface, normalised as a density on the receiver
    (``Φ G_q / Σ_q' G_q' A_q'``, A: pixel footprint) so that its flux is kept."""
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
                add_flux(caustic, cj + dj, ci + di, w * g_q / total, ph, g, ell)


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
