"""Light shafts (de la Fuente 2011 §4.6): photon paths as lines of scattering sources drawn into a
pixel pyramid, the pyramid collapsed, and a 3×3 blur.
"""

import warp as wp

from warpcaustics.kernels.caustics.photons import Photons
from warpcaustics.kernels.optics.phase import phase_value
from warpcaustics.kernels.scene.camera.pinhole import PinholeCamera, pixel_solid_angle, project

wp.set_module_options({"enable_backward": False})

MAX_SHAFT_STEPS = 2048
"""Most samples along one photon's light-shaft line."""

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
    ph: Photons,
    stride: int,
    tube_width_m: float,
    scattering_per_m: wp.array[wp.float32],
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
    f = ph.face[p]
    if f < 0:
        return
    if copy != 4 and (ph.periodic == 0 or f >= ph.floor_face_count):
        return
    extent_m = ph.extent_m
    shift = wp.vec3(float(copy % 3 - 1) * extent_m, float(copy / 3 - 1) * extent_m, 0.0)
    o = ph.origin[p] + shift
    x1 = ph.hit[p] + shift
    d = ph.direction[p]
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
    g = p / ph.photons_per_group
    w = ph.weight[p] * float(stride) * dl
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
                for jj in range(ph.wavelengths_per_group):
                    k = g * ph.wavelengths_per_group + jj
                    wp.atomic_add(
                        pyramid,
                        k,
                        index,
                        geometry
                        * ph.sun_irradiance[k]
                        * scattering_per_m[k]
                        * wp.exp(-ph.attenuation_per_m[k] * (ph.path_before[p] + ell + s)),
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
