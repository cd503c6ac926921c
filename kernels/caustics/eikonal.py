"""Eikonal caustics (after Mercier 2013): the refracted wavefront's travel time in a 3-D grid.

The optical path φ of the sunlight below the surface solves |∇φ| = n_w. The grid has N×N columns
at the water grid's cell centres (spacing h = L/N) and layers z_k = z_top − k·h from above the
highest crest down past the floor. Layers at and just below the surface of each column are
*frozen*: φ there is the local refracted plane front, ``φ(p) = −s·q + n_w t·(p − q)`` with q the
surface point above p and t the sun refracted at q. Below, φ is found layer by layer from the top:
refracted rays always descend (they leave the surface within the critical angle of the
vertical), so a node's upwind neighbours lie in its own layer or the one above. Each layer is
relaxed by Jacobi passes of the upwind (Godunov) update (Zhao 2005; the update of the fast
marching method, Sethian 1996), second order where the next node upwind is known (Sethian 1999:
a first-order scheme rounds a converging front's crest into a kink, and its Laplacian — all that
matters here — would not converge), until no node changes: parallel over a layer's N² nodes,
sequential over layers — a fast-sweeping variant ordered along the direction of propagation.

Values are stored as ψ = φ − φ0(p), the departure from the still-water front φ0(p) = G·p,
G = n_w t0: small numbers, so float32 keeps the Laplacian of a nearly flat front exact. At the faces
of a non-periodic grid the missing neighbour mirrors ψ (∂ψ/∂n = 0): the front is continued as
the incoming plane wave, so a flat interface stays exactly planar up to the faces (our reading of
Mercier §3.2, "modified propagation costs at the domain faces").

Mercier's caustic texture is the discrete Laplacian of φ (eq. 3–4): the 7-point Laplacian here.
To turn it into floor irradiance we integrate the transport equation ∇·(I∇φ) = 0 along the rays,
d ln I / ds = −Δφ / |∇φ| (semi-Lagrangian, one layer per step), which keeps still water uniform.
"""

import warp as wp

from warpcaustics.kernels.geometry import (
    bilerp,
    cell_centre,
    fresnel_transmittance,
    grid_bilinear,
    grid_cell,
    refract,
    scalar_bilinear,
)

wp.set_module_options({"enable_backward": False})

FAR = wp.constant(1.0e30)
"""ψ of a node the front has not reached."""

MAX_LOG_STEP = wp.constant(8.0)
"""|Δ ln I| per layer is clamped here: at the kinks of the first-arrival front (caustics) the
Laplacian is a spike and the intensity would overflow."""


@wp.struct
class EikonalGrid:
    n: int
    """Columns per side (N)."""
    layers: int
    """Layers (nz)."""
    h: float
    """Node spacing, horizontal and vertical [m]."""
    extent_m: float
    """Side L of the patch [m]."""
    z_top: float
    """Height of layer 0 [m]."""
    periodic: int
    """1: columns wrap; 0: faces mirror ψ."""
    slowness: float
    """n_w: the optical path per metre in water [-]."""
    gradient: wp.vec3
    """G = n_w t0: the still-water front's gradient [-]."""
    sun_dir: wp.vec3
    """Unit vector towards the sun."""
    eta: float
    """n_air / n_w, for refraction into the water."""


@wp.func
def layer_z(grid: EikonalGrid, k: int) -> float:
    return grid.z_top - float(k) * grid.h


@wp.func
def lateral(grid: EikonalGrid, psi: wp.array3d[wp.float32], k: int, j: int, i: int, axis: int,
            offset: int) -> float:
    """φ − φ0(p) at the lateral node ``offset`` steps from (k, j, i) along ``axis`` (0: x, 1: y):
    ψ there plus G·(node − p). Outside a non-periodic grid the node mirrors ψ across the face
    (half a spacing beyond the outermost nodes)."""
    m, _outside = lateral_index(grid, j, i, axis, offset)
    value = psi[k, j, m]
    if axis == 1:
        value = psi[k, m, i]
    return value + grid.gradient[axis] * grid.h * float(offset)


