"""Photon splatting (caustics mapping, Shah et al. 2007; de la Fuente 2011 §4.5).

A regular grid of s×s photons per surface cell leaves the bilinearly interpolated, displaced
water surface, refracts (Snell + exact Fresnel), and finds the receiver it lands on either
exactly (a ray query on the receivers' BVH) or by Shah's iteration on a receiver-position buffer
rendered from the light: ``t ← |R(o + t d) − o|``, where R(x) is the receiver position the light
sees through x. Photons are stored flat, index ``((g Q + qy) Q + qx) s² + sub``.

A photon carries ``weight = A⊥ · T`` [m²]: the area of its share of the cell projected
perpendicular to the sun times its Fresnel transmittance (and sun visibility); its flux in band
k is ``weight · E_sun(k) · exp(−c(k) ℓ)``, ℓ its path in water.
"""

import warp as wp

from warpcaustics.kernels.caustics.bounces import (
    BEYOND_LIMIT_END,
    LANDED,
    MAX_OBJECT_BOUNCES,
    TRAPPED_END,
    Optics,
    follow_bounces,
)
from warpcaustics.kernels.caustics.bounces import MISSED as MISSED_END
from warpcaustics.kernels.caustics.fluxratio import grid_corner, lift, texel_of
from warpcaustics.kernels.geometry import bilerp, sun_into_water

wp.set_module_options({"enable_backward": False})

RAY_LENGTH_M = 1.0e5
"""Longest ray queried on the BVH [m]."""

MAX_BLEND_DEPTH_TEXELS = 8.0
"""Light-view texels are blended only if their depths along the view differ by less than this many
texel widths (a surface inclined up to ~83° to the view); beyond, the nearest texel is used."""


@wp.struct
class LightView:
    """Orthographic view from the light onto the receivers (Shah's receiver-position buffer),
    along the sun's refracted direction under still water (``u × v``, pointing up).

    Texel (i, j) looks along −(u × v) through ``origin + (i + ½) texel u + (j + ½) texel v``.
    """

    origin: wp.vec3
    u: wp.vec3
    v: wp.vec3
    texel_m: float
    positions: wp.array2d[wp.vec3]
    faces: wp.array2d[wp.int32]


@wp.func
def bilinear_vec3(a: wp.vec3, b: wp.vec3, c: wp.vec3, d: wp.vec3, tu: float, tv: float) -> wp.vec3:
    """(1-tv)((1-tu) a + tu b) + tv((1-tu) c + tu d): a, b at v = 0; c, d at v = 1."""
    return (1.0 - tv) * ((1.0 - tu) * a + tu * b) + tv * ((1.0 - tu) * c + tu * d)


MAX_WALLS_PASSED = 2
"""Walls a light-view ray may pass from outside: two where it crosses a pool's corner."""
WALL_PASS_M = 1.0e-4
"""How far past a wall hit from outside a light-view ray starts again [m]."""


@wp.func
def wall_from_outside(q: wp.MeshQueryRay, face_receiver: wp.array[wp.int32], walls_id: int) -> bool:
    """Whether ray query ``q`` hit a pool's wall from outside (its faces face inwards)."""
    return q.result and face_receiver[q.face] == walls_id and q.sign < 0.0


