"""The cost of the waves longer than the field scene's patch: ``python -m benchmarks.long_waves``.

``warpcaustics field gernez2009`` renders, beside each frame of the scene (``configs/field/
gernez2009.toml``: 2048² cells over 8 m, a 1 m window of 512² texels, 8 sun-disk and 16 sky
directions in cones, small-angle scattering), a frame of a 128 m patch of the waves longer than 8 m
alone (``--long-waves``: 256² cells, the whole patch on 256² texels, ``water.shortest_wave_m`` = 8).
This times a warm frame of each at an 85° sun (the paper's diffuse share), one core, and prints the
long waves' frame over the scene's: what the comparison pays for them. The statistics' windows of
the whole patch (``patch_windows``, from the coarse map the window's light is computed beside) are
timed too, against the statistics without them, on this frame (one band) and on a frame of the
Darecki profile's set-up (``configs/field/darecki2011.toml`` at 0.86 m, 8 m on 256² cells: a
0.4 m window of 400² texels, each of its three bands' windows too, on coarse texels the windows'
edges cross). ``--quick``: the scene on 256² cells, 4 sky cones, 2 disk directions, the beam spread's walks
of 16384 photons (keeps the script running).
"""

from __future__ import annotations

import sys

from benchmarks.field_budget import QUICK_LIGHT, SKY_16_CONES  # the sky as the figures were measured
from benchmarks.run import ROOT, device_record, median_time

SCENE = ROOT / "configs/field/gernez2009.toml"
POINT = {**SKY_16_CONES, "sun.elevation_deg": 5.0, "sky.diffuse_fraction": 0.85}
"""An 85° sun at the paper's diffuse share (``jerlov.gernez2009_diffuse_share``)."""

QUICK = {"water.resolution": 256, "caustics.map_resolution": 256, **QUICK_LIGHT}

DARECKI = ROOT / "configs/field/darecki2011.toml"
DARECKI_FRAME = {"floor.depth_m": 0.86, "water.extent_m": 8.0, "water.resolution": 256}
"""A frame whose statistics are per band, with 20 windows a side on 128 coarse texels."""


def statistics_cost(result, stats_cfg, repeats: int) -> tuple[float, float]:
    """(seconds with the patch's windows, without them) of one frame's statistics."""
    from warpcaustics.batch.stats import frame_statistics

    with_windows = median_time(lambda: frame_statistics(result, stats_cfg), repeats)
    coarse = result.coarse_floor_irradiance
    result.coarse_floor_irradiance = None  # the statistics without the patch's windows
    try:
        without = median_time(lambda: frame_statistics(result, stats_cfg), repeats)
    finally:
        result.coarse_floor_irradiance = coarse
    return with_windows, without


def run(quick: bool, device: str) -> dict:
    import warpcaustics as wc
    from warpcaustics.batch.field.common import LONG_WAVES_OVERRIDES
    from warpcaustics.batch.field.gernez2009 import LONG_WAVES_EXTENT_M
    repeats = 2 if quick else 3
    scene_overrides = {**POINT, **(QUICK if quick else {})}
    long_overrides = {**POINT, **LONG_WAVES_OVERRIDES, "water.extent_m": LONG_WAVES_EXTENT_M,
                      "water.shortest_wave_m": 8.0, "caustics.map_extent_m": 0.0,
                      **(QUICK_LIGHT if quick else {})}
    times = {}
    results = {}
    for name, overrides in (("scene", scene_overrides), ("long_waves", long_overrides)):
        scene = wc.load_scene(SCENE, overrides)
        renderer = wc.Renderer(scene, device=device)
        renderer.render(0.0)  # warm-up: the kernels, the spreads and the cells' multipliers
        times[name] = median_time(lambda r=renderer: r.render(0.5), repeats, device)
        results[name] = (renderer.render(1.0), scene.config.stats)
    with_windows, without = statistics_cost(*results["scene"], repeats)
    darecki = wc.load_scene(DARECKI, {**DARECKI_FRAME, **(QUICK_LIGHT if quick else {})})
    per_band = statistics_cost(wc.render(darecki, device=device), darecki.config.stats, repeats)
    ratio = times["long_waves"] / times["scene"]
    print(f"scene frame {times['scene']:.2f} s, long waves' frame {times['long_waves']:.2f} s: "
          f"x{ratio:.3f} of the scene's")
    print(f"statistics {with_windows * 1e3:.1f} ms with the patch's windows, {without * 1e3:.1f} ms without: "
          f"x{with_windows / without:.2f}")
    print(f"Darecki's per-band statistics {per_band[0] * 1e3:.1f} ms with the patch's windows, "
          f"{per_band[1] * 1e3:.1f} ms without: x{per_band[0] / per_band[1]:.2f}")
    return {"benchmark": "long_waves", **device_record(device), "quick": quick, "repeats": repeats,
            "scene_overrides": scene_overrides, "long_waves_overrides": long_overrides,
            "seconds": times, "long_over_scene": ratio,
            "statistics_seconds": {"with_patch_windows": with_windows, "without": without},
            "per_band_statistics_seconds": {"with_patch_windows": per_band[0], "without": per_band[1]}}


def main(argv: list[str] | None = None) -> int:
    from benchmarks.run import module_main

    return module_main(argv, "long_waves", run, __doc__)


if __name__ == "__main__":
    sys.exit(main())
