"""Wave caustic texture (after Mercier 2013, §4): the 3-D wave equation driven from the interface.

On the eikonal grid (``kernels/caustics/eikonal.py``: N×N columns, layers h apart, the frozen layers at and
just under the surface), a scalar wave u obeys u_tt = v² ∇²u − σ u_t with v = 1/n_w (time is
measured in metres of optical path, so the phase of the sunlight is ω(t − φ)). The frozen nodes
are driven with the refracted plane wave, u = ramp(t) √I₀ sin(ω(t − φ_ext)), I₀ the refracted
intensity across the ray; below them the leapfrog scheme carries it down, and the time average of
u² after the front has passed is the intensity, I = 2⟨u²⟩ (a plane wave of amplitude A has
⟨u²⟩ = A²/2). A damping band (σ growing quadratically) under the floor absorbs what leaves
downwards; the faces of a non-periodic grid let still water's plane wave through. Only layers
the wave can have reached are stepped: the stencil's domain of dependence grows one node per step.
"""

import warp as wp

from warpcaustics.kernels.caustics.eikonal import (
    EikonalGrid,
    beyond_patch,
    facing,
    floor_sample,
    lateral_index,
    layer_z,
)
from warpcaustics.kernels.geometry import cell_centre, grid_bilinear

wp.set_module_options({"enable_backward": False})


@wp.struct
class WaveParams:
    omega: float
    """Temporal angular frequency [rad per m of optical path]: from the leapfrog's own dispersion
    relation for ``kappa``, so still water's plane wave is an exact mode of the grid."""
    omega_space: float
    """Phase per metre of optical path of the front's departure ψ [rad/m]."""
    kappa: wp.vec3
    """Wave vector of the still-water plane wave [rad/m]; on a periodic grid its horizontal part
    is the nearest one that tiles the patch."""
    amplitude_flat: float
    """√I₀ of still water: the amplitude of the plane wave that continues beyond the faces of a
    non-periodic grid."""
    group_vz: float
    """Vertical group velocity of that wave [m per m of optical path]: beyond a face its ramp
    starts when the front gets there."""
    ramp_time: float
    """The drive's rise time [m of optical path]."""
    courant2: float
    """(v Δt / h)²."""
    dt: float
    """Time step [m of optical path]."""
    band: int
    """Thickness of the damping bands [nodes]."""
    sigma_max: float
    """Damping rate at a band's far edge [1 / m of optical path]."""


@wp.func
def damping(grid: EikonalGrid, params: WaveParams, k: int, j: int, i: int) -> float:
    """σ at node (k, j, i): a quadratic ramp over the band above the bottom layer."""
    b = float(params.band)
    d = float(k - (grid.layers - 1 - params.band)) / b
    sigma = float(0.0)
    if d > 0.0:
        sigma = params.sigma_max * d * d
    return sigma


@wp.kernel
def surface_heights(
    grid: EikonalGrid,
    positions: wp.array2d[wp.vec3],
    surface_extent_m: float,
    surface_periodic: int,
    eta: wp.array2d[wp.float32],
):
    """η above each column (for the attenuation path)."""
    j, i = wp.tid()
    xy = cell_centre(i, j, grid.n, grid.extent_m)
    eta[j, i] = grid_bilinear(positions, surface_extent_m, surface_periodic, xy[0], xy[1])[2]


@wp.kernel
def drive(
    grid: EikonalGrid,
    params: WaveParams,
    top: wp.array2d[wp.int32],
    psi: wp.array3d[wp.float32],
    intensity: wp.array3d[wp.float32],
    time: float,
    ramp: float,
    u: wp.array3d[wp.float32],
):
    """Set the frozen nodes to the refracted wave at ``time``: phase ω t − (κ·p + ω_s ψ)."""
    j, i = wp.tid()
    xy = cell_centre(i, j, grid.n, grid.extent_m)
    for k in range(top[j, i] + 1):
        p = wp.vec3(xy[0], xy[1], layer_z(grid, k))
        phase = params.omega * time - wp.dot(params.kappa, p) - params.omega_space * psi[k, j, i]
        u[k, j, i] = ramp * wp.sqrt(intensity[k, j, i]) * wp.sin(phase)


