"""One shallow-water pool substep: Warp vs a vectorised numpy implementation of the same scheme.

The same staggered grid and the same operations as ``kernels/water/pool.py``: semi-Lagrangian
advection of u and v (bilinear, clamped), gravity and viscosity on the faces, conservative upwind
update of the depths. Both start from the same state (a pool sloshing after drops).
``python -m benchmarks.pool_step [--quick]`` runs it alone (``benchmarks.run`` runs it too).
"""

from __future__ import annotations

import sys

import numpy as np

# the kernels' own constants (importing warp here does not initialise it)
from warpcaustics.kernels.water.pool import GRAVITY as G
from warpcaustics.kernels.water.pool import REST_SPEED


def _sample(field, fx, fy):
    rows, cols = field.shape
    x = np.clip(fx, 0.0, cols - 1)
    y = np.clip(fy, 0.0, rows - 1)
    i0 = np.minimum(x.astype(np.int64), cols - 2)
    j0 = np.minimum(y.astype(np.int64), rows - 2)
    tx, ty = x - i0.astype(np.float32), y - j0.astype(np.float32)
    return ((1 - ty) * ((1 - tx) * field[j0, i0] + tx * field[j0, i0 + 1])
            + ty * ((1 - tx) * field[j0 + 1, i0] + tx * field[j0 + 1, i0 + 1]))


def _laplacian(f):
    p = np.pad(f, 1, mode="edge")
    return p[1:-1, :-2] + p[1:-1, 2:] + p[:-2, 1:-1] + p[2:, 1:-1] - 4 * f


def _at_rest_if_slow(wet, velocity):
    """kernels/water/pool.py:accelerated: zero where dry or slower than REST_SPEED (NaN kept)."""
    return np.where(wet & ~(np.abs(velocity) < np.float32(REST_SPEED)), velocity, np.float32(0))


def numpy_step(h, u, v, depth, dt, cell, nu):
    """The pool substep in numpy, float32 throughout and in the kernels' order of operations;
    returns new (h, u, v)."""
    n = h.shape[0]
    k = np.float32(dt / cell)
    index = np.arange(n + 1, dtype=np.float32)
    iy, jx = np.meshgrid(index[:n], index, indexing="ij")
    u_adv = _sample(u, jx - u * k, iy - _sample(v, jx - 0.5, iy + 0.5) * k)
    jy, ix = np.meshgrid(index, index[:n], indexing="ij")
    v_adv = _sample(v, ix - _sample(u, ix + 0.5, jy - 0.5) * k, jy - v * k)
    eta = h - depth
    # g dt/Δ and ν dt/Δ² formed in float32 in the kernels' order
    dt32, cell32 = np.float32(dt), np.float32(cell)
    gravity_k = np.float32(G) * dt32 / cell32
    viscous_k = np.float32(nu) * dt32 / (cell32 * cell32)
    u_new = np.zeros_like(u)
    v_new = np.zeros_like(v)
    wet_x = (h[:, :-1] > 0) & (h[:, 1:] > 0)
    u_new[:, 1:-1] = _at_rest_if_slow(wet_x, u_adv[:, 1:-1] - gravity_k * np.diff(eta, axis=1)
                                      + viscous_k * _laplacian(u_adv)[:, 1:-1])
    wet_y = (h[:-1] > 0) & (h[1:] > 0)
    v_new[1:-1] = _at_rest_if_slow(wet_y, v_adv[1:-1] - gravity_k * np.diff(eta, axis=0)
                                   + viscous_k * _laplacian(v_adv)[1:-1])
    fx = np.where(u_new[:, 1:-1] > 0, u_new[:, 1:-1] * h[:, :-1], u_new[:, 1:-1] * h[:, 1:])
    fy = np.where(v_new[1:-1] > 0, v_new[1:-1] * h[:-1], v_new[1:-1] * h[1:])
    flux_x = np.pad(fx, ((0, 0), (1, 1)))
    flux_y = np.pad(fy, ((1, 1), (0, 0)))
    h_new = h - k * ((np.diff(flux_x, axis=1) + flux_y[1:]) - flux_y[:-1])
    return h_new.astype(np.float32), u_new.astype(np.float32), v_new.astype(np.float32)


def _pool(n: int, device: str):
    import warpcaustics as wc
    from warpcaustics.water.pool import ShallowWaterPool

    from benchmarks.run import CONFIGS

    scene = wc.load_scene(CONFIGS / "pool.toml", {"water.resolution": n})
    pool = ShallowWaterPool.from_config(scene.config, device)
    dt = _dt(pool)
    for _ in range(64):  # a sloshing state after the first drop, the same for both sides
        pool.step(dt)
    return pool


def _dt(pool) -> float:
    return pool.cfl * pool.cell_m / pool.max_wave_speed()


def warp_stepper(n: int, device: str):
    """One Warp substep of the sloshing pool, and how many to time together (enough to dwarf the
    launch overhead at small N)."""
    pool = _pool(n, device)
    dt = _dt(pool)
    return (lambda: pool.step(dt)), max(1, 4096 // n)


def numpy_stepper(n: int, device: str):
    """One numpy substep from the same sloshing state (made by the kernels on ``device``: on a GPU
    that spares making it again on the CPU), and the check of its agreement with the kernels there:
    the largest depth difference after one substep [m]."""
    pool = _pool(n, device)
    dt = _dt(pool)
    # .copy(): on the CPU device .numpy() is a view of the arrays the step overwrites.
    h, u, v = pool.h.numpy().copy(), pool.u.numpy().copy(), pool.v.numpy().copy()
    depth = pool.floor_depth.numpy().copy()

    def step():
        return numpy_step(h, u, v, depth, dt, pool.cell_m, pool.viscosity)

    def check() -> dict:
        h1, _, _ = step()
        pool.step(dt)
        return {"max_abs_depth_diff_m": float(np.abs(h1 - pool.h.numpy()).max())}

    return step, check


def run(quick: bool, device: str) -> dict:
    """The substep at each size, Warp and numpy timed in turn, with the log-log slopes and, in the
    full run, the plot."""
    from benchmarks.run import run_steps

    return run_steps("pool_step", "pool_substep", quick, device)


def main(argv: list[str] | None = None) -> int:
    from benchmarks.run import module_main

    return module_main(argv, "pool_step", run, __doc__)


if __name__ == "__main__":
    sys.exit(main())
