"""One procedural-waves surface (GPU Gems ch. 2): Warp vs the same function in vectorised numpy.

Both evaluate heights and analytic normals of ``configs/procedural.toml``'s octave waves at every
vertex of an N×N grid (float32, like the kernel); the numpy side also reports its largest height
difference from the kernel.
"""

from __future__ import annotations

import numpy as np

TIME_S = 0.7


def numpy_surface(n: int, extent_m: float, w) -> tuple[np.ndarray, np.ndarray]:
    """Heights (N, N) and unit normals (N, N, 3) of the octave waves at the cell centres (float32)."""
    c = ((np.arange(n, dtype=np.float32) + 0.5) * np.float32(extent_m / n) - np.float32(extent_m / 2))
    x, y = np.meshgrid(c, c)
    u, v = x / np.float32(w.scale_m), y / np.float32(w.scale_m)
    r = np.sqrt(u * u + v * v)
    ur, vr = u / r, v / r
    z = np.zeros_like(u)
    gx = np.zeros_like(u)
    gy = np.zeros_like(u)
    f = np.float32(w.factor)
    for _ in range(w.octaves):
        phase = np.float32(w.speed_rad_s * TIME_S) + u * v * np.float32(w.frequency) / f
        s, co = np.sin(phase), np.cos(phase)
        z -= f * co
        gx += r * s * v * np.float32(w.frequency) - f * co * ur
        gy += r * s * u * np.float32(w.frequency) - f * co * vr
        f = f * np.float32(0.5)
    a2 = np.float32(2.0 * w.amplitude)
    height = np.float32(w.scale_m) * a2 * r * z
    normal = np.stack([-a2 * gx, -a2 * gy, np.ones_like(gx)], -1)
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    return height, normal


def _water(n: int, device: str):
    import warpcaustics as wc
    from warpcaustics.water import ProceduralWater

    from benchmarks.run import CONFIGS

    scene = wc.load_scene(CONFIGS / "procedural.toml", {"water.resolution": n})
    return ProceduralWater.from_config(scene.config, device), scene.config.water.extent_m


def warp_stepper(n: int, device: str):
    """One Warp evaluation of the surface, and how many to time together."""
    water, _ = _water(n, device)
    return (lambda: water.at(TIME_S)), max(1, 8192 // n)


def numpy_stepper(n: int, device: str):
    """One numpy evaluation, and the check of its agreement with the kernel on ``device``: the
    largest height difference [m]."""
    water, extent = _water(n, device)

    def step():
        return numpy_surface(n, extent, water.waves)

    def check() -> dict:
        height, _ = step()
        kernel_height = water.at(TIME_S).positions.numpy()[..., 2]
        return {"max_abs_height_diff_m": float(np.abs(height - kernel_height).max())}

    return step, check
