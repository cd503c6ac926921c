"""The sky's cones against the sky's continuum in float64: ``python -m benchmarks.sky_continuum``.

The floor's sky part at 510 and 670 nm (Jerlov IB) by ``sky.sampling = "cones"`` (8 to 256 cones)
and by point directions (``stratified``), against the float64 integration over the directions the
light arrives from in the water (``tests/sky_continuum.py``, written apart from the package), at
16 × 16 floor points, under a uniform sky and the CIE overcast sky (type 1):

- ``sea``: ``tests/test_sky_continuum.py``'s scene (Elfouhaily at 5 m/s, 256² over 4 m, 3.2 m deep),
  at more points and a finer quadrature than the test's;
- ``gernez``: the Gernez comparison's own sea (``configs/field/gernez2009.toml``: 2048² over 8 m,
  3.2 m deep) under the overcast sky, the whole patch as the map (512² texels), the scattered light
  left out (``optics.scattering = "single"``): is the model's red, a quarter as rough as its green
  there, what the continuum gives?
- ``gernez_low_sun``: the same sea under the CIE clear sky (type 12, the config's) with the sun 80°
  from the zenith: the sky's part of a low sun's CV, 16 and 64 cones against the continuum;

Printed per case: each band's mean and CV over the points, the CV over the continuum's, the red's CV
over the green's, the correlation with the continuum point by point, and the seconds of each render
and of the reference (one core). ``--quick``: the ``sea`` scene with the test's 8 × 8 points and
coarse quadrature, 16 and 64 cones; ``--samplings``: other skies than each case's own. Figures in
docs/validation.md (issue 32's sky, issue 27's overcast red); about 25 minutes in full.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the test's scene and points, 16 and 64 cones")
    parser.add_argument("--cases", default="sea,gernez,gernez_low_sun,surface",
                        help="comma-separated of sea, gernez, gernez_low_sun, surface (default all)")
    parser.add_argument("--samplings", default=None,
                        help="the skies to render instead of each case's own, comma-separated "
                             "sampling:directions[:surface_resolution], e.g. cones:128:1024,cones:256:1024")
    args = parser.parse_args(argv)
    sys.path.insert(0, str(ROOT / "tests"))
    from sky_continuum import (  # noqa: I001 (the tests' folder, put on the path above)
        CIE_SKIES, PeriodicHeights, cie_sky, floor_irradiance, texel_points, uniform_sky)
    from test_sky_continuum import SEA

    import warpcaustics as wc

    if not CIE_SKIES.exists():
        parser.error(f"needs the CIE skies' table at {CIE_SKIES} (../shared/data/sky beside the checkout)")
    skies = {"uniform": ({"sky.model": "uniform"}, lambda sun: uniform_sky),
             "cie_overcast": ({"sky.model": "cie", "sky.cie_type": 1}, lambda sun: cie_sky(1, sun)),
             "cie_clear_sun_80": ({"sky.model": "cie", "sky.cie_type": 12, "sun.elevation_deg": 10.0},
                                  lambda sun: cie_sky(12, sun))}
    gernez = {"sun.elevation_deg": 50.0, "sun.angular_diameter_deg": 0.0, "sky.diffuse_fraction": 0.99,
              "optics.scattering": "single", "optics.beam_spread": "wells",
              "optics.wavelengths": [510.0, 670.0], "caustics.map_extent_m": 8.0, "optics.ior": 1.333}
    # the cones on the whole sea (16, this run's baseline; 64 on it: results/sky_continuum.txt's first run),
    # and through its waves cut to a coarser grid (sky.surface_resolution)
    on_coarser = [("cones", 16, 0), ("cones", 16, 1024), ("cones", 64, 1024), ("cones", 64, 512)]
    every = [("cones", 8), ("cones", 16), ("cones", 32), ("cones", 64), ("cones", 256), ("stratified", 1024)]
    cases = {
        "sea": (None, SEA, 4.0, SEA["caustics.map_resolution"] * (1 if args.quick else 2), list(skies),
                [("cones", 16), ("cones", 64)] if args.quick else every),
        "gernez": (ROOT / "configs" / "field" / "gernez2009.toml", gernez, 8.0, 512, ["cie_overcast"],
                   on_coarser),
        "gernez_low_sun": (ROOT / "configs" / "field" / "gernez2009.toml", gernez, 8.0, 512,
                           ["cie_clear_sun_80"], on_coarser),
    }
    if args.samplings:
        chosen = []
        for item in args.samplings.split(","):
            parts = item.split(":")
            if len(parts) not in (2, 3) or not all(p.isdigit() for p in parts[1:]):
                parser.error(f"--samplings: {item!r} is not sampling:directions[:surface_resolution]")
            chosen.append((parts[0], *map(int, parts[1:])))
        cases = {name: (*case[:5], chosen) for name, case in cases.items()}
    if "surface" in args.cases.split(","):
        surface_case(gernez)
    points_a_side, quadrature = (8, 96) if args.quick else (16, 160)
    for name in (c for c in args.cases.split(",") if c != "surface"):
        config, overrides, extent, texels, sky_names, samplings = cases[name]
        idx, where = texel_points(texels, texels // points_a_side, extent)
        for sky_name in sky_names:
            sky, make_radiance = skies[sky_name]
            print(f"\n{name}, {sky_name} sky: {len(where)} points")
            rows = []
            for sampling, directions, *coarser in samplings:
                keys = {**overrides, **sky, "caustics.map_resolution": texels, "sky.sampling": sampling,
                        "sky.directions": directions}
                if coarser:
                    keys["sky.surface_resolution"] = coarser[0]
                scene = wc.load_scene(config, keys)
                start = time.perf_counter()
                r = wc.render(scene, device="cpu")
                seconds = time.perf_counter() - start
                sky_map = r.sky_floor_irradiance / scene.sky_irradiance(r.sun_irradiance)[:, None, None]
                on = f" on {coarser[0]}²" if coarser and coarser[0] else ""
                label = f"{sampling} {directions}{on}"
                rows.append((label, sky_map[:, idx][:, :, idx].reshape(2, -1), seconds))
            start = time.perf_counter()
            heights = PeriodicHeights(r.surface_positions[..., 2], extent)
            continuum = floor_irradiance(heights, where, scene.config.floor.depth_m, float(r.ior[0]),
                                         r.attenuation_per_m, make_radiance(scene.sun_direction), quadrature,
                                         quadrature).T
            rows.insert(0, ("continuum", continuum, time.perf_counter() - start))
            exact = continuum.std(axis=1) / continuum.mean(axis=1)
            for label, values, seconds in rows:
                cv = values.std(axis=1) / values.mean(axis=1)
                corr = [np.corrcoef(values[k], continuum[k])[0, 1] for k in range(2)]
                print(f"  {label:22s} mean {values.mean(axis=1).round(5)}  CV {cv.round(5)}  "
                      f"/ continuum {(cv / exact).round(3)}  670/510 {cv[1] / cv[0]:.3f}  "
                      f"corr {np.round(corr, 3)}  {seconds:.1f} s")
    return 0


def surface_case(overrides: dict) -> None:
    """``--cases surface``: the sky's float64 continuum on the Gernez sea and on the same sea without
    its waves shorter than a 1024² or 512² grid holds, sampled on that grid (what sky.surface_resolution
    refracts the cones through, low-passed here in numpy), under the CIE overcast sky and the clear
    sky with the sun 80° and 40° from the zenith, at 8 × 8 points 1 m apart, 160² directions. Nothing
    of the package but the sea's heights and the water's c(λ)."""
    from helpers import low_pass  # noqa: I001 (the tests' folder, put on the path in main)
    from sky_continuum import PeriodicHeights, cie_sky, floor_irradiance, texel_points

    import warpcaustics as wc
    from warpcaustics.optics import spectra
    from warpcaustics.water.ocean import FFTOcean

    scene = wc.load_scene(ROOT / "configs" / "field" / "gernez2009.toml", overrides)
    cfg = scene.config
    heights = FFTOcean.from_config(cfg, "cpu").at(0.0).positions.numpy()[..., 2]
    attenuation = spectra.water_optics(cfg.optics, spectra.bins_for(cfg.optics)).attenuation_per_m
    _, where = texel_points(512, 64, cfg.water.extent_m)
    skies = {"cie_overcast": cie_sky(1, np.array([0.0, 0.0, 1.0]))}
    for zenith in (80.0, 40.0):
        sun = np.array([np.sin(np.radians(zenith)), 0.0, np.cos(np.radians(zenith))])
        skies[f"cie_clear_sun_{zenith:g}"] = cie_sky(12, sun)
    for name, radiance in skies.items():
        print(f"\nsurface, {name} sky: {len(where)} points, the continuum on the waves an M² grid holds")
        whole = None
        for m in (heights.shape[0], 1024, 512):
            start = time.perf_counter()
            cut = heights if m == heights.shape[0] else low_pass(heights, m, cfg.water.extent_m)
            field = PeriodicHeights(cut, cfg.water.extent_m)  # on the M² grid, as the sky's surface
            e = floor_irradiance(field, where, cfg.floor.depth_m, cfg.optics.ior, attenuation, radiance,
                                 160, 160).T
            mean, cv = e.mean(axis=1), e.std(axis=1) / e.mean(axis=1)
            whole = (mean, cv) if whole is None else whole
            print(f"  {m:4d}²  mean {mean.round(5)} ({(mean / whole[0] - 1).round(4)})  CV {cv.round(5)} "
                  f"({(cv / whole[1] - 1).round(4)})  {time.perf_counter() - start:.1f} s")


if __name__ == "__main__":
    sys.exit(main())
