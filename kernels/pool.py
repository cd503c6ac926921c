"""Shallow-water pool: depth-averaged mass and momentum with gravity and viscosity, walls, drops.

Staggered (MAC) grid over the N×N cells of the pool: water depth ``h[iy, ix]`` at cell centres,
``u[iy, jx]`` on the N+1 x-faces of each row, ``v[jy, ix]`` on the N+1 y-faces of each column.
Mass is updated in conservative flux form with upwind face depths, so the volume only changes
by rounding; walls are faces with zero normal velocity. Momentum: semi-Lagrangian advection, then
gravity from the surface slope and an explicit viscous Laplacian (symplectic Euler: velocities
first, then depths with the new velocities).

The substep's kernels take ``span`` consecutive cells of a row per thread (launch dimension
(rows, ⌈columns/span⌉)): one cell per thread on the GPU, a whole row per thread on the CPU, where
Warp runs threads one after another and a thread's own fixed cost would otherwise be paid per cell.
The arithmetic per cell is the same either way.
"""

import warp as wp

from warpcaustics.kernels.geometry import cell_centre, normal_from_slopes

wp.set_module_options({"enable_backward": False})

GRAVITY = 9.81


@wp.func
def sample_faces(field: wp.array2d[wp.float32], fx: float, fy: float) -> float:
    """Bilinear sample of a face grid at fractional index (fx along columns, fy along rows), clamped."""
    rows = field.shape[0]
    cols = field.shape[1]
    x = wp.clamp(fx, 0.0, float(cols - 1))
    y = wp.clamp(fy, 0.0, float(rows - 1))
    i0 = wp.min(int(x), cols - 2)
    j0 = wp.min(int(y), rows - 2)
    tx = x - float(i0)
    ty = y - float(j0)
    return (1.0 - ty) * ((1.0 - tx) * field[j0, i0] + tx * field[j0, i0 + 1]) + ty * (
        (1.0 - tx) * field[j0 + 1, i0] + tx * field[j0 + 1, i0 + 1])


@wp.func
def span_end(chunk: int, span: int, cols: int) -> int:
    """End (exclusive) of the ``chunk``-th run of ``span`` cells in a row of ``cols``."""
    return wp.min((chunk + 1) * span, cols)


@wp.kernel
def advect_u(u: wp.array2d[wp.float32], v: wp.array2d[wp.float32], dt_over_cell: float, span: int,
             u_out: wp.array2d[wp.float32]):
    """Semi-Lagrangian advection of u (face (iy, jx) sits at cell coordinates (jx, iy + 0.5))."""
    iy, chunk = wp.tid()
    for jx in range(chunk * span, span_end(chunk, span, u.shape[1])):
        vel_u = u[iy, jx]
        # v at this u-face: mean of the four surrounding v-faces (v-grid index (ix, jy)), the
        # nearest column's two at the walls. Bit for bit the bilinear sample at (jx − ½, iy + ½)
        # (weights ½ scale exactly), without its clamps and conversions.
        ia = wp.max(jx - 1, 0)
        ib = wp.min(jx, v.shape[1] - 1)
        vel_v = 0.25 * ((v[iy, ia] + v[iy, ib]) + (v[iy + 1, ia] + v[iy + 1, ib]))
        u_out[iy, jx] = sample_faces(u, float(jx) - vel_u * dt_over_cell, float(iy) - vel_v * dt_over_cell)


@wp.kernel
def advect_v(u: wp.array2d[wp.float32], v: wp.array2d[wp.float32], dt_over_cell: float, span: int,
             v_out: wp.array2d[wp.float32]):
    """Semi-Lagrangian advection of v (face (jy, ix) sits at cell coordinates (ix + 0.5, jy))."""
    jy, chunk = wp.tid()
    for ix in range(chunk * span, span_end(chunk, span, v.shape[1])):
        vel_v = v[jy, ix]
        # u at this v-face: mean of the four surrounding u-faces (as vel_v in advect_u).
        ja = wp.max(jy - 1, 0)
        jb = wp.min(jy, u.shape[0] - 1)
        vel_u = 0.25 * ((u[ja, ix] + u[ja, ix + 1]) + (u[jb, ix] + u[jb, ix + 1]))
        v_out[jy, ix] = sample_faces(v, float(ix) - vel_u * dt_over_cell, float(jy) - vel_v * dt_over_cell)


@wp.func
def laplacian(f: wp.array2d[wp.float32], j: int, i: int) -> float:
    """5-point Laplacian (in index units) with zero-gradient ends."""
    rows = f.shape[0]
    cols = f.shape[1]
    c = f[j, i]
    return (f[j, wp.max(i - 1, 0)] + f[j, wp.min(i + 1, cols - 1)] + f[wp.max(j - 1, 0), i]
            + f[wp.min(j + 1, rows - 1), i] - 4.0 * c)


