"""Photon footprint splats vs texel deposits at equal photon count and time, same run.

``configs/ocean.toml`` (a point sun, rgb, no absorption) with photons deposited per texel and
spread over their footprints, at several photons per surface cell: the photon stage's time (emit,
trace, deposit; median after a warm-up frame, device synchronised) and the floor map's relative L1
against the converged photon map (footprints at ``CONVERGED`` photons per cell: the photon method's
own limit, so the figure is its noise) and against the beams' exact map (the triangle surface model
instead of the photons' bilinear patches). Printed with photons per texel; the ratio is the time
footprints need for the texel deposit's error at the default 4×4 per cell.
``python -m benchmarks.photon_splats --help``.
"""

from __future__ import annotations

import sys

from benchmarks.run import ROOT, device_record, median_time, point_sun_scene

FULL = {"n": 256, "m": 256, "subdivisions": (1, 2, 4, 8), "converged": 16}
QUICK = {"n": 32, "m": 32, "subdivisions": (1, 2, 4), "converged": 8}


def _scene(n: int, m: int, overrides: dict):
    return point_sun_scene(ROOT / "configs" / "ocean.toml", {
        "water.resolution": n, "caustics.map_resolution": m, "optics.wavelengths": "rgb",
        "optics.water_type": "none", **overrides})


def measure(size: dict, device: str, repeats: int) -> list[dict]:
    import warpcaustics as wc
    from warpcaustics.reference import relative_l1

    n, m = size["n"], size["m"]
    beams = wc.render(_scene(n, m, {"caustics.method": "beams"}), device=device).floor_irradiance
    converged = wc.render(_scene(n, m, {"caustics.method": "photons", "caustics.photon_splat": "footprint",
                                        "caustics.photon_subdivisions": size["converged"]}),
                          device=device).floor_irradiance
    rows = []
    for splat in ("texel", "footprint"):
        for s in size["subdivisions"]:
            scene = _scene(n, m, {"caustics.method": "photons", "caustics.photon_splat": splat,
                                  "caustics.photon_subdivisions": s})
            renderer = wc.Renderer(scene, device)
            result = renderer.render(0.0)  # warm-up
            stage = renderer.method.caustics[0]
            surface = renderer.water.at(0.0)

            def trace(stage=stage, surface=surface, renderer=renderer, scene=scene):
                stage.trace(surface, renderer.visible, scene.sun_direction, renderer.light.sun_irradiance)

            rows.append({"splat": splat, "subdivisions": s, "water_n": n, "map_m": m,
                         "photons_per_texel": (n * s) ** 2 / m**2,
                         "stage_s": median_time(trace, repeats, device),
                         "l1_vs_converged": relative_l1(result.floor_irradiance, converged),
                         "l1_vs_beams": relative_l1(result.floor_irradiance, beams)})
    return rows


def equal_error_ratio(rows: list[dict]) -> float:
    """Texel time at the default 4×4 per cell over the time of the cheapest footprint setting whose
    L1 against the converged map is no larger (a lower bound of the time ratio at equal error;
    nan if none is)."""
    texel = next(r for r in rows if r["splat"] == "texel" and r["subdivisions"] == 4)
    good = [r["stage_s"] for r in rows
            if r["splat"] == "footprint" and r["l1_vs_converged"] <= texel["l1_vs_converged"]]
    return float(texel["stage_s"] / min(good)) if good else float("nan")


def run(quick: bool, device: str) -> dict:
    import warp as wp

    from benchmarks.run import _cpu_name

    size = QUICK if quick else FULL
    repeats = 2 if quick else 5
    record = device_record(device)
    print(f"photon splat warp {wp.__version__} [{device}: {record['device_name']}] | cpu {_cpu_name()}",
          flush=True)
    rows = measure(size, device, repeats)
    for r in rows:
        print(f"photon splat {r['splat']:9s} {r['subdivisions']:2d}x{r['subdivisions']:<2d} per cell "
              f"{r['photons_per_texel']:6.1f} per texel | {r['stage_s'] * 1e3:8.1f} ms | L1 vs converged "
              f"{r['l1_vs_converged']:.4f} | vs beams {r['l1_vs_beams']:.4f}", flush=True)
    ratio = equal_error_ratio(rows)
    print(f"photon splat texel 4x4 per cell vs the cheapest footprint setting at least as accurate: "
          f"ratio {ratio:.2f}x (time at equal L1, a lower bound)", flush=True)
    return {"benchmark": "photon_splats", **record, "repeats": repeats,
            "converged_subdivisions": size["converged"],
            "timing": "median of the photon stage's trace() after a warm-up frame, device synchronised",
            "results": rows, "texel_4x4_time_over_footprint_time_at_equal_l1": ratio}


def main(argv: list[str] | None = None) -> int:
    from benchmarks.run import module_main

    return module_main(argv, "photon_splats", run, __doc__)


if __name__ == "__main__":
    sys.exit(main())
