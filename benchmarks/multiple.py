"""Multiple-scattering random walk: photons per second, and the flux-ratio map of the same frame.

``configs/ocean.toml`` in coastal water, 3 m deep, rgb bands: the walk's wall time (median after a
warm-up frame, device synchronised) and its photon rate, beside the single-scattering flux-ratio
map's time on the same surface, and beside the same walk without its boundaries (a transparent
top and a black floor, the walk before issue 32): what the surface's Fresnel reflection and the
floor's albedo (this config's 0.6/0.55/0.45) cost. ``python -m benchmarks.multiple --help``.
"""

from __future__ import annotations

import sys

from benchmarks.run import CONFIGS, device_record, median_time, point_sun_scene

FULL = [(128, 4), (256, 4)]
QUICK = [(64, 4)]


def measure(n: int, samples: int, device: str, repeats: int) -> dict:
    from warpcaustics.optics.refraction import height_range
    from warpcaustics.pipeline import Renderer

    from benchmarks.sunmap import flux_ratio_pass

    scene = point_sun_scene(
        CONFIGS / "ocean.toml",
        {
            "water.resolution": n,
            "caustics.map_resolution": 2 * n,
            "optics.wavelengths": "rgb",
            "optics.water_type": "coastal_ocean",
            "floor.depth_m": 3.0,
            "optics.scattering": "multiple",
            "optics.mc_samples": samples,
        },
    )
    renderer = Renderer(scene, device)
    result = renderer.render(0.0)  # warm-up
    surface = renderer.water.at(0.0)
    _, highest = height_range(surface, device)
    from warpcaustics.caustics.multiple import MultipleScattering

    walk_s = median_time(lambda: renderer.method.multiple.run(surface, renderer.visible), repeats, device)
    light = renderer.light
    open_walk = MultipleScattering(scene.config, light.sun_directions, float(light.group_ior[0]),
                                   light.sun_irradiance, light.optics.absorption_per_m,
                                   light.optics.scattering_per_m, device, surface_reflects=False)
    open_walk.run(surface, renderer.visible)  # warm-up
    open_s = median_time(lambda: open_walk.run(surface, renderer.visible), repeats, device)
    flux_ratio_s = median_time(flux_ratio_pass(renderer, surface, highest), repeats, device)
    photons = result.multiple_scattering_stats["photons"]
    return {
        "water_n": n,
        "samples_per_cell_side": samples,
        "photons": photons,
        "walk_s": walk_s,
        "photons_per_s": photons / walk_s,
        "fluxratio_s": flux_ratio_s,
        "walk_over_fluxratio": walk_s / flux_ratio_s,
        "walk_without_boundaries_s": open_s,
        "boundaries_cost": walk_s / open_s,
    }


def run(quick: bool, device: str) -> dict:
    repeats = 2 if quick else 3
    rows = []
    for n, s in QUICK if quick else FULL:
        row = measure(n, s, device, repeats)
        rows.append(row)
        print(
            f"multiple     ocean N={n:4d} s={s} | {row['photons'] / 1e6:6.2f} M photons in "
            f"{row['walk_s']:7.3f} s = {row['photons_per_s'] / 1e6:6.2f} M photons/s | flux ratio "
            f"{row['fluxratio_s'] * 1e3:7.1f} ms | without boundaries "
            f"{row['walk_without_boundaries_s']:6.3f} s"
            f" (boundaries ×{row['boundaries_cost']:.2f})",
            flush=True,
        )
    return {
        "benchmark": "multiple_scattering_walk",
        **device_record(device),
        "repeats": repeats,
        "results": rows,
    }


def main(argv: list[str] | None = None) -> int:
    from benchmarks.run import module_main

    return module_main(argv, "multiple", run, __doc__)


if __name__ == "__main__":
    sys.exit(main())
