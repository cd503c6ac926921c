"""One FFT-ocean step (spectrum at t, inverse FFTs, surface assembly): Warp vs numpy.fft.

Both compute the same choppy surface (λ = 1: four packed complex 2-D transforms) from the same
initial spectrum: the four Hermitian spectra at time t, their inverse FFTs, then positions,
normals and the Jacobian at every vertex. ``python -m benchmarks.ocean_step [--quick] [--device D]``
runs it alone (``benchmarks.run`` runs it too; on CUDA to 2048²).
"""

from __future__ import annotations

import itertools
import sys

import numpy as np


def _ocean(n: int, device: str):
    import warpcaustics as wc
    from warpcaustics.water import FFTOcean

    from benchmarks.run import CONFIGS

    scene = wc.load_scene(CONFIGS / "ocean.toml", {"water.resolution": n, "water.choppiness": 1.0})
    return FFTOcean.from_config(scene.config, device)


def warp_stepper(n: int, device: str):
    """One Warp step of the ocean, each call at a later time (nothing carried over), one per timing."""
    ocean = _ocean(n, device)
    clock = itertools.count(1)
    return (lambda: ocean.at(0.1 * next(clock))), 1


def numpy_step(h0, h0m, omega, k, choppiness, extent_m, t):
    """The same step in numpy, in single precision like the kernels: complex64 spectra and
    numpy.fft.ifft2, which transforms complex64 in single precision (numpy ≥ 2.0). Inputs must be
    complex64 / float32; Python scalars keep that precision (NEP 50)."""
    n = len(k)
    kx, ky = np.meshgrid(k, k)
    kk = np.hypot(kx, ky)
    inv_k = np.divide(1.0, kk, out=np.zeros_like(kk), where=kk > 0)
    h = h0 * np.exp(-1j * omega * t) + h0m * np.exp(1j * omega * t)
    f = lambda spec: np.fft.ifft2(spec) * (n * n)  # noqa: E731
    a = f(h + 1j * (1j * kx * h))
    b = f(1j * ky * h + 1j * (1j * kx * inv_k * h))
    c = f(1j * ky * inv_k * h + 1j * (-kx * kx * inv_k * h))
    d = f(-ky * ky * inv_k * h + 1j * (-kx * ky * inv_k * h))
    x = (np.arange(n, dtype=np.float32) + 0.5) * (extent_m / n) - extent_m / 2
    xs, ys = np.meshgrid(x, x)
    jxx, jyy, jxy = 1 + choppiness * c.imag, 1 + choppiness * d.real, choppiness * d.imag
    positions = np.stack([xs + choppiness * b.imag, ys + choppiness * c.real, a.real], -1)
    tx = np.stack([jxx, jxy, a.imag], -1)
    ty = np.stack([jxy, jyy, b.real], -1)
    normals = np.cross(tx, ty)
    normals /= np.linalg.norm(normals, axis=-1, keepdims=True)
    return positions, normals, jxx * jyy - jxy * jxy


def numpy_stepper(n: int, device: str):
    """One numpy step from the same initial spectrum (drawn on ``device``), each call at a later
    time, and the check of its agreement with the kernels there: the largest vertex position
    difference at t = 0.5 s [m]."""
    from warpcaustics.water import from_vec2

    ocean = _ocean(n, device)
    h0 = from_vec2(ocean.h0).astype(np.complex64)
    h0m = from_vec2(ocean.h0_minus_conj).astype(np.complex64)
    omega = ocean.omega.numpy()
    k = ocean.k_axis.numpy()
    clock = itertools.count(1)

    def at(t: float):
        return numpy_step(h0, h0m, omega, k, 1.0, ocean.extent_m, t)

    def check() -> dict:
        positions, _, _ = at(0.5)
        return {"max_abs_position_diff_m": float(np.abs(ocean.at(0.5).positions.numpy() - positions).max())}

    return (lambda: at(0.1 * next(clock))), check


def run(quick: bool, device: str) -> dict:
    """The step at each size, Warp and numpy timed in turn, with the log-log slopes and, in the full
    run, the plot."""
    from benchmarks.run import run_steps

    return run_steps("ocean_step", "fft_ocean_step", quick, device)


def main(argv: list[str] | None = None) -> int:
    from benchmarks.run import module_main

    return module_main(argv, "ocean_step", run, __doc__)


if __name__ == "__main__":
    sys.exit(main())
