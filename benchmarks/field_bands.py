"""The cost of the Gernez comparison's six bands: ``python -m benchmarks.field_bands``.

``warpcaustics field gernez2009_bands`` renders the Gernez scene (``configs/field/gernez2009.toml``:
2048² cells over 8 m, a 1 m window of 512² texels, 8 sun-disk and 16 sky directions in cones,
small-angle scattering with the walked spread) in the six bands of Gernez & Antoine's Fig. 10a at
once, with each band's statistics and its sky and direct parts (``stats.per_band``). This times a
warm frame of it at a 20° sun (the paper's diffuse share), one core, against a warm frame of the
comparison at 510 nm alone in the same process, and prints the ratio: what the bands cost over
the one band. The frame's statistics are timed too, per band with the sky's parts against the
band-integrated ones alone. ``--quick``: 128² cells and texels, 4 sky cones, 2 disk directions, the beam
spread's walks of 16384 photons (keeps the script running).
"""

from __future__ import annotations

import sys

from benchmarks.field_budget import QUICK_LIGHT, SKY_16_CONES  # the sky as the figures were measured
from benchmarks.run import ROOT, device_record, median_time

SCENE = ROOT / "configs/field/gernez2009.toml"
POINT = {**SKY_16_CONES, "sun.elevation_deg": 70.0, "sky.diffuse_fraction": 0.21}
"""A 20° sun at the paper's diffuse share (``jerlov.gernez2009_diffuse_share``)."""

QUICK = {"water.resolution": 128, "caustics.map_resolution": 128, **QUICK_LIGHT}


def run(quick: bool, device: str) -> dict:
    import dataclasses

    import warpcaustics as wc
    from warpcaustics.batch.field.gernez2009_bands import band_overrides, record
    from warpcaustics.batch.stats import frame_statistics

    repeats = 1 if quick else 2
    base = {**POINT, **(QUICK if quick else {})}
    times = {}
    for name, overrides in (("one_band", base), ("six_bands", {**base, **band_overrides(record())})):
        scene = wc.load_scene(SCENE, overrides)
        renderer = wc.Renderer(scene, device=device)
        renderer.render(0.0)  # warm-up: the kernels, the spreads and the cells' multipliers
        times[name] = median_time(lambda r=renderer: r.render(0.5), repeats, device)
    result, cfg = renderer.render(1.0), scene.config.stats  # the six bands'
    integrated = dataclasses.replace(cfg, per_band=False)
    stats = {"per_band": median_time(lambda: frame_statistics(result, cfg), repeats),
             "band_integrated": median_time(lambda: frame_statistics(result, integrated), repeats)}
    ratio = times["six_bands"] / times["one_band"]
    print(f"Gernez frame at 510 nm {times['one_band']:.2f} s, in the six bands {times['six_bands']:.2f} s: "
          f"x{ratio:.2f}")
    print(f"six-band frame's statistics {stats['per_band'] * 1e3:.0f} ms with each band's and its sky's "
          f"and direct parts, {stats['band_integrated'] * 1e3:.0f} ms band-integrated only: "
          f"x{stats['per_band'] / stats['band_integrated']:.2f}")
    return {"benchmark": "field_bands", **device_record(device), "quick": quick, "repeats": repeats,
            "overrides": base, "seconds": times, "six_over_one": ratio, "statistics_seconds": stats}


def main(argv: list[str] | None = None) -> int:
    from benchmarks.run import module_main

    return module_main(argv, "field_bands", run, __doc__)


if __name__ == "__main__":
    sys.exit(main())