@wp.kernel
def render_light_view(
    mesh: wp.uint64,
    face_receiver: wp.array[wp.int32],
    walls_id: int,
    view_dir: wp.vec3,
    distance_m: float,
    view: LightView,
):
    """Fill the light view: the first receiver point seen along −``view_dir`` through each texel
    (face −1: none). ``view_dir`` is the sun's direction under still water. A pool's walls are
    seen only from inside (their faces face inwards): light enters the pool through the water, so a
    wall hit from outside is passed through. Without that the walls, which stand above the water,
    would hide the floor and the far wall that the refracted light reaches."""
    j, i = wp.tid()
    centre = (
        view.origin + ((float(i) + 0.5) * view.texel_m) * view.u + ((float(j) + 0.5) * view.texel_m) * view.v
    )
    start = centre + distance_m * view_dir
    q = wp.mesh_query_ray(mesh, start, -view_dir, RAY_LENGTH_M)
    for _wall in range(MAX_WALLS_PASSED):
        if not wall_from_outside(q, face_receiver, walls_id):
            break
        start = start - (q.t + WALL_PASS_M) * view_dir
        q = wp.mesh_query_ray(mesh, start, -view_dir, RAY_LENGTH_M)
    if q.result and not wall_from_outside(q, face_receiver, walls_id):
        view.positions[j, i] = start - q.t * view_dir
        view.faces[j, i] = q.face
    else:
        view.positions[j, i] = centre
        view.faces[j, i] = -1


@wp.func
def look_up(view: LightView, face_receiver: wp.array[wp.int32], x: wp.vec3):
    """The receiver point R(x) the light view sees through x and its face (−1 outside the view).

    R is interpolated bilinearly between texel centres when the four texels around x show the same
    receiver (exact on planes, smooth on curved receivers), else taken from the nearest texel
    (silhouettes: no blending of unrelated surfaces)."""
    a = wp.dot(x - view.origin, view.u) / view.texel_m
    b = wp.dot(x - view.origin, view.v) / view.texel_m
    res = view.positions.shape[0]
    if a < 0.0 or b < 0.0 or a >= float(res) or b >= float(res):
        return wp.vec3(0.0), int(-1)
    i = int(a)
    j = int(b)
    f = view.faces[j, i]
    if f < 0:
        return view.positions[j, i], f
    fa = a - 0.5
    fb = b - 0.5
    i0 = int(wp.floor(fa))
    j0 = int(wp.floor(fb))
    if i0 < 0 or j0 < 0 or i0 + 1 >= res or j0 + 1 >= res:
        return view.positions[j, i], f
    r = face_receiver[f]
    f00 = view.faces[j0, i0]
    f10 = view.faces[j0, i0 + 1]
    f01 = view.faces[j0 + 1, i0]
    f11 = view.faces[j0 + 1, i0 + 1]
    if f00 < 0 or f10 < 0 or f01 < 0 or f11 < 0:
        return view.positions[j, i], f
    if (
        face_receiver[f00] != r
        or face_receiver[f10] != r
        or face_receiver[f01] != r
        or face_receiver[f11] != r
    ):
        return view.positions[j, i], f
    p00 = view.positions[j0, i0]
    p10 = view.positions[j0, i0 + 1]
    p01 = view.positions[j0 + 1, i0]
    p11 = view.positions[j0 + 1, i0 + 1]
    # A depth jump (part of a mesh hiding another part from the light) must not be blended across.
    s = wp.cross(view.u, view.v)
    d0 = wp.dot(p00, s)
    jump = wp.max(wp.abs(wp.dot(p10, s) - d0), wp.abs(wp.dot(p01, s) - d0))
    jump = wp.max(jump, wp.abs(wp.dot(p11, s) - d0))
    if jump > MAX_BLEND_DEPTH_TEXELS * view.texel_m:
        return view.positions[j, i], f
    return bilinear_vec3(p00, p10, p01, p11, fa - float(i0), fb - float(j0)), f


@wp.func
def newton_hit(
    view: LightView,
    face_receiver: wp.array[wp.int32],
    o: wp.vec3,
    d: wp.vec3,
    plane_z: float,
    iterations: int,
):
    """Shah's iteration for the ray o + t d: returns (t, face) with face −1 if the ray left the
    light view. Starts where the ray meets the plane z = plane_z (the floor at rest)."""
    t = (plane_z - o[2]) / d[2]
    r = wp.vec3(0.0)
    f = int(-1)
    for _it in range(iterations):
        r, f = look_up(view, face_receiver, o + t * d)
        if f < 0:
            return t, f
        t = wp.length(r - o)
    r, f = look_up(view, face_receiver, o + t * d)
    return t, f


