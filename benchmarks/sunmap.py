"""Sun-map caustics (GPU Gems ch. 2) per frame vs the flux-ratio floor map, same scene, same run.

For the default ocean (``configs/ocean.toml``, the surface grid path) and the procedural waves
(``configs/procedural.toml``, the analytic path) at the same water N and map M: the median wall
time of the sun-map stage (one backward ray per texel, §2.3–2.4), of its per-pixel variant
(§2.5: the gradient above each texel, no search for the surface, no Snell's law) and of the
flux-ratio map (refraction of every vertex, then the footprint deposits), each after a warm-up,
device synchronised.
``python -m benchmarks.sunmap --help``.
"""

from __future__ import annotations

import sys

from benchmarks.run import ROOT, device_record, median_time, point_sun_scene

FULL = [(256, 512), (512, 1024)]
QUICK = [(128, 256)]
SCENES = ("configs/ocean.toml", "configs/procedural.toml")


def measure(config: str, n: int, m: int, device: str, repeats: int) -> dict:
    """Times of the two floor maps of one frame (the water surface is computed once, outside)."""
    from warpcaustics.pipeline import Renderer
    scene = point_sun_scene(ROOT / config, {"caustics.method": "sunmap", "water.resolution": n,
                                            "caustics.map_resolution": m})
    renderer = Renderer(scene, device)
    result = renderer.render(0.5)  # warm-up: JIT compile, first launches
    surface = renderer.water.at(0.5)
    flux_ratio = flux_ratio_pass(renderer, surface, float(surface.positions.numpy()[..., 2].max()))

    stage = renderer.method.approximate

    def sun_map():
        stage.run(surface, renderer.water, 0.5)

    fluxratio_s = median_time(flux_ratio, repeats, device)
    sunmap_s = median_time(sun_map, repeats, device)
    stage.per_pixel = True  # §2.5's variant on the same surface and buffers
    sun_map()  # warm-up: its kernels compile
    per_pixel_s = median_time(sun_map, repeats, device)
    from warpcaustics.io.comparison import map_correlation, relative_l1

    return {"config": config, "water_n": n, "map_m": m, "bins": len(result.wavelengths_nm),
            "fluxratio_s": fluxratio_s, "sunmap_s": sunmap_s,
            "speedup_sunmap_vs_fluxratio": fluxratio_s / sunmap_s, "per_pixel_s": per_pixel_s,
            "speedup_per_pixel_vs_per_vertex": sunmap_s / per_pixel_s,
            "relative_l1_sunmap_vs_fluxratio": relative_l1(result.floor_irradiance,
                                                           result.comparison.floor_irradiance),
            "correlation_sunmap_vs_fluxratio": map_correlation(result.floor_irradiance,
                                                               result.comparison.floor_irradiance,
                                                               result.bin_widths_nm)}


def flux_ratio_pass(renderer, surface, highest_m: float):
    """A function that draws the flux-ratio map of ``surface`` with the renderer's buffers (the
    baseline the approximate methods are timed against)."""
    from warpcaustics.optics.refraction import refract_to_floor, sun_visibility

    scene = renderer.scene
    device = renderer.device
    visible = sun_visibility(surface, scene.sun_direction, highest_m, device, out=renderer.visible)

    def flux_ratio():
        refracted = refract_to_floor(surface, visible, renderer.light.group_ior, scene.sun_direction,
                                     -scene.config.floor.depth_m, device, out=renderer.method.refracted)
        renderer.method.floor.run(surface, refracted, scene.sun_direction)

    return flux_ratio


def run(quick: bool, device: str) -> dict:
    import warp as wp

    from benchmarks.run import _cpu_name

    repeats = 2 if quick else 5
    record = device_record(device)
    wp_name = record["device_name"]
    print(f"sunmap       warp {wp.__version__} [{device}: {wp_name}] | cpu {_cpu_name()}", flush=True)
    rows = []
    for config in SCENES:
        for n, m in QUICK if quick else FULL:
            row = measure(config, n, m, device, repeats)
            rows.append(row)
            print(f"sunmap       {config:24s} N={n:5d} M={m:5d} K={row['bins']:3d} | sun map "
                  f"{row['sunmap_s'] * 1e3:9.2f} ms | flux ratio {row['fluxratio_s'] * 1e3:9.2f} ms | "
                  f"ratio {row['speedup_sunmap_vs_fluxratio']:6.1f}x | per pixel "
                  f"{row['per_pixel_s'] * 1e3:8.2f} ms ({row['speedup_per_pixel_vs_per_vertex']:4.2f}x per "
                  "vertex's speed) | L1 vs flux ratio "
                  f"{row['relative_l1_sunmap_vs_fluxratio']:.2f}, correlation "
                  f"{row['correlation_sunmap_vs_fluxratio']:.2f}", flush=True)
    return {"benchmark": "sunmap_vs_fluxratio", **record, "repeats": repeats,
            "timing": "median wall time of each floor-map stage on one surface, after a warm-up frame, "
                      "device synchronised",
            "results": rows}


def main(argv: list[str] | None = None) -> int:
    from benchmarks.run import module_main

    return module_main(argv, "sunmap", run, __doc__)


if __name__ == "__main__":
    sys.exit(main())
