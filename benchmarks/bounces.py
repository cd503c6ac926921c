"""Light through a glass receiver (``caustics.bounces = 2``) vs the same scene with it opaque, by
photons and by beams.

``configs/two_sided.toml`` (a glass ball in a pool, no camera) with the ball as glass
(``receivers[0].ior = 1.9``: photons traced exactly on the BVH make two more refractions with exact
Fresnel where they meet it; beams that meet it are followed past it as bounced beams, cut into
sub-beams across its rim) and as an opaque receiver (``caustics.bounces = 1``): the median time of
the caustic stage of a frame (photons: emit, trace, deposit; beams: build, bounce, bin, gather the
floor and the faces), after a warm-up frame, device synchronised.
``python -m benchmarks.bounces --help``.
"""

from __future__ import annotations

import sys

from benchmarks.run import ROOT, device_record, median_time, point_sun_scene

FULL = [("photons", 128, 4), ("photons", 256, 4), ("beams", 64, 0), ("beams", 128, 0)]
QUICK = [("photons", 32, 2), ("beams", 32, 0)]


def measure(method: str, n: int, subdivisions: int, device: str, repeats: int) -> dict:
    import warpcaustics as wc

    times = {}
    for name, extra in (("glass", {}), ("opaque", {"caustics.bounces": 1, "receivers": [
            {"mesh": "sphere", "scale": 0.8, "translate_m": [0.0, 0.0, -0.7]}]})):
        sub = {"caustics.photon_subdivisions": subdivisions} if subdivisions else {}
        scene = point_sun_scene(ROOT / "configs" / "two_sided.toml", {
            "caustics.method": method, "water.resolution": n, "camera.enabled": False,
            "optics.wavelengths": "rgb", **sub, **extra})
        renderer = wc.Renderer(scene, device)
        renderer.render(0.0)  # warm-up: JIT compile
        stage = renderer.method.caustics[0]
        surface = renderer.water.at(0.0)

        def trace(stage=stage, surface=surface, renderer=renderer, scene=scene):
            stage.trace(surface, renderer.visible, scene.sun_direction, renderer.light.sun_irradiance)

        times[name] = median_time(trace, repeats, device)
        times[f"{name}_items"] = stage.primary_slots if method == "beams" else stage.weight.shape[0]
        if method == "beams" and name == "glass":
            times["bounced"] = stage.bounces.used
    return {"method": method, "water_n": n, "subdivisions": subdivisions, "items": times["glass_items"],
            "bounced_slots": times.get("bounced", 0), "glass_s": times["glass"], "opaque_s": times["opaque"],
            "glass_vs_opaque": times["glass"] / times["opaque"]}


def run(quick: bool, device: str) -> dict:
    import warp as wp

    from benchmarks.run import _cpu_name

    repeats = 2 if quick else 5
    record = device_record(device)
    print(f"bounces      warp {wp.__version__} [{device}: {record['device_name']}] | cpu {_cpu_name()}",
          flush=True)
    rows = []
    for method, n, s in QUICK if quick else FULL:
        r = measure(method, n, s, device, repeats)
        rows.append(r)
        print(f"bounces      {method:7s} N={n:4d} {r['items']:9d} {method} | "
              f"glass ball {r['glass_s'] * 1e3:9.1f} ms | opaque ball {r['opaque_s'] * 1e3:9.1f} ms | "
              f"ratio {r['glass_vs_opaque']:5.2f}x", flush=True)
    return {"benchmark": "bounces", **record, "repeats": repeats,
            "timing": "median of the caustic stage's trace() (photons: emit, trace, deposit; beams: build, "
                      "bounce, bin, gather) after a warm-up frame, device synchronised", "results": rows}


def main(argv: list[str] | None = None) -> int:
    from benchmarks.run import module_main

    return module_main(argv, "bounces", run, __doc__)


if __name__ == "__main__":
    sys.exit(main())
