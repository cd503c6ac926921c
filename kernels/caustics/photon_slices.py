"""The photons' light in the water column, on horizontal slices (the light shafts of the view from
above the water, ``caustics.method = "photons"``).

A camera under the water splats each photon's path as its pinhole projects it
(``kernels/scene/camera/splats.py``); the refracted view rays of a camera above the water share no
centre of projection, so there the photons' light is gathered instead from planes z = z_s: each
photon's last segment crosses a plane at one point, and the crossings of its grid neighbours span
its lattice cell there, as the hits do on the floor (``photon_footprints``). Its flux, attenuated
over its path to the plane and divided by |d_z| (flux per area across the light, E⊥, rather than
per horizontal area), is spread over that cell by exact clipping into the slice's texels; a
photon whose neighbours do not cross the plane falls back to its texel. The camera samples the
in-scattering integral along each refracted ray from these maps (``kernels/scene/camera/above.py
slice_inscatter``).
"""

import warp as wp

from warpcaustics.kernels.caustics.fluxratio import FloorMap, spread_triangle, texel_of, wrap_coord
from warpcaustics.kernels.caustics.photon_footprints import photon_deposit
from warpcaustics.kernels.caustics.photon_lattice import MAX_CELL_SPACINGS, grid_neighbour, unwrap
from warpcaustics.kernels.caustics.photons import Photons

wp.set_module_options({"enable_backward": False})


@wp.func
def crossing(ph: Photons, p: int, z: float):
    """(point, ok): where photon p's last segment, from its start to its hit, crosses the plane z
    (ok = 0 if it does not, or the photon carries nothing or landed nowhere)."""
    if ph.face[p] < 0 or ph.weight[p] <= 0.0:
        return wp.vec3(0.0), int(0)
    o = ph.origin[p]
    h = ph.hit[p]
    if not (o[2] >= z and h[2] <= z and o[2] > h[2]):  # the planes at its ends count
        return wp.vec3(0.0), int(0)
    t = (o[2] - z) / (o[2] - h[2])
    c = o + t * (h - o)
    return wp.vec3(c[0], c[1], z), int(1)


@wp.func
def slice_step(ph: Photons, p: int, c: wp.vec3, along_v: int, z: float):
    """(e, ok): the step from photon p's crossing ``c`` to its next grid neighbour's along u or v,
    forwards, or backwards (reversed) where the forward one does not cross the plane."""
    n = grid_neighbour(p, along_v, 1, ph.quads, ph.subdivisions, ph.periodic)
    if n >= 0:
        cn, ok = crossing(ph, n, z)
        if ok != 0:
            return unwrap(c, cn, ph.periodic, ph.extent_m), int(1)
    n = grid_neighbour(p, along_v, -1, ph.quads, ph.subdivisions, ph.periodic)
    if n >= 0:
        cn, ok = crossing(ph, n, z)
        if ok != 0:
            return unwrap(cn, c, ph.periodic, ph.extent_m), int(1)
    return wp.vec3(0.0), int(0)


@wp.kernel
def splat_slice(
    ph: Photons,
    z: float,
    spacing_m: float,
    slice_map: FloorMap,
    flux: wp.array4d[wp.float32],
    texels: wp.array3d[wp.float32],
    coarse_count: wp.array[wp.int32],
):
    """Photon p's E⊥ where its last segment crosses the plane z, into ``texels`` (M, M, K) [W m^-2
    nm^-1 per unit of the flux's horizontal density]: ``w E(λ) e^{−c(λ)ℓ} / |d_z|`` over its lattice
    cell at the plane (half per triangle, kept in ``flux`` (P, 1, 1, K)), or into its texel."""
    p = wp.tid()
    c, ok = crossing(ph, p, z)
    if ok == 0:
        return
    o = ph.origin[p]
    along = c - o
    ell = ph.path_before[p] + wp.length(along)
    d = wp.normalize(ph.hit[p] - o)
    g = p / ph.photons_per_group
    k0 = g * ph.wavelengths_per_group
    scale = ph.weight[p] / wp.abs(d[2])
    for j in range(ph.wavelengths_per_group):
        k = k0 + j
        flux[p, 0, 0, k] = 0.5 * scale * ph.sun_irradiance[k] * wp.exp(-ph.attenuation_per_m[k] * ell)
    m = texels.shape[0]
    q = (wp.vec2(c[0], c[1]) - slice_map.origin) * slice_map.scale
    eu, ok_u = slice_step(ph, p, c, 0, z)
    ev, ok_v = slice_step(ph, p, c, 1, z)
    u = wp.vec2(eu[0], eu[1]) * slice_map.scale
    v = wp.vec2(ev[0], ev[1]) * slice_map.scale
    area = wp.abs(u[0] * v[1] - u[1] * v[0])
    longest = wp.max(wp.length(u), wp.length(v))
    fine = ok_u != 0 and ok_v != 0 and area > 1.0e-6 * longest * longest
    fine = fine and longest <= MAX_CELL_SPACINGS * spacing_m * slice_map.scale
    q0 = q - 0.5 * (u + v)
    if fine and slice_map.wrap != 0:
        q0 = wp.vec2(wrap_coord(q0[0], m), wrap_coord(q0[1], m))
    elif fine:  # past a pool's wall the cell would lose flux: the texel instead
        lo = wp.min(wp.min(q0, q0 + u), wp.min(q0 + v, q0 + u + v))
        hi = wp.max(wp.max(q0, q0 + u), wp.max(q0 + v, q0 + u + v))
        fine = lo[0] >= 0.0 and lo[1] >= 0.0 and hi[0] <= float(m) and hi[1] <= float(m)
    inv_texel_area = slice_map.scale * slice_map.scale
    if not fine:
        tx = texel_of(q[0], m, slice_map.wrap)
        ty = texel_of(q[1], m, slice_map.wrap)
        if tx >= 0 and ty >= 0:
            for j in range(ph.wavelengths_per_group):
                k = k0 + j
                wp.atomic_add(texels, ty, tx, k, 2.0 * flux[p, 0, 0, k] * inv_texel_area)
        return
    dep = photon_deposit(texels, flux, k0, ph.wavelengths_per_group, p)
    spread_triangle(dep, q0, u, u + v, m, slice_map.wrap, slice_map.max_clipped, inv_texel_area, coarse_count)
    spread_triangle(dep, q0, u + v, v, m, slice_map.wrap, slice_map.max_clipped, inv_texel_area, coarse_count)