@wp.func
def lateral_index(grid: EikonalGrid, j: int, i: int, axis: int, offset: int):
    """Index along ``axis`` of the node ``offset`` steps from column (j, i): wrapped on a periodic
    grid; beyond a face, its mirror image across the face (half a spacing past the outermost
    nodes), with ``outside`` = 1."""
    n = grid.n
    c = i
    if axis == 1:
        c = j
    m = c + offset
    outside = int(0)
    if grid.periodic != 0:
        m = ((m % n) + n) % n
    else:
        if m < 0:
            m = -m - 1
            outside = 1
        if m >= n:
            m = 2 * n - 1 - m
            outside = 1
    return m, outside


@wp.func
def upwind(first: float, second: float) -> wp.vec2:
    """(weight, value) of one axis' upwind term. Second order where the next node along is known
    and earlier: (3u − 4a + a₂)/2h = (3/2)(u − ã)/h with ã = (4a − a₂)/3 (the second-order fast
    marching of Sethian 1999); first order, (u − a)/h, otherwise."""
    if second <= first:
        return wp.vec2(2.25, (4.0 * first - second) / 3.0)
    return wp.vec2(1.0, first)


@wp.func
def lateral_upwind(
    grid: EikonalGrid, psi: wp.array3d[wp.float32], k: int, j: int, i: int, axis: int
) -> wp.vec2:
    """The upwind term of a lateral axis, from the side whose neighbour the front reached first."""
    lo = lateral(grid, psi, k, j, i, axis, -1)
    hi = lateral(grid, psi, k, j, i, axis, 1)
    if lo <= hi:
        return upwind(lo, lateral(grid, psi, k, j, i, axis, -2))
    return upwind(hi, lateral(grid, psi, k, j, i, axis, 2))


@wp.func
def quadratic(t0: wp.vec2, t1: wp.vec2, t2: wp.vec2, f: float) -> float:
    """Larger root of Σ w (u − a)² = f² over the (w, a) terms given (a zero weight drops one)."""
    a = t0[0] + t1[0] + t2[0]
    b = t0[0] * t0[1] + t1[0] * t1[1] + t2[0] * t2[1]
    c = t0[0] * t0[1] * t0[1] + t1[0] * t1[1] * t1[1] + t2[0] * t2[1] * t2[1] - f * f
    return (b + wp.sqrt(wp.max(b * b - a * c, 0.0))) / a


@wp.func
def solve_terms(t0: wp.vec2, t1: wp.vec2, t2: wp.vec2, f: float) -> float:
    """Upwind solution u of Σ w_i max(u − a_i, 0)² = f² for three (w_i, a_i) terms: take them in
    order of a_i, adding the next while u exceeds it (Zhao 2005 §2, with weights)."""
    if t1[1] < t0[1]:
        tmp = t0
        t0 = t1
        t1 = tmp
    if t2[1] < t1[1]:
        tmp = t1
        t1 = t2
        t2 = tmp
    if t1[1] < t0[1]:
        tmp = t0
        t0 = t1
        t1 = tmp
    none = wp.vec2(0.0, 0.0)
    u = t0[1] + f / wp.sqrt(t0[0])
    if u > t1[1]:
        u = quadratic(t0, t1, none, f)
        if u > t2[1]:
            u = quadratic(t0, t1, t2, f)
    return u


