"""The sky's cones on a coarser surface: ``python -m benchmarks.sky_surface``.

``sky.surface_resolution`` refracts the sky's cones through the sea's own waves cut to a coarser
grid (``FFTOcean.truncated``), the sun's passes keeping the whole sea. This times a warm frame of the
Gernez comparison's scene (``configs/field/gernez2009.toml``: 2048² cells over 8 m, a 1 m window of
512² texels, 8 sun-disk directions, small-angle scattering with the walked spread) at a 20° sun (the
paper's diffuse share), one core, with the sky as it was (16 cones on the whole grid, the baseline),
64 cones on the whole grid, and 16 and 64 cones on 1024² (64 on 1024²: the config now), and prints
each over the baseline, with the sky's stages (shading, refraction and deposit; the cones' spread)
and the first frame's, which builds the cells' multipliers and the transfer's walked spreads.
``--quick``: 256² cells (the sky's surface 128²), 128² texels, Wells's spread (no walks), 4 and 16
cones (keeps the script running).
"""

from __future__ import annotations

import sys
import time

from benchmarks.run import ROOT, device_record, median_time

SCENE = ROOT / "configs/field/gernez2009.toml"
POINT = {"sun.elevation_deg": 70.0, "sky.diffuse_fraction": 0.21}
"""A 20° sun at the paper's diffuse share (``jerlov.gernez2009_diffuse_share``)."""

QUICK = {"water.resolution": 256, "caustics.map_resolution": 128, "optics.beam_spread": "wells"}


def measure(directions: int, surface: int, quick: bool, device: str, repeats: int) -> dict:
    """One case's frames, in a process of its own (its first frame builds its own multipliers)."""
    import warpcaustics as wc

    overrides = {**POINT, **(QUICK if quick else {}), "sky.directions": directions,
                 "sky.surface_resolution": surface}
    renderer = wc.Renderer(wc.load_scene(SCENE, overrides), device=device)
    start = time.perf_counter()
    first = renderer.render(0.0)  # the kernels, the spreads and the cells' multipliers
    first_s = time.perf_counter() - start
    last = {}
    warm = median_time(lambda: last.update(frame=renderer.render(0.5)), repeats, device)
    stages = last["frame"].timings_s  # the last warm frame's
    return {"directions": directions, "sky_surface": renderer.scene.sky_resolution,
            "first_frame_s": first_s, "warm_frame_s": warm, "sky_s": stages.get("sky", 0.0),
            "sky_cones_s": stages.get("sky_cones", 0.0),
            "first_sky_cones_s": first.timings_s.get("sky_cones", 0.0)}


def run(quick: bool, device: str) -> dict:
    from benchmarks.run import _in_child

    repeats = 1 if quick else 2
    few, many, coarse = (4, 16, 128) if quick else (16, 64, 1024)
    cases = {f"{few} cones, whole grid": (few, 0), f"{many} cones, whole grid": (many, 0),
             f"{few} cones on {coarse}²": (few, coarse), f"{many} cones on {coarse}²": (many, coarse)}
    rows = {name: _in_child("measure", d, ns, quick, device, repeats, module="sky_surface")
            for name, (d, ns) in cases.items()}
    baseline = rows[next(iter(rows))]["warm_frame_s"]
    for name, row in rows.items():
        row["over_baseline"] = row["warm_frame_s"] / baseline
        print(f"{name:26s} warm frame {row['warm_frame_s']:6.2f} s (x{row['over_baseline']:.2f}): sky passes "
              f"{row['sky_s']:5.2f} s, cones' spread {row['sky_cones_s']:4.2f} s; first frame "
              f"{row['first_frame_s']:6.2f} s (cells' multipliers {row['first_sky_cones_s']:.2f} s)")
    return {"benchmark": "sky_surface", **device_record(device), "quick": quick, "repeats": repeats,
            "overrides": {**POINT, **(QUICK if quick else {})}, "rows": rows}


def main(argv: list[str] | None = None) -> int:
    from benchmarks.run import module_main

    return module_main(argv, "sky_surface", run, __doc__)


if __name__ == "__main__":
    sys.exit(main())