@wp.kernel
def emit_photons(
    positions: wp.array2d[wp.vec3],
    normals: wp.array2d[wp.vec3],
    visible: wp.array2d[wp.float32],
    ior: wp.array[wp.float32],
    sun_dir: wp.vec3,
    subdivisions: int,
    extent_m: float,
    periodic: int,
    origin: wp.array[wp.vec3],
    direction: wp.array[wp.vec3],
    weight: wp.array[wp.float32],
):
    """Photon (g, qy, qx, sub): its start on the bilinear surface patch of quad (qx, qy), its
    refracted direction for index group g and its weight A⊥·T [m²] (0 if lit from behind, on
    total internal reflection or if it would not descend). ``sun_dir`` is the pass's direction
    towards the light (the renderer runs a pass per direction of the sun's disk or of the sky)."""
    g, qy, qx, sub = wp.tid()
    n = positions.shape[0]
    quads = positions.shape[0] + 1 - periodic
    s = subdivisions
    tu = (float(sub % s) + 0.5) / float(s)
    tv = (float(sub / s) + 0.5) / float(s)
    x00, y00, h00 = grid_corner(qx, qy, 0, 0, n, extent_m, periodic)
    x10, y10, h10 = grid_corner(qx, qy, 1, 0, n, extent_m, periodic)
    x01, y01, h01 = grid_corner(qx, qy, 0, 1, n, extent_m, periodic)
    x11, y11, h11 = grid_corner(qx, qy, 1, 1, n, extent_m, periodic)
    p00 = lift(positions[y00, x00], h00)
    p10 = lift(positions[y10, x10], h10)
    p01 = lift(positions[y01, x01], h01)
    p11 = lift(positions[y11, x11], h11)
    p = bilinear_vec3(p00, p10, p01, p11, tu, tv)
    dp_du = (1.0 - tv) * (p10 - p00) + tv * (p11 - p01)
    dp_dv = (1.0 - tu) * (p01 - p00) + tu * (p11 - p10)
    a_perp = wp.max(wp.dot(wp.cross(dp_du, dp_dv), sun_dir), 0.0) / float(s * s)
    normal = wp.normalize(
        bilinear_vec3(normals[y00, x00], normals[y10, x10], normals[y01, x01], normals[y11, x11], tu, tv)
    )
    seen = bilerp(visible[y00, x00], visible[y10, x10], visible[y01, x01], visible[y11, x11], tu, tv)
    d, transmitted = sun_into_water(normal, sun_dir, 1.0 / ior[g])
    w = a_perp * transmitted * seen
    i = ((g * quads + qy) * quads + qx) * s * s + sub
    origin[i] = p
    direction[i] = d
    weight[i] = w


@wp.func
def periodic_start(o: wp.vec3, d: wp.vec3, extent_m: float, plane_z: float) -> wp.vec3:
    """Shift a periodic sea's photon start by whole periods so that the photon, followed to the
    plane z = plane_z, lands inside the patch (the light of the neighbouring tiles)."""
    t = (plane_z - o[2]) / d[2]
    x = o[0] + t * d[0]
    y = o[1] + t * d[1]
    return o - wp.vec3(extent_m * wp.floor(x / extent_m + 0.5), extent_m * wp.floor(y / extent_m + 0.5), 0.0)


