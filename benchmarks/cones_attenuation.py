"""Does the cones' spread need each point's own attenuation? ``python -m benchmarks.cones_attenuation``.

``sky.sampling = "cones"`` spreads each sky direction's floor map over its cell of the sky by the
cell's points' offsets, weighted by the sky's radiance and the Fresnel transmittance
(``optics/sky_cells.py``), the same in every band: the points' own paths through the water, longer
for the cell's shallower directions, are not attenuated apart. Where absorption is strong (the red,
a ≈ 0.42-0.45 1/m) that could make the spread too wide and the red too smooth under diffuse light,
where Gernez & Antoine (2009)'s red fluctuates most (docs/validation.md, "Each band"). This renders
the Gernez scene under the CIE overcast sky (type 1, 99 % of the light, the sun 40° from the zenith)
in one band at a time, with the config's spread and with each point's weight times
exp(−c D (1/cosθ_w,s − 1/cosθ_w,j)) (c = a + b of the band, D the depth: the point's path against
its direction's), and prints the sky's CV over the 8 m patch (the window and the patch's windows,
pooled over the frames) for both. A measurement of a candidate, not a mode: the weighted spread is
put in for this process only. ``--quick``: a 256² sea and window, one frame (keeps it running).
"""

from __future__ import annotations

import argparse
import json
import sys

import numpy as np

from benchmarks.field_budget import SKY_16_CONES  # the sky as these figures were measured
from benchmarks.run import ROOT

OVERCAST = {"sun.elevation_deg": 50.0, "sky.model": "cie", "sky.cie_type": 1, "sky.diffuse_fraction": 0.99}
QUICK = {"water.resolution": 256, "caustics.map_resolution": 256}


def weight_by_paths(c_per_m: float) -> None:
    """Make the cones' multipliers weight each cell point by its own path's attenuation relative to
    its direction's (for the rest of this process; cached apart from the config's)."""
    from warpcaustics.caustics import sky_cones
    from warpcaustics.optics import sky_cells

    def multiplier(j, directions, sky_type, sun, ior, depth_m, texel_m, m):
        def make():
            points, weights = sky_cells.sky_cells(directions, sky_type, sun, ior)[j]
            direction = np.asarray(directions[j], np.float64)

            def path(cos_air):  # D / cos θ_w of a direction of cos θ = cos_air in the air
                return depth_m / np.sqrt(1.0 - (1.0 - np.asarray(cos_air) ** 2) / ior**2)

            att = np.exp(-c_per_m * (path(points[:, 2]) - path(direction[2])))
            return sky_cells.cell_multiplier(direction, points, weights * att, len(directions), depth_m, ior,
                                             texel_m, m)

        key = ("paths", c_per_m, j, directions, sky_type, sun, ior, depth_m, texel_m, m)
        return sky_cones._CACHE.get(key, make)

    sky_cones._multiplier = multiplier


def measure(nm: float, weighted: bool, frames: int, quick: bool) -> dict:
    import warpcaustics as wc
    from warpcaustics.batch.field.gernez2009 import whole_sea
    from warpcaustics.batch.stats import frame_statistics
    from warpcaustics.optics.spectra import bins_for, water_optics

    scene = wc.load_scene(ROOT / "configs/field/gernez2009.toml",
                          {**SKY_16_CONES, **OVERCAST, **(QUICK if quick else {}),
                           "optics.wavelengths": [nm]})
    water = water_optics(scene.config.optics, bins_for(scene.config.optics))
    c = float(water.absorption_per_m[0] + water.scattering_per_m[0])
    if weighted:
        weight_by_paths(c)
    renderer = wc.Renderer(scene, device="cpu")
    stats = [frame_statistics(renderer.render(2.0 * f), scene.config.stats) for f in range(frames)]
    sea = whole_sea(stats, None, 1.0, overcast=True)
    return {"wavelength_nm": nm, "c_per_m": c, "weighted": weighted, "frames": frames,
            "model_cv": sea["model_cv"], "model_cv_window": sea["model_cv_window"]}


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m benchmarks.cones_attenuation",
                                description=__doc__.splitlines()[0])
    p.add_argument("--nm", default="510,670", help="bands, one at a time (default 510,670)")
    p.add_argument("--frames", type=int, default=3, help="frames 2 s apart (default 3)")
    p.add_argument("--quick", action="store_true", help="a 256² sea and window, one frame")
    p.add_argument("--one", nargs=2, metavar=("NM", "VARIANT"), help=argparse.SUPPRESS)  # a child's run
    args = p.parse_args(argv)
    frames = 1 if args.quick else args.frames
    if args.one:  # each variant in a process of its own: the multipliers' cache and the patch stay there
        print(json.dumps(measure(float(args.one[0]), args.one[1] == "weighted", frames, args.quick)))
        return 0
    import subprocess

    for nm in (float(x) for x in args.nm.split(",")):
        rows = []
        for variant in ("plain", "weighted"):
            cmd = [sys.executable, "-m", "benchmarks.cones_attenuation", "--one", f"{nm:g}", variant,
                   "--frames", str(frames)] + (["--quick"] if args.quick else [])
            out = subprocess.run(cmd, cwd=ROOT, check=True, capture_output=True, text=True).stdout
            rows.append(json.loads(out.strip().splitlines()[-1]))
        plain, weighted = rows
        print(f"{nm:g} nm (c = {plain['c_per_m']:.3f} 1/m): the sky's CV over the patch "
              f"{plain['model_cv']:.4f} "
              f"with the config's spread, {weighted['model_cv']:.4f} with each point's attenuation "
              f"(x{weighted['model_cv'] / plain['model_cv']:.3f}); the window {plain['model_cv_window']:.4f} "
              f"and {weighted['model_cv_window']:.4f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