@wp.kernel
def init_front(
    grid: EikonalGrid,
    positions: wp.array2d[wp.vec3],
    normals: wp.array2d[wp.vec3],
    visible: wp.array2d[wp.float32],
    surface_extent_m: float,
    surface_periodic: int,
    top: wp.array2d[wp.int32],
    psi: wp.array3d[wp.float32],
    intensity: wp.array3d[wp.float32],
    path: wp.array3d[wp.float32],
):
    """Per column: the surface above it, the frozen layers (z ≥ η − h) with the refracted plane
    front, their intensity across the ray, I = E_sun-relative T (s·n) / (n_z |t_z|) times the sun's
    visibility there (crests shade the surface behind them at a low sun), and path."""
    j, i = wp.tid()
    xy = cell_centre(i, j, grid.n, grid.extent_m)
    q = grid_bilinear(positions, surface_extent_m, surface_periodic, xy[0], xy[1])
    eta_m = q[2]
    nrm = wp.normalize(grid_bilinear(normals, surface_extent_m, surface_periodic, xy[0], xy[1]))
    cos_i = wp.dot(nrm, grid.sun_dir)
    t = wp.vec3(0.0, 0.0, -1.0)
    through = float(0.0)
    if cos_i > 0.0:
        d = refract(-grid.sun_dir, nrm, grid.eta)
        if d[2] < -1.0e-3:
            t = wp.normalize(d)
            through = fresnel_transmittance(cos_i, grid.eta) * cos_i / (nrm[2] * wp.abs(t[2]))
            through *= scalar_bilinear(visible, surface_extent_m, surface_periodic, xy[0], xy[1])
    last = int(wp.floor((grid.z_top - (eta_m - grid.h)) / grid.h))
    last = wp.clamp(last, 0, grid.layers - 1)
    top[j, i] = last
    n_w = grid.slowness
    for k in range(grid.layers):
        z = layer_z(grid, k)
        if k <= last:
            # φ_ext − φ0 on the vertical through q (x, y terms cancel by Snell's law)
            psi[k, j, i] = -grid.sun_dir[2] * eta_m + n_w * t[2] * (z - eta_m) - grid.gradient[2] * z
            intensity[k, j, i] = through
            path[k, j, i] = wp.max(eta_m - z, 0.0) / wp.abs(t[2])
        else:
            psi[k, j, i] = FAR
            intensity[k, j, i] = 0.0
            path[k, j, i] = 0.0


@wp.kernel
def relax_layer(
    grid: EikonalGrid,
    k: int,
    top: wp.array2d[wp.int32],
    psi: wp.array3d[wp.float32],
    tolerance: float,
    scratch: wp.array2d[wp.float32],
    changed: wp.array[wp.int32],
):
    """One Jacobi pass of the Godunov update over layer k (frozen nodes keep their value)."""
    j, i = wp.tid()
    old = psi[k, j, i]
    if k <= top[j, i]:
        scratch[j, i] = old
        return
    gz = grid.gradient[2] * grid.h  # the node above is h higher
    up = psi[k - 1, j, i] + gz
    up2 = up + FAR
    if k >= 2:
        up2 = psi[k - 2, j, i] + 2.0 * gz
    u = solve_terms(lateral_upwind(grid, psi, k, j, i, 0), lateral_upwind(grid, psi, k, j, i, 1),
                    upwind(up, up2), grid.slowness * grid.h)
    new = wp.min(old, u)
    scratch[j, i] = new
    if old - new > tolerance:
        changed[0] = 1


@wp.kernel
def store_layer(k: int, scratch: wp.array2d[wp.float32], psi: wp.array3d[wp.float32]):
    j, i = wp.tid()
    psi[k, j, i] = scratch[j, i]


@wp.func
def vertical(grid: EikonalGrid, psi: wp.array3d[wp.float32], k: int, j: int, i: int) -> wp.vec2:
    """φ − φ0(p) of the nodes above and below (k − 1, k + 1); the bottom layer mirrors."""
    g = grid.gradient[2] * grid.h
    if k == 0:  # the top layer (always frozen) mirrors the one below
        below = psi[1, j, i]
        return wp.vec2(below + g, below - g)
    above = psi[k - 1, j, i]
    below = above
    if k + 1 < grid.layers:
        below = psi[k + 1, j, i]
    return wp.vec2(above + g, below - g)


@wp.kernel
def laplacian(
    grid: EikonalGrid,
    top: wp.array2d[wp.int32],
    psi: wp.array3d[wp.float32],
    lap: wp.array3d[wp.float32],
):
    """Mercier's caustic texture: the 7-point Laplacian Δφ [1/m] (0 on frozen nodes)."""
    k, j, i = wp.tid()
    if k <= top[j, i]:
        lap[k, j, i] = 0.0
        return
    x = lateral(grid, psi, k, j, i, 0, -1) + lateral(grid, psi, k, j, i, 0, 1)
    y = lateral(grid, psi, k, j, i, 1, -1) + lateral(grid, psi, k, j, i, 1, 1)
    z = vertical(grid, psi, k, j, i)
    lap[k, j, i] = (x + y + z[0] + z[1] - 6.0 * psi[k, j, i]) / (grid.h * grid.h)


