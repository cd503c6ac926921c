"""The sun's disk vs a point sun: one frame of the default ocean by the flux-ratio map, same run.

The disk costs one refraction and one deposit per direction over it, so the frame's caustic
stages should take about ``sun.disk_samples`` times the point sun's. Median of a few frames after
a warm-up frame, device synchronised. ``python -m benchmarks.sun_disk --help``.
"""

from __future__ import annotations

import sys

from benchmarks.run import median_time

FULL = (256, 512, (8, 16, 32))
QUICK = (128, 256, (8,))


def measure(n: int, m: int, samples: int, device: str, repeats: int) -> dict:
    import warpcaustics as wc
    from warpcaustics.pipeline import Renderer

    rows = {}
    for name, diameter in (("point", 0.0), ("disk", 0.53)):
        scene = wc.load_scene(
            "configs/ocean.toml",
            {
                "water.resolution": n,
                "caustics.map_resolution": m,
                "sun.angular_diameter_deg": diameter,
                "sun.disk_samples": samples,
            },
        )
        renderer = Renderer(scene, device)
        renderer.render(0.0)  # warm-up
        rows[name] = median_time(lambda renderer=renderer: renderer.render(0.0), repeats, device)
    return {
        "water_n": n,
        "map_m": m,
        "disk_samples": samples,
        "point_frame_s": rows["point"],
        "disk_frame_s": rows["disk"],
        "disk_over_point": rows["disk"] / rows["point"],
    }


def run(quick: bool, device: str) -> dict:
    import warp as wp

    n, m, sample_counts = QUICK if quick else FULL
    repeats = 2 if quick else 3
    results = []
    for samples in sample_counts:
        row = measure(n, m, samples, device, repeats)
        results.append(row)
        print(
            f"sun disk     ocean N={n} M={m} | {samples:3d} directions | point "
            f"{row['point_frame_s'] * 1e3:8.1f} ms | disk {row['disk_frame_s'] * 1e3:8.1f} ms | "
            f"disk / point {row['disk_over_point']:5.1f}x",
            flush=True,
        )
    return {
        "benchmark": "sun_disk_vs_point",
        "device": device,
        "device_name": str(wp.get_device(device).name),
        "warp_version": wp.__version__,
        "repeats": repeats,
        "timing": "median wall time of a whole frame after a warm-up, device synchronised",
        "results": results,
    }


def main(argv: list[str] | None = None) -> int:
    from benchmarks.run import module_main

    return module_main(argv, "sun_disk", run, __doc__)


if __name__ == "__main__":
    sys.exit(main())
