"""How many sky directions the CV needs: ``python -m benchmarks.sky_directions``.

Each of the sky's ``sky.directions`` draws a caustic pattern of its own; a real sky's continuum of
directions washes them out. This measures the field set-up's CV of downwelling irradiance
(``configs/field/gernez2009.toml``: 3.1 cm cells, 510 nm, a 1 m window seen through the 8 mm
collector, ``optics.scattering = "small_angle"``) on a 256² × 8 m window of that sea (the same
cells; the 32 m patch only adds longer waves) at the paper's diffuse share for each sun zenith,
against the number of sky directions, 16 → 64 → 256, at 3.2 m and 9 m, a sun 20° and 85° from the
zenith, pooled over ``--frames`` frames; with the CV of the sun's part alone (the sky as a uniform
background) beside it. Directions are enough where the CV stops changing. ``--quick``: 16 and 64
directions, 3.2 m, one frame. ``--halves``: each count also with ``sky.sampling = "halves"``, whose
two independently drawn halves give the CV with the sky's continuum (``cv_continuous_sky``), free of
the directions' own noise, to compare with the stratified sky's CV as its directions grow — and the
power spectrum of E/Ē − 1 in octave bands of spatial frequency, the stratified sky's own (its 256
directions from one frame) and the continuum's from the halves' cross-power
(``continuous_sky_spectrum``).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from benchmarks.field_budget import BEFORE  # the field set-up as these figures were measured

ROOT = Path(__file__).resolve().parents[1]


def measure(zeniths, depths, counts, frames: int, samplings=("stratified",),
            spectra: bool = False) -> list[dict]:
    import warpcaustics as wc
    from warpcaustics.batch.field import diffuse_fraction
    from warpcaustics.batch.stats import (
        collector_average,
        continuous_sky_cv,
        continuous_sky_moments,
        continuous_sky_spectrum,
        cross_band_power,
    )

    rows = []
    for zenith in zeniths:
        share = diffuse_fraction(zenith)
        for depth in depths:
            for count, sampling in ((c, s) for c in counts for s in samplings):
                scene = wc.load_scene(ROOT / "configs/field/gernez2009.toml", {
                    **BEFORE, "water.resolution": 256, "water.extent_m": 8.0,
                    "sun.elevation_deg": 90.0 - zenith, "sky.sampling": sampling,
                    "sky.diffuse_fraction": share, "sky.directions": count, "floor.depth_m": depth})
                cfg = scene.config
                texel = cfg.caustics.map_extent_m / cfg.caustics.map_resolution
                collector = cfg.stats.collector_mm * 1e-3
                renderer = wc.Renderer(scene, device="cpu")
                window = cfg.caustics.map_extent_m
                total, sun, halves, power = [], [], [], []
                start = time.perf_counter()
                for f in range(frames):
                    r = renderer.render(0.5 * f)
                    e = collector_average(r.floor_irradiance[0], texel, collector, periodic=False)
                    sky = collector_average(r.sky_floor_irradiance[0], texel, collector, periodic=False)
                    total.append(e)
                    power.append(cross_band_power(e, e, window, periodic=False) / float(e.mean()) ** 2)
                    sun.append(e - sky + sky.mean())  # the sky as a uniform background
                    if r.sky_floor_irradiance_even is not None:  # the sky's continuum from its halves
                        even = collector_average(r.sky_floor_irradiance_even[0], texel, collector,
                                                 periodic=False)
                        halves.append(continuous_sky_moments(e, sky, even, extent_m=window, periodic=False))
                seconds = (time.perf_counter() - start) / frames
                total, sun = np.array(total), np.array(sun)
                row = {"sun_zenith_deg": zenith, "diffuse_share": share, "depth_m": depth,
                       "directions": count, "sampling": sampling, "cv": float(total.std() / total.mean()),
                       "cv_uniform_sky": float(sun.std() / sun.mean()), "s_per_frame": seconds}
                text = ""
                if halves:  # pooled over the frames
                    row["cv_continuous_sky"] = continuous_sky_cv(halves)
                    text = f", the sky's continuum from its halves {row['cv_continuous_sky']:.4f}"
                row["relative_power"] = np.mean(power, axis=0).tolist()
                if halves:
                    row["continuous_sky_relative_power"] = continuous_sky_spectrum(halves)["relative_power"]
                rows.append(row)
                print(f"sun {zenith:4.0f}°  diffuse {share:.2f}  {depth:4.1f} m  {count:4d} directions, "
                      f"{sampling:10s}: CV {row['cv']:.4f}  (uniform sky {row['cv_uniform_sky']:.4f}{text})  "
                      f"{seconds:.0f} s/frame", flush=True)
                if spectra:
                    print(f"    power of E/E-1 per octave band from {1 / window:g} cycles/m: "
                          + " ".join(f"{x:.2e}" for x in row["relative_power"]), flush=True)
                    if halves:
                        print("    the sky's continuum from its halves:              "
                              + " ".join(f"{x:.2e}" for x in row["continuous_sky_relative_power"]),
                              flush=True)
    return rows


def cones(zenith: float, depth: float, frames: int) -> None:
    """The cones' CV and spectrum against the stratified sky's as its directions grow, and the
    continuum extrapolated from the last two counts (the directions' own power falls as 1/D)."""
    rows = measure((zenith,), (depth,), (16, 64), frames, ("cones",), spectra=True)
    rows += measure((zenith,), (depth,), (16, 64, 256, 1024), frames, spectra=True)
    p256, p1024 = (np.array(r["relative_power"]) for r in rows[-2:])
    extrapolated = (4.0 * p1024 - p256) / 3.0
    print("    the continuum extrapolated from 256 and 1024 stratified directions, (4 P_1024 - P_256)/3: "
          + " ".join(f"{x:.2e}" for x in extrapolated)
          + f"; CV {np.sqrt(max(float(extrapolated.sum()), 0.0)):.4f} (the bands' sum)", flush=True)
    for row in rows[:2]:
        print(f"    cones, {row['directions']} directions: CV from the bands' sum "
              f"{np.sqrt(float(np.sum(row['relative_power']))):.4f}", flush=True)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="16 and 64 directions, 3.2 m, one frame")
    parser.add_argument("--frames", type=int, default=2)
    parser.add_argument("--halves", action="store_true",
                        help="also each count with sky.sampling = 'halves' (the CV and power spectrum "
                             "with the sky's continuum, issue 32), at an 85° sun, --depth (3.2 m), 16 and 64 "
                             "directions, and 256 stratified directions for one frame")
    parser.add_argument("--cones", action="store_true",
                        help="sky.sampling = 'cones' (each direction spread over its cell of the sky) at "
                             "16 and 64 directions against the stratified sky's 16 to 1024 and the "
                             "continuum extrapolated from them, (4 P_1024 - P_256)/3, per octave band, at an "
                             "85° sun and --depth (3.2 m)")
    parser.add_argument("--depth", type=float, default=3.2,
                        help="with --halves or --cones: the floor's depth [m] (default 3.2)")
    parser.add_argument("--zenith", type=float, default=85.0,
                        help="with --cones: the sun's zenith [deg] (default 85)")
    args = parser.parse_args(argv)
    if args.quick:
        measure((85.0,), (3.2,), (16, 64), 1)
        measure((85.0,), (3.2,), (16,), 1, ("cones",))
    elif args.cones:
        cones(args.zenith, args.depth, args.frames)
    elif args.halves:
        measure((85.0,), (args.depth,), (16, 64), args.frames, ("stratified", "halves"), spectra=True)
        measure((85.0,), (args.depth,), (256,), 1, spectra=True)
    else:
        measure((20.0, 85.0), (3.2, 9.0), (16, 64, 256), args.frames)
    return 0


if __name__ == "__main__":
    sys.exit(main())