@wp.kernel
def trace_photons(
    mesh: wp.uint64,
    view: LightView,
    face_receiver: wp.array[wp.int32],
    newton_iterations: int,
    extent_m: float,
    periodic: int,
    plane_z: float,
    origin: wp.array[wp.vec3],
    direction: wp.array[wp.vec3],
    weight: wp.array[wp.float32],
    hit: wp.array[wp.vec3],
    face: wp.array[wp.int32],
):
    """Where photon i lands: exactly on the BVH (``newton_iterations < 0``) or by Shah's
    iteration on the light view. Photons with weight 0 or that find no receiver get face −1.

    On a periodic sea the start is first moved by whole periods (see :func:`periodic_start`);
    ``origin`` is updated so that light shafts are drawn from where the photon really started.
    """
    i = wp.tid()
    face[i] = -1
    if weight[i] <= 0.0:
        return
    o = origin[i]
    d = direction[i]
    if periodic != 0:
        o = periodic_start(o, d, extent_m, plane_z)
        origin[i] = o
    if newton_iterations < 0:
        q = wp.mesh_query_ray(mesh, o, d, RAY_LENGTH_M)
        if q.result:
            hit[i] = o + q.t * d
            face[i] = q.face
    else:
        t, f = newton_hit(view, face_receiver, o, d, plane_z, newton_iterations)
        hit[i] = o + t * d
        face[i] = f


@wp.struct
class Photons:
    """A pass's traced photons as the deposit and the camera read them: each photon's ``origin`` on
    the surface, ``direction``, ``hit`` and receiver ``face`` (−1: none) and flux weight A⊥·T
    [m²]; ``photons_per_group`` per index group, each group ``wavelengths_per_group`` bands of
    ``sun_irradiance`` and ``attenuation_per_m``; the emission lattice (``quads`` per side,
    ``subdivisions``² photons a quad) on the patch ``extent_m`` (``periodic``: the sea repeats),
    and the receivers' first ``floor_face_count`` faces being the floor's."""

    hit: wp.array[wp.vec3]
    face: wp.array[wp.int32]
    origin: wp.array[wp.vec3]
    direction: wp.array[wp.vec3]
    weight: wp.array[wp.float32]
    path_before: wp.array[wp.float32]
    """Water path before ``origin`` [m]: 0, or the path to the last bounce (``caustics.bounces``)."""
    photons_per_group: int
    wavelengths_per_group: int
    sun_irradiance: wp.array[wp.float32]
    attenuation_per_m: wp.array[wp.float32]
    quads: int
    subdivisions: int
    extent_m: float
    periodic: int
    floor_face_count: int


@wp.kernel
def deposit_photons(
    ph: Photons,
    floor_inv_area: wp.array2d[wp.float32],
    splatted: wp.array[wp.int32],
    floor_texels: wp.array3d[wp.float32],
    face_flux: wp.array2d[wp.float32],
):
    """Add photon i's flux to the floor map texel under its hit (divided by that texel's true
    floor area: irradiance) or, for other receivers, to its face's flux (F_other, K) [W nm^-1].
    Photons with ``splatted[i]`` = 1 were spread over their footprint already."""
    i = wp.tid()
    f = ph.face[i]
    if f < 0 or splatted[i] != 0:
        return
    g = i / ph.photons_per_group
    p = ph.hit[i]
    ell = ph.path_before[i] + wp.length(p - ph.origin[i])
    w = ph.weight[i]
    k0 = g * ph.wavelengths_per_group
    extent_m = ph.extent_m
    if f < ph.floor_face_count:
        m = floor_texels.shape[0]
        tx = texel_of((p[0] + 0.5 * extent_m) * float(m) / extent_m, m, ph.periodic)
        ty = texel_of((p[1] + 0.5 * extent_m) * float(m) / extent_m, m, ph.periodic)
        if tx < 0 or ty < 0:
            return
        scale = w * floor_inv_area[ty, tx]
        for j in range(ph.wavelengths_per_group):
            k = k0 + j
            wp.atomic_add(
                floor_texels, ty, tx, k, scale * ph.sun_irradiance[k] * wp.exp(-ph.attenuation_per_m[k] * ell)
            )
    else:
        for j in range(ph.wavelengths_per_group):
            k = k0 + j
            wp.atomic_add(
                face_flux,
                f - ph.floor_face_count,
                k,
                w * ph.sun_irradiance[k] * wp.exp(-ph.attenuation_per_m[k] * ell),
            )