@wp.func
def ray_gradient(grid: EikonalGrid, psi: wp.array3d[wp.float32], k: int, j: int, i: int) -> wp.vec3:
    """∇φ at node (k, j, i) by central differences (one-sided at the bottom)."""
    z = vertical(grid, psi, k, j, i)
    h2 = 2.0 * grid.h
    return wp.vec3((lateral(grid, psi, k, j, i, 0, 1) - lateral(grid, psi, k, j, i, 0, -1)) / h2,
                   (lateral(grid, psi, k, j, i, 1, 1) - lateral(grid, psi, k, j, i, 1, -1)) / h2,
                   (z[0] - z[1]) / h2)


@wp.func
def layer_sample(grid: EikonalGrid, a: wp.array3d[wp.float32], k: int, x: float, y: float) -> float:
    """Bilinear value of layer k of a node array at (x, y) [m] (wrapped or clamped)."""
    i0, j0, i1, j1, tu, tv = grid_cell(grid.n, grid.extent_m, grid.periodic, x, y)
    return bilerp(a[k, j0, i0], a[k, j0, i1], a[k, j1, i0], a[k, j1, i1], tu, tv)


@wp.func
def floor_sample(grid: EikonalGrid, a: wp.array3d[wp.float32], floor_z: float, x: float, y: float) -> float:
    """A node array at the floor point (x, y, floor_z): linear between the two layers around it,
    bilinear within each."""
    kf = (grid.z_top - floor_z) / grid.h
    k0 = wp.clamp(int(wp.floor(kf)), 0, grid.layers - 2)
    w = wp.clamp(kf - float(k0), 0.0, 1.0)
    return (1.0 - w) * layer_sample(grid, a, k0, x, y) + w * layer_sample(grid, a, k0 + 1, x, y)


@wp.kernel
def transport_layer(
    grid: EikonalGrid,
    k: int,
    top: wp.array2d[wp.int32],
    psi: wp.array3d[wp.float32],
    lap: wp.array3d[wp.float32],
    intensity: wp.array3d[wp.float32],
    path: wp.array3d[wp.float32],
    horizontal: wp.array3d[wp.float32],
):
    """Layer k of the intensity across the rays: I(p) = I(p_up) exp(−∫ Δφ/|∇φ| ds) from the point
    p_up where the ray through p crosses layer k − 1 (trapezoid rule; the Laplacian is taken as 0
    above the frozen layers' end). Also the path from the surface and the irradiance on a
    horizontal plane, I |r_z| (written for every layer, frozen ones included)."""
    j, i = wp.tid()
    g = ray_gradient(grid, psi, k, j, i)
    r = wp.normalize(g)
    if k <= top[j, i]:
        horizontal[k, j, i] = intensity[k, j, i] * wp.abs(r[2])
        return
    xy = cell_centre(i, j, grid.n, grid.extent_m)
    step = grid.h / wp.max(wp.abs(r[2]), 1.0e-3)
    ux = xy[0] - r[0] * step
    uy = xy[1] - r[1] * step
    lap_up = layer_sample(grid, lap, k - 1, ux, uy)
    rate = 0.5 * (lap[k, j, i] + lap_up) / wp.length(g)
    log_step = wp.clamp(-rate * step, -MAX_LOG_STEP, MAX_LOG_STEP)
    value = layer_sample(grid, intensity, k - 1, ux, uy) * wp.exp(log_step)
    intensity[k, j, i] = value
    path[k, j, i] = layer_sample(grid, path, k - 1, ux, uy) + step
    horizontal[k, j, i] = value * wp.abs(r[2])