@wp.kernel
def accelerate_u(u_adv: wp.array2d[wp.float32], h: wp.array2d[wp.float32],
                 floor_depth: wp.array2d[wp.float32], dt: float, cell: float, viscosity: float, span: int,
                 u: wp.array2d[wp.float32]):
    """u += dt (−g ∂η/∂x + ν ∇²u); walls (first and last face) and dry faces stay at rest."""
    iy, chunk = wp.tid()
    n = h.shape[1]
    for jx in range(chunk * span, span_end(chunk, span, u.shape[1])):
        if jx == 0 or jx == n or h[iy, jx - 1] <= 0.0 or h[iy, jx] <= 0.0:
            u[iy, jx] = 0.0
        else:
            slope = ((h[iy, jx] - floor_depth[iy, jx]) - (h[iy, jx - 1] - floor_depth[iy, jx - 1])) / cell
            u[iy, jx] = u_adv[iy, jx] + dt * (
                -GRAVITY * slope + viscosity * laplacian(u_adv, iy, jx) / (cell * cell))


@wp.kernel
def accelerate_v(v_adv: wp.array2d[wp.float32], h: wp.array2d[wp.float32],
                 floor_depth: wp.array2d[wp.float32], dt: float, cell: float, viscosity: float, span: int,
                 v: wp.array2d[wp.float32]):
    """v += dt (−g ∂η/∂y + ν ∇²v); walls and dry faces stay at rest."""
    jy, chunk = wp.tid()
    n = h.shape[0]
    for ix in range(chunk * span, span_end(chunk, span, v.shape[1])):
        if jy == 0 or jy == n or h[jy - 1, ix] <= 0.0 or h[jy, ix] <= 0.0:
            v[jy, ix] = 0.0
        else:
            slope = ((h[jy, ix] - floor_depth[jy, ix]) - (h[jy - 1, ix] - floor_depth[jy - 1, ix])) / cell
            v[jy, ix] = v_adv[jy, ix] + dt * (
                -GRAVITY * slope + viscosity * laplacian(v_adv, jy, ix) / (cell * cell))


@wp.func
def upwind_flux(vel: float, h_minus: float, h_plus: float) -> float:
    """Mass flux through a face: velocity × depth of the cell the water comes from."""
    if vel > 0.0:
        return vel * h_minus
    return vel * h_plus


@wp.kernel
def update_depth(h: wp.array2d[wp.float32], u: wp.array2d[wp.float32], v: wp.array2d[wp.float32],
                 dt_over_cell: float, span: int, h_out: wp.array2d[wp.float32]):
    """h −= dt/Δ · (flux out − flux in) over the four faces (conservative form)."""
    iy, chunk = wp.tid()
    n = h.shape[0]
    for ix in range(chunk * span, span_end(chunk, span, n)):
        west = float(0.0)
        east = float(0.0)
        south = float(0.0)
        north = float(0.0)
        if ix > 0:
            west = upwind_flux(u[iy, ix], h[iy, ix - 1], h[iy, ix])
        if ix < n - 1:
            east = upwind_flux(u[iy, ix + 1], h[iy, ix], h[iy, ix + 1])
        if iy > 0:
            south = upwind_flux(v[iy, ix], h[iy - 1, ix], h[iy, ix])
        if iy < n - 1:
            north = upwind_flux(v[iy + 1, ix], h[iy, ix], h[iy + 1, ix])
        h_out[iy, ix] = h[iy, ix] - dt_over_cell * (east - west + north - south)


@wp.kernel
def add_drop(h: wp.array2d[wp.float32], extent_m: float, x_m: float, y_m: float, radius_m: float,
             height_m: float):
    """Add a Gaussian mound of water (negative height removes water, never below a dry bed)."""
    iy, ix = wp.tid()
    c = cell_centre(ix, iy, h.shape[0], extent_m)
    r2 = (c[0] - x_m) * (c[0] - x_m) + (c[1] - y_m) * (c[1] - y_m)
    h[iy, ix] = wp.max(h[iy, ix] + height_m * wp.exp(-0.5 * r2 / (radius_m * radius_m)), 0.0)