# --- several bounces (caustics.bounces > 1): light through glass receivers, off mirrors ----------

REFLECTED = wp.constant(0)
"""Tally rows: light reflected at a glass receiver's faces (Fresnel), which the deterministic
photon leaves behind,"""
BEYOND_LIMIT = wp.constant(1)
"""light that meets a glass or specular receiver after its last allowed bounce,"""
TRAPPED = wp.constant(2)
"""light still inside a glass receiver after MAX_INTERNAL_REFLECTIONS total internal reflections,"""
MISSED = wp.constant(3)
"""and light that meets no receiver after a bounce."""
TALLIES = 4


@wp.func
def tally(tallies: wp.array2d[wp.float64], row: int, w: float, ph_e: wp.array[wp.float32],
          attenuation: wp.array[wp.float32], k0: int, bands: int, path: float):
    """tallies[row, k] += w E(k) e^{−c(k) path} for the photon's bands."""
    for j in range(bands):
        k = k0 + j
        wp.atomic_add(tallies, row, k, wp.float64(w * ph_e[k] * wp.exp(-attenuation[k] * path)))


@wp.kernel
def trace_bounces(
    mesh: wp.uint64,
    face_receiver: wp.array[wp.int32],
    optics: Optics,
    extent_m: float,
    periodic: int,
    plane_z: float,
    sun_irradiance: wp.array[wp.float32],
    attenuation: wp.array[wp.float32],
    photons_per_group: int,
    bands_per_group: int,
    origin: wp.array[wp.vec3],
    direction: wp.array[wp.vec3],
    weight: wp.array[wp.float32],
    carried: wp.array[wp.float32],
    path_before: wp.array[wp.float32],
    hit: wp.array[wp.vec3],
    face: wp.array[wp.int32],
    tallies: wp.array2d[wp.float64],
):
    """Photon i followed through up to ``object_bounces`` interactions with glass or specular
    receivers (``kernels/caustics/bounces.py``) to the diffuse receiver it lands on. On exit
    ``origin``/``direction`` are the last segment's, ``carried`` its weight and ``path_before`` the
    water path before it (glass does not attenuate). What does not land is tallied by reason
    (:data:`REFLECTED` at each bounce, :data:`BEYOND_LIMIT`, :data:`TRAPPED`, :data:`MISSED`)."""
    i = wp.tid()
    face[i] = -1
    carried[i] = 0.0
    path_before[i] = 0.0
    w = weight[i]
    if w <= 0.0:
        return
    g = i / photons_per_group
    k0 = g * bands_per_group
    o = origin[i]
    d = direction[i]
    if periodic != 0:
        o = periodic_start(o, d, extent_m, plane_z)
    tr = follow_bounces(mesh, face_receiver, optics, optics.water_ior[g], o, d)
    for j in range(MAX_OBJECT_BOUNCES):
        if j < tr.bounces and tr.loss[j] > 0.0:
            tally(tallies, REFLECTED, w * tr.loss[j], sun_irradiance, attenuation, k0, bands_per_group,
                  tr.loss_path_m[j])
    w = w * tr.transmit
    if tr.end == BEYOND_LIMIT_END:
        tally(tallies, BEYOND_LIMIT, w, sun_irradiance, attenuation, k0, bands_per_group, tr.path_m)
        return
    if tr.end == TRAPPED_END:
        tally(tallies, TRAPPED, w, sun_irradiance, attenuation, k0, bands_per_group, tr.path_m)
        return
    if tr.end == MISSED_END and tr.bounces > 0:
        tally(tallies, MISSED, w, sun_irradiance, attenuation, k0, bands_per_group, tr.path_m)
    origin[i] = tr.origin
    direction[i] = tr.direction
    carried[i] = w
    path_before[i] = tr.path_m
    if tr.end == LANDED:
        hit[i] = tr.hit
        face[i] = tr.face
