"""The sun's disk and the sky vs a point sun: one frame of the default ocean by the flux-ratio
map and by the photons, same run.

For the flux-ratio map the disk costs one refraction and one deposit per direction over it, so the
frame's caustic stages should take about ``sun.disk_samples`` times the point sun's; a uniform sky
over as many directions adds as many passes, each with its own crest-shading march. The photons
run a pass per disk direction and per sky direction too. The eikonal grid (64³) solves once more
per sky direction. Median of a few frames after a warm-up frame, device synchronised.
``python -m benchmarks.sun_disk --help``.
"""

from __future__ import annotations

import sys

from benchmarks.run import CONFIGS, device_record, median_time, point_sun_scene

FULL = (256, 512, (8, 16, 32))
QUICK = (128, 256, (8,))
EIKONAL = {"caustics.method": "eikonal", "caustics.eikonal_resolution": 64}


def measure(n: int, m: int, samples: int, device: str, repeats: int) -> dict:
    from warpcaustics.pipeline import Renderer

    rows = {}
    cases = (
        ("point", {}),
        ("disk", {"sun.angular_diameter_deg": 0.53, "sun.disk_samples": samples}),
        ("sky", {"sky.model": "uniform", "sky.diffuse_fraction": 0.2, "sky.directions": samples}),
        ("photons_point", {"caustics.method": "photons"}),
        ("photons_disk", {"caustics.method": "photons", "sun.angular_diameter_deg": 0.53,
                          "sun.disk_samples": samples}),
        ("photons_sky", {"caustics.method": "photons", "sky.model": "uniform", "sky.diffuse_fraction": 0.2,
                         "sky.directions": samples}),
        ("eikonal_point", EIKONAL),
        ("eikonal_sky", {**EIKONAL, "sky.model": "uniform", "sky.diffuse_fraction": 0.2,
                         "sky.directions": samples}),
    )
    for name, extra in cases:
        scene = point_sun_scene(
            CONFIGS / "ocean.toml", {"water.resolution": n, "caustics.map_resolution": m, **extra}
        )
        renderer = Renderer(scene, device)
        renderer.render(0.0)  # warm-up
        rows[name] = median_time(lambda renderer=renderer: renderer.render(0.0), repeats, device)
    return {
        "water_n": n,
        "map_m": m,
        "directions": samples,
        "point_frame_s": rows["point"],
        "disk_frame_s": rows["disk"],
        "disk_over_point": rows["disk"] / rows["point"],
        "sky_frame_s": rows["sky"],
        "sky_over_point": rows["sky"] / rows["point"],
        "photons_point_frame_s": rows["photons_point"],
        "photons_disk_frame_s": rows["photons_disk"],
        "photons_disk_over_point": rows["photons_disk"] / rows["photons_point"],
        "photons_sky_frame_s": rows["photons_sky"],
        "photons_sky_over_point": rows["photons_sky"] / rows["photons_point"],
        "eikonal_point_frame_s": rows["eikonal_point"],
        "eikonal_sky_frame_s": rows["eikonal_sky"],
        "eikonal_sky_over_point": rows["eikonal_sky"] / rows["eikonal_point"],
    }


def run(quick: bool, device: str) -> dict:
    n, m, sample_counts = QUICK if quick else FULL
    repeats = 2 if quick else 3
    results = []
    for samples in sample_counts:
        row = measure(n, m, samples, device, repeats)
        results.append(row)
        print(
            f"sun disk     ocean N={n} M={m} | {samples:3d} directions | point "
            f"{row['point_frame_s'] * 1e3:8.1f} ms | disk {row['disk_frame_s'] * 1e3:8.1f} ms | "
            f"disk / point {row['disk_over_point']:5.1f}x | sky {row['sky_frame_s'] * 1e3:8.1f} ms | "
            f"sky / point {row['sky_over_point']:5.1f}x | photons: point "
            f"{row['photons_point_frame_s'] * 1e3:8.1f} ms, "
            f"disk / point {row['photons_disk_over_point']:5.2f}x, "
            f"sky / point {row['photons_sky_over_point']:5.1f}x | eikonal 64³: point "
            f"{row['eikonal_point_frame_s'] * 1e3:8.1f} ms, "
            f"sky / point {row['eikonal_sky_over_point']:5.1f}x",
            flush=True,
        )
    return {
        "benchmark": "sun_disk_and_sky_vs_point",
        **device_record(device),
        "repeats": repeats,
        "timing": "median wall time of a whole frame after a warm-up, device synchronised",
        "results": results,
    }


def main(argv: list[str] | None = None) -> int:
    from benchmarks.run import module_main

    return module_main(argv, "sun_disk", run, __doc__)


if __name__ == "__main__":
    sys.exit(main())
