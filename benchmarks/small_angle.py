"""The small-angle scattering mode against single scattering on the same frame.

``python -m benchmarks.small_angle`` (part of ``python -m benchmarks.run``; ``--quick``: 256² over 8
m, 4 sky and 2 disk directions, walks of 16384 photons): the field set-up
(``configs/field/gernez2009.toml``: a 1024² JONSWAP sea over 32 m, 16 sun-disk and 16 sky
directions, a 1 m window of 512² texels, 510 nm) rendered with ``optics.scattering = "single"`` and
``"small_angle"`` (the scattered light of each pass by the small-angle transfer, its mean from a
random walk at one photon per cell), warm frames, median of ``repeats``, one core. Prints the time
of each and their ratio; the record says where the small-angle time goes (the walk, the transfer's
FFTs, the sky's per-direction read-backs). A third frame, ``small_angle`` with the window taken
whole as periodic (as before 2026-12-05: no coarse map of the patch), gives the cost of the window's
large scales from the whole patch (each pass's quads splatted on a coarse map, its FFT transfer and
the bilinear read at the window's texels). A fourth, ``small_angle`` with ``optics.beam_spread =
"walk"`` (the column's beam spread function from a walk of a pencil beam per light direction instead
of Wells's closed form), is timed warm like the others — its walks and multipliers are kept from the
first frame — and its first frame, which walks them, is reported too. A fifth, ``small_angle`` with
the sky in cones (``sky.sampling = "cones"``: each sky direction's map spread over its cell of the
sky before its transfer), gives the cones' cost against the point directions, warm and first frame
(which computes the cells' multipliers). Last, the phase function's spread table (the Hankel
transform behind the transfer, computed once a process): computed, against read back from the
cache on disk that keeps it between processes (``warpcaustics/io/table_cache.py``, a folder of its
own here).
"""

from __future__ import annotations

import sys
import time

from benchmarks.field_budget import BEFORE, QUICK_LIGHT  # BEFORE: the set-up as these figures were measured
from benchmarks.run import ROOT, device_record, median_time

FULL = {}
QUICK = {"water.resolution": 256, "water.extent_m": 8.0, "caustics.map_resolution": 256, **QUICK_LIGHT}


def run(quick: bool, device: str) -> dict:
    import warpcaustics as wc

    repeats = 2 if quick else 3
    overrides = {"optics.mc_samples": 1, "floor.albedo": 0.0, **(QUICK if quick else FULL)}
    from warpcaustics.caustics import fluxratio

    times, stages = {}, {}
    first = {}
    for mode, scattering in (("single", "single"), ("small_angle", "small_angle"),
                             ("periodic_window", "small_angle"), ("walked_spread", "small_angle"),
                             ("sky_cones", "small_angle")):
        spread = "walk" if mode == "walked_spread" else "wells"
        sampling = "cones" if mode == "sky_cones" else "stratified"
        scene = wc.load_scene(ROOT / "configs/field/gernez2009.toml",
                              {**BEFORE, **overrides, "optics.scattering": scattering,
                               "optics.beam_spread": spread, "sky.sampling": sampling})
        coarse = fluxratio.coarse_resolution
        if mode == "periodic_window":  # the baseline: no coarse map, the window taken whole as periodic
            fluxratio.coarse_resolution = lambda cfg, periodic: 0
        try:
            renderer = wc.Renderer(scene, device=device)
        finally:
            fluxratio.coarse_resolution = coarse
        start = time.perf_counter()
        renderer.render(0.0)  # warm-up (and the phase function's spread table, or the walked spreads)
        first[mode] = time.perf_counter() - start
        times[mode] = median_time(lambda r=renderer: r.render(0.5), repeats, device)
        result = renderer.render(0.5)
        stages[mode] = {k: round(v, 4) for k, v in result.timings_s.items()}
    n = scene.config.water.resolution
    row = {"water_n": n, "map": scene.config.caustics.map_resolution, "single_s": times["single"],
           "small_angle_s": times["small_angle"], "ratio": times["small_angle"] / times["single"],
           "periodic_window_s": times["periodic_window"],
           "coarse_ratio": times["small_angle"] / times["periodic_window"],
           "coarse_texels": fluxratio.coarse_resolution(scene.config, True),
           "walked_spread_s": times["walked_spread"],
           "walked_spread_ratio": times["walked_spread"] / times["small_angle"],
           "sky_cones_s": times["sky_cones"], "sky_cones_ratio": times["sky_cones"] / times["small_angle"],
           "first_frame_s": {k: round(v, 2) for k, v in first.items()}, "stages_s": stages}
    print(f"small_angle  field frame N={n} | single {times['single']:.2f} s | small_angle "
          f"{times['small_angle']:.2f} s | ×{row['ratio']:.2f} | the window periodic (no coarse map) "
          f"{times['periodic_window']:.2f} s: the coarse map ×{row['coarse_ratio']:.2f} | walked spread "
          f"{times['walked_spread']:.2f} s (×{row['walked_spread_ratio']:.2f} of Wells's; first frame "
          f"{first['walked_spread']:.1f} s against {first['small_angle']:.1f} s) | sky in cones "
          f"{times['sky_cones']:.2f} s (×{row['sky_cones_ratio']:.2f} of point directions; first frame "
          f"{first['sky_cones']:.1f} s)", flush=True)
    row["spread_table"] = spread_table_cost(scene.config.optics)
    return {"benchmark": "small_angle_scattering", **device_record(device), "repeats": repeats,
            "results": [row]}


def spread_table_cost(optics) -> dict:
    """Seconds to compute the configured phase function's spread table and to read it from the cache."""
    import os
    import tempfile

    from warpcaustics.io.table_cache import CACHE_ENV
    from warpcaustics.optics.phase import phase_quadrature
    from warpcaustics.optics.small_angle import spread_from_phase

    quadrature = phase_quadrature(optics.phase_function, optics.hg_g, optics.petzold_station.value)
    before = os.environ.get(CACHE_ENV)
    with tempfile.TemporaryDirectory() as folder:
        os.environ[CACHE_ENV] = folder
        try:
            start = time.perf_counter()
            spread_from_phase(*quadrature)  # computed and written
            computed = time.perf_counter() - start
            start = time.perf_counter()
            spread_from_phase(*quadrature)
            read = time.perf_counter() - start
        finally:
            if before is None:
                os.environ.pop(CACHE_ENV)
            else:
                os.environ[CACHE_ENV] = before
    print(f"small_angle  the spread table ({optics.phase_function.value}): computed {computed:.2f} s | from "
          f"the cache {read * 1e3:.1f} ms | ×{computed / read:.0f}", flush=True)
    return {"computed_s": round(computed, 3), "cached_s": round(read, 5), "ratio": round(computed / read, 1)}


def main(argv: list[str] | None = None) -> int:
    from benchmarks.run import module_main

    return module_main(argv, "small_angle", run, __doc__)


if __name__ == "__main__":
    sys.exit(main())