@wp.kernel
def floor_irradiance(
    grid: EikonalGrid,
    horizontal: wp.array3d[wp.float32],
    path: wp.array3d[wp.float32],
    texel_z: wp.array2d[wp.float32],
    texel_normal: wp.array2d[wp.vec3],
    sun_irradiance: wp.array[wp.float32],
    attenuation_per_m: wp.array[wp.float32],
    out: wp.array3d[wp.float32],
):
    """Floor map (K, M, M): the horizontal irradiance of the two layers around the floor at the
    texel's centre (height ``texel_z``), interpolated in z and bilinearly in x, y, times E_sun(λ)
    exp(−c(λ) ℓ); on a relief, times ``facing``: irradiance on the floor's true area. On a
    non-periodic grid a texel is dark where its still-water ray comes from beyond the patch (no
    water surface there), as in the flux-ratio map: the faces continue the front, so the field
    itself does not know."""
    b, j, i = wp.tid()
    xy = cell_centre(i, j, out.shape[1], grid.extent_m)
    floor_z = texel_z[j, i]
    e = wp.max(floor_sample(grid, horizontal, floor_z, xy[0], xy[1]), 0.0)  # §3.3's waves may dip below 0
    length = floor_sample(grid, path, floor_z, xy[0], xy[1])
    value = sun_irradiance[b] * e * facing(grid, texel_normal[j, i]) * wp.exp(-attenuation_per_m[b] * length)
    if grid.periodic == 0 and beyond_patch(grid, xy[0], xy[1], floor_z):
        value = 0.0
    out[b, j, i] = value


@wp.func
def facing(grid: EikonalGrid, normal: wp.vec3) -> float:
    """Irradiance on a floor of unit normal ``normal`` per horizontal irradiance, |n·t0| / |t0_z|
    with t0 still water's refracted direction (the relief's tilt towards or away from the light;
    the local rays' own tilt is neglected). Exactly 1 on a flat floor."""
    return wp.abs(wp.dot(normal, grid.gradient)) / wp.abs(grid.gradient[2])


@wp.func
def beyond_patch(grid: EikonalGrid, x: float, y: float, floor_z: float) -> bool:
    """Whether still water's refracted ray to the floor point (x, y) enters the water outside the
    patch (it meets z = 0 at (x, y) − t₀_xy · (−floor_z)/|t₀_z|)."""
    t = grid.gradient / grid.slowness
    s = (0.0 - floor_z) / wp.abs(t[2])
    half = 0.5 * grid.extent_m
    return wp.abs(x - t[0] * s) > half or wp.abs(y - t[1] * s) > half


@wp.func
def neighbour(i: int, n: int, periodic: int) -> int:
    """Column index i of an n-column grid: wrapped (periodic) or mirrored at the faces."""
    if periodic != 0:
        return (i + n) % n
    if i < 0:
        return 0
    if i >= n:
        return n - 1
    return i


@wp.kernel
def threshold_wave_step(grid: EikonalGrid, horizontal: wp.array3d[wp.float32], k: int, courant2: float,
                        first: int):
    """Mercier (2013) §3.3's post-process, one layer: below the threshold height the caustic texture
    is not the eikonal's but a wave simulation in the xy plane, depth standing for time, started
    from the threshold layer at rest, so light that the viscosity solution gathers into thin
    structures spreads in cones of half-angle atan(√courant2): layer k+1 from layers k and k−1 by
    leapfrog (the first step from layer k alone), columns wrapping on a periodic grid and mirrored
    at the faces of a pool. Values may go negative; the floor sample clamps them."""
    j, i = wp.tid()
    n = grid.n
    u = horizontal[k, j, i]
    west = horizontal[k, j, neighbour(i - 1, n, grid.periodic)]
    east = horizontal[k, j, neighbour(i + 1, n, grid.periodic)]
    south = horizontal[k, neighbour(j - 1, n, grid.periodic), i]
    north = horizontal[k, neighbour(j + 1, n, grid.periodic), i]
    lap = west + east + south + north - 4.0 * u
    if first != 0:
        horizontal[k + 1, j, i] = u + 0.5 * courant2 * lap
    else:
        horizontal[k + 1, j, i] = 2.0 * u - horizontal[k - 1, j, i] + courant2 * lap

