"""Crest shading: the sweep and the march with blocks against the step-by-step march, same run:
``python -m benchmarks.shading [--quick] [--device cpu]``.

Every light direction of a frame (the sun's disk, each sky direction) needs the crests' shading of
every surface vertex. The march goes from every vertex towards the light in half-cell steps until
the ray clears the highest crest: at a low sun on a fine grid that is hundreds of lookups per
vertex (N³ work at a fixed patch size), and the field comparisons' sky passes were most of their
frames. Its kernel steps over whole blocks of cells (64 and 8 on a side) where the ray already runs
above the block's highest vertex (``march``; walled water still marches); periodic seas are now
shaded by a sweep down the lines of a lattice aligned with the light's azimuth, a few lookups per
vertex at any sun (``sweep``, ``kernels/optics/horizon.py``). The baseline is the march as it was,
kept here (``stepwise_visibility``; ``tests/test_shading.py`` checks the march with blocks agrees with
it to the bit, ``tests/test_horizon.py`` that the sweep is as close to the surface's shading). Sea:
``configs/field/gernez2009.toml``'s (Elfouhaily, 5 m/s) on 8 m at N², as the field budget's fine
rows; the blocks are built once a frame and timed with the march, the sweep's lattice allocated
once. Median of a few calls after a warm-up, device synchronised.
"""

from __future__ import annotations

import sys

import numpy as np
import warp as wp

from warpcaustics.kernels.optics.refract import surface_height

from benchmarks.run import CONFIGS, device_record, interleaved_times

FULL = ((512, 1024, 2048), (20.0, 60.0, 80.0))
QUICK = ((256,), (20.0, 80.0))


@wp.kernel
def stepwise_visibility(positions: wp.array2d[wp.vec3], sun_dir: wp.vec3, extent_m: float, periodic: int,
                        z_range: wp.array[wp.float32], visible: wp.array2d[wp.float32]):
    """The crest-shading march before the height blocks: every half-cell step looked up."""
    iy, ix = wp.tid()
    p = positions[iy, ix]
    horizontal = wp.sqrt(sun_dir[0] * sun_dir[0] + sun_dir[1] * sun_dir[1])
    visible[iy, ix] = 1.0
    if horizontal < 1.0e-6:
        return
    n = positions.shape[0]
    cell = extent_m / float(n)
    step = 0.5 * cell / horizontal
    steps = int(wp.ceil((z_range[1] - p[2]) / (sun_dir[2] * step))) + 1
    tolerance = 1.0e-4 * cell
    for i in range(1, steps + 1):
        q = p + (float(i) * step) * sun_dir
        if periodic == 0 and (wp.abs(q[0]) > 0.5 * extent_m - 0.5 * cell
                              or wp.abs(q[1]) > 0.5 * extent_m - 0.5 * cell):
            return
        if surface_height(positions, extent_m, q[0], q[1]) > q[2] + tolerance:
            visible[iy, ix] = 0.0
            return


def stepwise(surface, sun_dir, highest_m: float, device: str) -> wp.array2d:
    """(N, N) visibility by the step-by-step march (the baseline)."""
    n = surface.resolution
    out = wp.empty((n, n), dtype=wp.float32, device=device)
    z_range = wp.array(np.array([0.0, highest_m], np.float32), dtype=wp.float32, device=device)
    wp.launch(stepwise_visibility, dim=(n, n),
              inputs=[surface.positions, wp.vec3(*np.asarray(sun_dir, np.float32)), float(surface.extent_m),
                      int(surface.periodic), z_range], outputs=[out], device=device)
    return out


def direction(zenith_deg: float, azimuth_deg: float = 30.0) -> np.ndarray:
    z, a = np.radians(zenith_deg), np.radians(azimuth_deg)
    return np.array([np.sin(z) * np.cos(a), np.sin(z) * np.sin(a), np.cos(z)])


def field_surface(n: int, device: str):
    """The field set-up's sea on 8 m at n² (t = 0) and its (lowest, highest) heights."""
    import warpcaustics as wc
    from warpcaustics.optics.refraction import height_range
    from warpcaustics.pipeline import Renderer

    scene = wc.load_scene(CONFIGS / "field/gernez2009.toml", {"water.resolution": n, "water.extent_m": 8.0})
    surface = Renderer(scene, device).water.at(0.0)
    return surface, height_range(surface, device)


def measure(n: int, zenith: float, device: str, repeats: int) -> dict:
    """One row: the sweep and the march with blocks (built inside, as a caller without a frame's
    blocks does) against the step-by-step baseline, on the field sea at n² over 8 m."""
    from warpcaustics.optics import refraction

    surface, (lowest, highest) = field_surface(n, device)
    d = direction(zenith)
    lattice = refraction.horizon_buffer(n, device)
    sweep = refraction.sweep_visibility
    sides = {"sweep": (lambda: sweep(surface, d, lowest, highest, device, horizon=lattice), 1),
             "blocks": (lambda: refraction.march_visibility(surface, d, highest, device), 1),
             "stepwise": (lambda: stepwise(surface, d, highest, device), 1),
             "build": (lambda: refraction.height_blocks(surface, device), 1)}
    march = sides["blocks"][0]().numpy()
    same = bool(np.array_equal(march, sides["stepwise"][0]().numpy()))
    differ = float(np.mean(sides["sweep"][0]().numpy() != march))
    times = {k: float(np.median(v)) for k, v in interleaved_times(sides, repeats, device).items()}
    return {"water_n": n, "extent_m": 8.0, "sun_zenith_deg": zenith, "sweep_s": times["sweep"],
            "blocks_s": times["blocks"], "stepwise_s": times["stepwise"], "build_s": times["build"],
            "same_visibility": same, "sweep_differs": differ, "speedup": times["stepwise"] / times["blocks"],
            "sweep_vs_blocks": times["blocks"] / times["sweep"],
            "sweep_vs_stepwise": times["stepwise"] / times["sweep"]}


def run(quick: bool, device: str) -> dict:
    sizes, zeniths = QUICK if quick else FULL
    repeats = 3
    results = []
    for n in sizes:
        for zenith in zeniths:
            row = measure(n, zenith, device, repeats)
            results.append(row)
            print(f"shading      field sea N={n:5d} over 8 m | sun {zenith:4.0f}° from the zenith | stepwise "
                  f"{row['stepwise_s'] * 1e3:9.1f} ms | blocks {row['blocks_s'] * 1e3:8.1f} ms (their build "
                  f"{row['build_s'] * 1e3:6.1f} ms, same: {row['same_visibility']}) | sweep "
                  f"{row['sweep_s'] * 1e3:8.1f} ms ({row['sweep_differs']:.2%} of vertices differ from the "
                  f"march) | sweep {row['sweep_vs_blocks']:5.1f}x the blocks, "
                  f"{row['sweep_vs_stepwise']:5.1f}x stepwise",
                  flush=True)
    return {"benchmark": "shading_sweep_and_blocks_vs_stepwise", **device_record(device), "repeats": repeats,
            "timing": "median wall time of one visibility pass (blocks built inside, the sweep's lattice "
                      "allocated once), device synchronised", "results": results}


def main(argv: list[str] | None = None) -> int:
    from benchmarks.run import module_main

    return module_main(argv, "shading", run, __doc__)


if __name__ == "__main__":
    sys.exit(main())
