"""The camera above the water vs the camera under it, same scene, same run.

``configs/above_water.toml`` (the pots in a pool, beams, a point sun and no sky so that one light
pass is timed) with its camera above the water, and again with the camera of
``configs/pool_pots.toml`` under it, at the same image size: the median time of a frame's camera
stage (above: the rays to the water and below it, the beams' gather at the points the refracted
rays meet, ``camera.shaft_samples`` midpoint samples of the in-scattering per ray; under: the
G-buffer gather and the scan-plane shafts), after a warm-up frame, device synchronised. Then the
camera above the water lit by the photons (``caustics.method = "photons"``: their maps, and their
shafts from E⊥ on ``camera.shaft_samples`` horizontal slices of the water) against the beams, with
shafts and without: the camera stages and the frames, whose ratio is what the photons cost
against the beams for the same view.
``python -m benchmarks.above_water --help``.
"""

from __future__ import annotations

import sys

from benchmarks.run import ROOT, device_record, median_time, point_sun_scene

FULL = [(128, (320, 240), 16), (128, (320, 240), 32)]
QUICK = [(32, (64, 48), 8)]
UNDER = {"camera.position_m": [-1.7, -1.8, -0.4], "camera.look_at_m": [0.2, 0.2, -1.3],
         "camera.fov_deg": 65.0}


def measure(n: int, size: tuple[int, int], samples: int, device: str, repeats: int) -> dict:
    import warpcaustics as wc

    times = {}
    photons, no_shafts = {"caustics.method": "photons"}, {"caustics.shafts": False}
    for where, extra in (("above", {}), ("under", UNDER), ("above_photons", photons),
                         ("above_beams_no_shafts", no_shafts),
                         ("above_photons_no_shafts", {**no_shafts, **photons})):
        scene = point_sun_scene(ROOT / "configs" / "above_water.toml", {
            "water.resolution": n, "camera.width": size[0], "camera.height": size[1],
            "camera.shaft_samples": samples, "sky.model": "none", "sky.diffuse_fraction": 0.0,
            "optics.wavelengths": "rgb", **extra})
        renderer = wc.Renderer(scene, device)
        renderer.render(1.0)  # warm-up: JIT compile; the pool steps to 1 s once

        def frame(renderer=renderer):
            return renderer.render(1.0).timings_s["camera"]

        times[where] = median_time(frame, repeats, device)  # the frame's wall time
        camera_s = sorted(frame() for _ in range(repeats))[repeats // 2]
        times[f"{where}_camera"] = camera_s
    return {"water_n": n, "camera_px": list(size), "shaft_samples": samples,
            "above_frame_s": times["above"], "under_frame_s": times["under"],
            "above_camera_s": times["above_camera"], "under_camera_s": times["under_camera"],
            "camera_above_vs_under": times["above_camera"] / times["under_camera"],
            **{f"{where}_{what}_s": times[where if what == "frame" else f"{where}_camera"]
               for where in ("above_photons", "above_beams_no_shafts", "above_photons_no_shafts")
               for what in ("frame", "camera")},
            "frame_photons_vs_beams": times["above_photons"] / times["above"],
            "frame_photons_vs_beams_no_shafts":
                times["above_photons_no_shafts"] / times["above_beams_no_shafts"]}


def run(quick: bool, device: str) -> dict:
    import warp as wp

    from benchmarks.run import _cpu_name

    repeats = 2 if quick else 5
    record = device_record(device)
    print(f"above_water  warp {wp.__version__} [{device}: {record['device_name']}] | cpu {_cpu_name()}",
          flush=True)
    rows = []
    for n, size, samples in QUICK if quick else FULL:
        r = measure(n, size, samples, device, repeats)
        rows.append(r)
        print(f"above_water  N={n:4d} {size[0]}x{size[1]} samples={samples:3d} | camera above "
              f"{r['above_camera_s'] * 1e3:9.1f} ms | under {r['under_camera_s'] * 1e3:9.1f} ms | ratio "
              f"{r['camera_above_vs_under']:5.2f}x | frames {r['above_frame_s']:.2f} s / "
              f"{r['under_frame_s']:.2f} s",
              flush=True)
        for tag, photons, beams, ratio in (
                ("shafts", "above_photons", "above", "frame_photons_vs_beams"),
                ("no shafts", "above_photons_no_shafts", "above_beams_no_shafts",
                 "frame_photons_vs_beams_no_shafts")):
            beams_camera = r[f"{beams}_camera_s"]
            print(f"above_water  N={n:4d} {size[0]}x{size[1]} {tag:9s} | camera above, photons "
                  f"{r[f'{photons}_camera_s'] * 1e3:9.1f} ms | beams {beams_camera * 1e3:9.1f} ms | frames "
                  f"{r[f'{photons}_frame_s']:.2f} s / {r[f'{beams}_frame_s']:.2f} s | ratio {r[ratio]:5.2f}x",
                  flush=True)
    return {"benchmark": "above_water_camera", **record, "repeats": repeats,
            "timing": "median of the camera stage of a frame (RenderResult.timings_s['camera']) after a "
                      "warm-up "
                      "frame; frame: median wall time of Renderer.render",
            "results": rows}


def main(argv: list[str] | None = None) -> int:
    from benchmarks.run import module_main

    return module_main(argv, "above_water", run, __doc__)


if __name__ == "__main__":
    sys.exit(main())