@wp.kernel
def add_bump(eta: wp.array2d[wp.float32], extent_m: float, x_m: float, y_m: float, radius_m: float,
             height_m: float):
    """Add a Gaussian bump to a surface elevation η (no clamp: η is negative in troughs)."""
    iy, ix = wp.tid()
    c = cell_centre(ix, iy, eta.shape[0], extent_m)
    r2 = (c[0] - x_m) * (c[0] - x_m) + (c[1] - y_m) * (c[1] - y_m)
    eta[iy, ix] = eta[iy, ix] + height_m * wp.exp(-0.5 * r2 / (radius_m * radius_m))


@wp.kernel
def wave_speed(h: wp.array2d[wp.float32], u: wp.array2d[wp.float32], v: wp.array2d[wp.float32],
               speed: wp.array[wp.float32]):
    """speed[0] = max over cells of |u| + |v| + √(g h) (atomic max; initialise to 0)."""
    iy, ix = wp.tid()
    vel = wp.max(wp.abs(u[iy, ix]), wp.abs(u[iy, ix + 1])) + wp.max(wp.abs(v[iy, ix]), wp.abs(v[iy + 1, ix]))
    wp.atomic_max(speed, 0, vel + wp.sqrt(GRAVITY * wp.max(h[iy, ix], 0.0)))


@wp.kernel
def pool_surface(h: wp.array2d[wp.float32], floor_depth: wp.array2d[wp.float32], extent_m: float,
                 positions: wp.array2d[wp.vec3], normals: wp.array2d[wp.vec3]):
    """Vertices at cell centres with z = η = h − depth; normals from central differences
    (one-sided at the walls)."""
    iy, ix = wp.tid()
    n = h.shape[0]
    cell = extent_m / float(n)
    i0 = wp.max(ix - 1, 0)
    i1 = wp.min(ix + 1, n - 1)
    j0 = wp.max(iy - 1, 0)
    j1 = wp.min(iy + 1, n - 1)
    ex = (h[iy, i1] - floor_depth[iy, i1] - h[iy, i0] + floor_depth[iy, i0]) / (float(i1 - i0) * cell)
    ey = (h[j1, ix] - floor_depth[j1, ix] - h[j0, ix] + floor_depth[j0, ix]) / (float(j1 - j0) * cell)
    xy = cell_centre(ix, iy, n, extent_m)
    positions[iy, ix] = wp.vec3(xy[0], xy[1], h[iy, ix] - floor_depth[iy, ix])
    normals[iy, ix] = normal_from_slopes(ex, ey)


@wp.kernel
def wave_equation_step(h: wp.array2d[wp.float32], h_prev: wp.array2d[wp.float32], courant2: float,
                       damping_dt: float, h_next: wp.array2d[wp.float32]):
    """Damped wave equation η_tt = c² ∇²η − γ η_t, leapfrog in time, reflecting walls (mirror
    neighbours): η⁺ = η + (1 − γΔt)(η − η⁻) + (cΔt/Δ)² ∇²η."""
    iy, ix = wp.tid()
    n = h.shape[0]
    c = h[iy, ix]
    lap = (h[iy, wp.max(ix - 1, 0)] + h[iy, wp.min(ix + 1, n - 1)] + h[wp.max(iy - 1, 0), ix]
           + h[wp.min(iy + 1, n - 1), ix] - 4.0 * c)
    h_next[iy, ix] = c + (1.0 - damping_dt) * (c - h_prev[iy, ix]) + courant2 * lap


@wp.kernel
def push_u(u: wp.array2d[wp.float32], extent_m: float, centre: wp.vec2, radius_m: float,
           body_velocity: wp.vec2, blend: float):
    """Inside the body's disc, relax u towards the body's velocity (a moving body pushes water)."""
    iy, jx = wp.tid()
    n = u.shape[0]
    cell = extent_m / float(n)
    p = wp.vec2(float(jx) * cell - 0.5 * extent_m, (float(iy) + 0.5) * cell - 0.5 * extent_m)
    if jx > 0 and jx < n and wp.length(p - centre) < radius_m:
        u[iy, jx] = u[iy, jx] + blend * (body_velocity[0] - u[iy, jx])


@wp.kernel
def push_v(v: wp.array2d[wp.float32], extent_m: float, centre: wp.vec2, radius_m: float,
           body_velocity: wp.vec2, blend: float):
    """Inside the body's disc, relax v towards the body's velocity."""
    jy, ix = wp.tid()
    n = v.shape[1]
    cell = extent_m / float(n)
    p = wp.vec2((float(ix) + 0.5) * cell - 0.5 * extent_m, float(jy) * cell - 0.5 * extent_m)
    if jy > 0 and jy < n and wp.length(p - centre) < radius_m:
        v[jy, ix] = v[jy, ix] + blend * (body_velocity[1] - v[jy, ix])
