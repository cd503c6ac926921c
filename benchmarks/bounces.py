"""Photons through a glass receiver (``caustics.bounces = 2``) vs the same scene with it opaque.

``configs/two_sided.toml`` (a glass ball in a pool, photons traced exactly on the BVH, no camera)
with the ball as glass (``receivers[0].ior = 1.9``, two more refractions per photon that meets it,
exact Fresnel, the tallies) and as an opaque receiver (``caustics.bounces = 1``): the median time of
the photon stage of a frame (emit, trace, deposit), after a warm-up frame, device synchronised.
``python -m benchmarks.bounces --help``.
"""

from __future__ import annotations

import sys

from benchmarks.run import ROOT, device_record, median_time, point_sun_scene

FULL = [(128, 4), (256, 4)]
QUICK = [(32, 2)]


def measure(n: int, subdivisions: int, device: str, repeats: int) -> dict:
    import warpcaustics as wc

    times = {}
    for name, extra in (("glass", {}), ("opaque", {"caustics.bounces": 1, "receivers": [
            {"mesh": "sphere", "scale": 0.8, "translate_m": [0.0, 0.0, -0.7]}]})):
        scene = point_sun_scene(ROOT / "configs" / "two_sided.toml", {
            "water.resolution": n, "caustics.photon_subdivisions": subdivisions, "camera.enabled": False,
            "optics.wavelengths": "rgb", **extra})
        renderer = wc.Renderer(scene, device)
        renderer.render(0.0)  # warm-up: JIT compile
        stage = renderer.method.caustics[0]
        surface = renderer.water.at(0.0)

        def trace(stage=stage, surface=surface, renderer=renderer, scene=scene):
            stage.trace(surface, renderer.visible, scene.sun_direction, renderer.light.sun_irradiance)

        times[name] = median_time(trace, repeats, device)
        times[f"{name}_photons"] = stage.weight.shape[0]
    return {"water_n": n, "subdivisions": subdivisions, "photons": times["glass_photons"],
            "glass_s": times["glass"], "opaque_s": times["opaque"],
            "glass_vs_opaque": times["glass"] / times["opaque"]}


def run(quick: bool, device: str) -> dict:
    import warp as wp

    from benchmarks.run import _cpu_name

    repeats = 2 if quick else 5
    record = device_record(device)
    print(f"bounces      warp {wp.__version__} [{device}: {record['device_name']}] | cpu {_cpu_name()}",
          flush=True)
    rows = []
    for n, s in QUICK if quick else FULL:
        r = measure(n, s, device, repeats)
        rows.append(r)
        print(f"bounces      N={n:4d} {r['photons']:9d} photons | glass ball {r['glass_s'] * 1e3:9.1f} ms | "
              f"opaque ball {r['opaque_s'] * 1e3:9.1f} ms | ratio {r['glass_vs_opaque']:5.2f}x", flush=True)
    return {"benchmark": "photon_bounces", **record, "repeats": repeats,
            "timing": "median of the photon stage's trace() (emit, trace, deposit) after a warm-up frame, "
                      "device synchronised", "results": rows}


def main(argv: list[str] | None = None) -> int:
    from benchmarks.run import module_main

    return module_main(argv, "bounces", run, __doc__)


if __name__ == "__main__":
    sys.exit(main())