@wp.func
def value_at(
    grid: EikonalGrid, params: WaveParams, u: wp.array3d[wp.float32], k: int, j: int, i: int, axis: int,
    offset: int, time: float, ramp: float
) -> float:
    """u at a lateral neighbour: wrapped on a periodic grid; beyond a face of a non-periodic one,
    still water's plane wave at that node (the face lets it through unchanged, as the eikonal
    method continues the front)."""
    m, outside = lateral_index(grid, j, i, axis, offset)
    if outside != 0:
        ii = i
        jj = j
        if axis == 0:
            ii = i + offset
        else:
            jj = j + offset
        xy = cell_centre(ii, jj, grid.n, grid.extent_m)
        p = wp.vec3(xy[0], xy[1], layer_z(grid, k))
        late = wp.clamp((time - wp.max(-p[2], 0.0) / params.group_vz) / params.ramp_time, 0.0, 1.0)
        rise = 0.5 * (1.0 - wp.cos(wp.pi * late))
        return rise * params.amplitude_flat * wp.sin(params.omega * time - wp.dot(params.kappa, p))
    if axis == 1:
        return u[k, m, i]
    return u[k, j, m]


@wp.kernel
def step(
    grid: EikonalGrid,
    params: WaveParams,
    top: wp.array2d[wp.int32],
    u: wp.array3d[wp.float32],
    u_old: wp.array3d[wp.float32],
    time: float,
    ramp: float,
    u_new: wp.array3d[wp.float32],
):
    """Leapfrog step of u_tt = v²∇²u − σu_t from ``time`` (launched over the active layers only)."""
    k, j, i = wp.tid()
    if k <= top[j, i]:
        return  # driven
    c = u[k, j, i]
    below = u[k - 1, j, i]
    if k + 1 < grid.layers:
        below = u[k + 1, j, i]
    lap = (value_at(grid, params, u, k, j, i, 0, -1, time, ramp)
           + value_at(grid, params, u, k, j, i, 0, 1, time, ramp)
           + value_at(grid, params, u, k, j, i, 1, -1, time, ramp)
           + value_at(grid, params, u, k, j, i, 1, 1, time, ramp)
           + u[k - 1, j, i] + below - 6.0 * c)
    a = 0.5 * damping(grid, params, k, j, i) * params.dt
    u_new[k, j, i] = (2.0 * c - (1.0 - a) * u_old[k, j, i] + params.courant2 * lap) / (1.0 + a)


@wp.kernel
def accumulate(u: wp.array3d[wp.float32], energy: wp.array3d[wp.float32]):
    """energy += u² (launched over the layers to average)."""
    k, j, i = wp.tid()
    v = u[k, j, i]
    energy[k, j, i] = energy[k, j, i] + v * v


@wp.kernel
def floor_irradiance(
    grid: EikonalGrid,
    energy: wp.array3d[wp.float32],
    samples: float,
    eta: wp.array2d[wp.float32],
    gain: float,
    exponent: float,
    texel_z: wp.array2d[wp.float32],
    texel_normal: wp.array2d[wp.vec3],
    sun_irradiance: wp.array[wp.float32],
    attenuation_per_m: wp.array[wp.float32],
    out: wp.array3d[wp.float32],
):
    """Floor map (K, M, M): the intensity I = 2⟨u²⟩ of the layers around the floor at the texel's
    centre (height ``texel_z``; interpolated in z, bilinear in x, y), Mercier's post-process a·I^b,
    times |n·t0| (irradiance on the floor of normal n: |t0_z| on a flat one), E_sun and exp(−c ℓ)
    along the still-water refracted direction from the surface. On a non-periodic
    grid a texel whose still-water ray comes from beyond the patch is dark, as for the other
    methods (the faces let the plane wave through, so the field itself does not know)."""
    b, j, i = wp.tid()
    xy = cell_centre(i, j, out.shape[1], grid.extent_m)
    floor_z = texel_z[j, i]
    e = floor_sample(grid, energy, floor_z, xy[0], xy[1])
    intensity = gain * wp.pow(wp.max(2.0 * e / samples, 0.0), exponent)
    cos_t = wp.abs(grid.gradient[2]) / grid.slowness
    # η at the texel: the nearest column's
    n = grid.n
    ci = wp.clamp(int((xy[0] + 0.5 * grid.extent_m) / grid.h), 0, n - 1)
    cj = wp.clamp(int((xy[1] + 0.5 * grid.extent_m) / grid.h), 0, n - 1)
    path = wp.max(eta[cj, ci] - floor_z, 0.0) / cos_t
    on_floor = cos_t * facing(grid, texel_normal[j, i])  # = |n·t0|
    value = sun_irradiance[b] * intensity * on_floor * wp.exp(-attenuation_per_m[b] * path)
    if grid.periodic == 0 and beyond_patch(grid, xy[0], xy[1], floor_z):
        value = 0.0
    out[b, j, i] = value
