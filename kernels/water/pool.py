"""Shallow-water pool: depth-averaged mass and momentum with gravity and viscosity, walls, drops.

Staggered (MAC) grid over the N×N cells of the pool: water depth ``h[iy, ix]`` at cell centres,
``u[iy, jx]`` on the N+1 x-faces of each row, ``v[jy, ix]`` on the N+1 y-faces of each column.
Mass is updated in conservative flux form with upwind face depths, so the volume only changes
by rounding; walls are faces with zero normal velocity. Momentum: semi-Lagrangian advection, then
gravity from the surface slope and an explicit viscous Laplacian (symplectic Euler: velocities
first, then depths with the new velocities).

The substep's kernels take ``span`` consecutive cells of a row per thread (a one-dimensional
launch over rows × ⌈columns/span⌉ runs, ``cell_run``): one cell per thread on the GPU, a whole row
per thread on the CPU, where Warp runs threads one after another and a thread's own fixed cost
would otherwise be paid per cell. The arithmetic per cell is the same either way. For the CPU's
sake the runs are ``while`` loops whose array indices are affine in the loop counter: the walls
and the first and last column are done outside the loop, with their clamped neighbours, so the
loop body has no clamps, wall tests or divisions. With the one-dimensional launch (a
two-dimensional one made the same loop 1.6× slower, for reasons the assembly did not show us),
accelerate_u ran 2.9×, accelerate_v 2.6× and update_depth 2.3× faster at 512² on a 2-core Xeon
(same process, interleaved) than with ``range`` loops, a two-dimensional launch and clamps and
tests in the loop. That is leaner scalar code, not SIMD: compiled with vectorisation off they run
as fast. The advection's bilinear sample reads where the velocity points; its arithmetic stays as it was
(the loop and launch alone made it about 1.1× faster).
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
def cell_run(thread: int, span: int, cols: int) -> wp.vec3i:
    """(row, first cell, end cell) of a thread's run of ``span`` cells in rows of ``cols`` cells:
    the launch is one-dimensional over rows × ⌈cols/span⌉ runs."""
    runs = (cols + span - 1) // span
    row = thread // runs
    start = (thread - row * runs) * span
    return wp.vec3i(row, start, wp.min(start + span, cols))


@wp.kernel
def advect_u(u: wp.array2d[wp.float32], v: wp.array2d[wp.float32], dt_over_cell: float, span: int,
             u_out: wp.array2d[wp.float32]):
    """Semi-Lagrangian advection of u (face (iy, jx) sits at cell coordinates (jx, iy + 0.5))."""
    run = cell_run(wp.tid(), span, u.shape[1])
    iy = run[0]
    last = v.shape[1] - 1
    jx = run[1]
    end = run[2]
    while jx < end:
        vel_u = u[iy, jx]
        # v at this u-face: mean of the four surrounding v-faces (v-grid index (ix, jy)), the
        # nearest column's two at the walls. Bit for bit the bilinear sample at (jx − ½, iy + ½)
        # (weights ½ scale exactly), without its clamps and conversions.
        ia = wp.max(jx - 1, 0)
        ib = wp.min(jx, last)
        vel_v = 0.25 * ((v[iy, ia] + v[iy, ib]) + (v[iy + 1, ia] + v[iy + 1, ib]))
        u_out[iy, jx] = sample_faces(u, float(jx) - vel_u * dt_over_cell, float(iy) - vel_v * dt_over_cell)
        jx += 1


@wp.kernel
def advect_v(u: wp.array2d[wp.float32], v: wp.array2d[wp.float32], dt_over_cell: float, span: int,
             v_out: wp.array2d[wp.float32]):
    """Semi-Lagrangian advection of v (face (jy, ix) sits at cell coordinates (ix + 0.5, jy))."""
    run = cell_run(wp.tid(), span, v.shape[1])
    jy = run[0]
    # u at this v-face: mean of the four surrounding u-faces (as vel_v in advect_u).
    ja = wp.max(jy - 1, 0)
    jb = wp.min(jy, u.shape[0] - 1)
    ix = run[1]
    end = run[2]
    while ix < end:
        vel_v = v[jy, ix]
        vel_u = 0.25 * ((u[ja, ix] + u[ja, ix + 1]) + (u[jb, ix] + u[jb, ix + 1]))
        v_out[jy, ix] = sample_faces(v, float(ix) - vel_u * dt_over_cell, float(jy) - vel_v * dt_over_cell)
        ix += 1


REST_SPEED = 1.0e-20
"""[m/s] A face velocity below this is set to zero. The numerical diffusion of the advection gives
a wave front tails that fall geometrically, and float32 would carry them down through subnormal
numbers (below 1.2e-38), which x86 CPUs compute 10–100× slower: with them the substep was up to
1.26× slower at 256² and 512² (docs/benchmarks.md). 1e-20 m/s moves nothing: the depths, which
change by u h dt/Δ, stayed the same to the bit wherever we compared (64²…1024², 64 substeps)."""


@wp.func
def accelerated(c: float, rise: float, lap: float, wet: bool, gravity_k: float, viscous_k: float) -> float:
    """A face's velocity after gravity and viscosity: c − g dt/Δ · Δη + ν dt/Δ² · ∇²c, or rest if dry
    or slower than REST_SPEED (a face counts as wet unless a neighbouring depth is ≤ 0, and a NaN
    velocity is not below REST_SPEED, so a NaN depth stays NaN and the CFL check sees it)."""
    value = c - gravity_k * rise + viscous_k * lap
    return wp.where(wet and not (wp.abs(value) < REST_SPEED), value, 0.0)


@wp.kernel
def accelerate_u(u_adv: wp.array2d[wp.float32], h: wp.array2d[wp.float32],
                 floor_depth: wp.array2d[wp.float32], dt: float, cell: float, viscosity: float, span: int,
                 u: wp.array2d[wp.float32]):
    """u += dt (−g ∂η/∂x + ν ∇²u); walls (first and last face) and dry faces stay at rest. The
    Laplacian has zero-gradient ends (the nearest row's face beyond the first and last row)."""
    run = cell_run(wp.tid(), span, u.shape[1])
    iy = run[0]
    n = h.shape[1]
    up = wp.max(iy - 1, 0)
    down = wp.min(iy + 1, n - 1)
    gravity_k = GRAVITY * dt / cell
    viscous_k = viscosity * dt / (cell * cell)
    if run[1] == 0:  # the west wall
        u[iy, 0] = 0.0
    if run[2] == n + 1:  # the east wall
        u[iy, n] = 0.0
    # Between the walls every index below is affine in jx: no clamps or tests in the loop.
    jx = wp.max(run[1], 1)
    end = wp.min(run[2], n)
    while jx < end:
        h_w = h[iy, jx - 1]
        h_e = h[iy, jx]
        c = u_adv[iy, jx]
        lap = u_adv[iy, jx - 1] + u_adv[iy, jx + 1] + u_adv[up, jx] + u_adv[down, jx] - 4.0 * c
        rise = (h_e - floor_depth[iy, jx]) - (h_w - floor_depth[iy, jx - 1])
        u[iy, jx] = accelerated(c, rise, lap, not (h_w <= 0.0 or h_e <= 0.0), gravity_k, viscous_k)
        jx += 1


@wp.func
def accelerated_v(v_adv: wp.array2d[wp.float32], h: wp.array2d[wp.float32],
                  floor_depth: wp.array2d[wp.float32], jy: int, ix: int, west: int, east: int,
                  gravity_k: float, viscous_k: float) -> float:
    """accelerate_v at the face (jy, ix) of an inner row; ``west``, ``east``: the columns of the
    Laplacian's side neighbours (the face's own at the first and last column)."""
    h_s = h[jy - 1, ix]
    h_n = h[jy, ix]
    c = v_adv[jy, ix]
    lap = v_adv[jy, west] + v_adv[jy, east] + v_adv[jy - 1, ix] + v_adv[jy + 1, ix] - 4.0 * c
    rise = (h_n - floor_depth[jy, ix]) - (h_s - floor_depth[jy - 1, ix])
    return accelerated(c, rise, lap, not (h_s <= 0.0 or h_n <= 0.0), gravity_k, viscous_k)


@wp.kernel
def accelerate_v(v_adv: wp.array2d[wp.float32], h: wp.array2d[wp.float32],
                 floor_depth: wp.array2d[wp.float32], dt: float, cell: float, viscosity: float, span: int,
                 v: wp.array2d[wp.float32]):
    """v += dt (−g ∂η/∂y + ν ∇²v); walls (first and last row of faces) and dry faces stay at rest."""
    run = cell_run(wp.tid(), span, v.shape[1])
    jy = run[0]
    n = h.shape[0]
    ix = run[1]
    end = run[2]
    if jy == 0 or jy == n:  # the south and north walls
        while ix < end:
            v[jy, ix] = 0.0
            ix += 1
        return
    gravity_k = GRAVITY * dt / cell
    viscous_k = viscosity * dt / (cell * cell)
    last = n - 1
    if ix == 0:
        v[jy, 0] = accelerated_v(v_adv, h, floor_depth, jy, 0, 0, wp.min(1, last), gravity_k, viscous_k)
    if end == n and last > 0:
        v[jy, last] = accelerated_v(v_adv, h, floor_depth, jy, last, last - 1, last, gravity_k, viscous_k)
    # Between the first and last column every index is affine in ix: no clamps in the loop.
    ix = wp.max(ix, 1)
    end = wp.min(end, last)
    while ix < end:
        v[jy, ix] = accelerated_v(v_adv, h, floor_depth, jy, ix, ix - 1, ix + 1, gravity_k, viscous_k)
        ix += 1


@wp.func
def upwind_flux(vel: float, h_minus: float, h_plus: float) -> float:
    """Mass flux through a face: velocity × depth of the cell the water comes from."""
    return vel * wp.where(vel > 0.0, h_minus, h_plus)


@wp.func
def net_outflow(h: wp.array2d[wp.float32], u: wp.array2d[wp.float32], v: wp.array2d[wp.float32],
                iy: int, ix: int, west: int, east: int, south: int, north: int,
                open_w: bool, open_e: bool, open_s: bool, open_n: bool) -> float:
    """Flux out − flux in over the cell's four faces; a face that is a wall (not open) carries none.
    ``west`` … ``north``: the neighbour cells' indices (any valid index behind a wall)."""
    c = h[iy, ix]
    flux_w = wp.where(open_w, upwind_flux(u[iy, ix], h[iy, west], c), 0.0)
    flux_e = wp.where(open_e, upwind_flux(u[iy, ix + 1], c, h[iy, east]), 0.0)
    flux_s = wp.where(open_s, upwind_flux(v[iy, ix], h[south, ix], c), 0.0)
    flux_n = wp.where(open_n, upwind_flux(v[iy + 1, ix], c, h[north, ix]), 0.0)
    return flux_e - flux_w + flux_n - flux_s


@wp.kernel
def update_depth(h: wp.array2d[wp.float32], u: wp.array2d[wp.float32], v: wp.array2d[wp.float32],
                 dt_over_cell: float, span: int, h_out: wp.array2d[wp.float32]):
    """h −= dt/Δ · (flux out − flux in) over the four faces (conservative form); no flux through
    the walls."""
    n = h.shape[0]
    run = cell_run(wp.tid(), span, n)
    iy = run[0]
    south = wp.max(iy - 1, 0)
    north = wp.min(iy + 1, n - 1)
    open_s = iy > 0
    open_n = iy < n - 1
    ix = run[1]
    end = run[2]
    last = n - 1
    if ix == 0:
        h_out[iy, 0] = h[iy, 0] - dt_over_cell * net_outflow(h, u, v, iy, 0, 0, wp.min(1, last), south, north,
                                                             False, last > 0, open_s, open_n)
    if end == n and last > 0:
        h_out[iy, last] = h[iy, last] - dt_over_cell * net_outflow(h, u, v, iy, last, last - 1, last, south,
                                                                   north, True, False, open_s, open_n)
    # Between the first and last column every index is affine in ix: no clamps in the loop.
    ix = wp.max(ix, 1)
    end = wp.min(end, last)
    while ix < end:
        h_out[iy, ix] = h[iy, ix] - dt_over_cell * net_outflow(h, u, v, iy, ix, ix - 1, ix + 1, south, north,
                                                               True, True, open_s, open_n)
        ix += 1


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
    """speed[0] = max over cells of |u| + |v| + √(g h) (atomic max; initialise to 0); infinite where
    a depth or velocity is not finite, which max() would otherwise pass over (a blow-up)."""
    iy, ix = wp.tid()
    vel = wp.max(wp.abs(u[iy, ix]), wp.abs(u[iy, ix + 1])) + wp.max(wp.abs(v[iy, ix]), wp.abs(v[iy + 1, ix]))
    cell_speed = vel + wp.sqrt(GRAVITY * wp.max(h[iy, ix], 0.0))
    if not wp.isfinite(h[iy, ix] + u[iy, ix] + u[iy, ix + 1] + v[iy, ix] + v[iy + 1, ix]):
        cell_speed = wp.inf
    wp.atomic_max(speed, 0, cell_speed)


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
