"""How much multiple scattering lowers the CV in the Gernez & Antoine (2009) comparison.

The comparison (``warpcaustics field gernez2009``, docs/validation.md) renders single scattering and
brackets the scattered light with a uniform background. This measures it instead: the scene of
``configs/field/gernez2009.toml`` on a smaller patch (8 m at 256², the same 3.1 cm cells; its
uniform sky with the paper's diffuse share at each zenith) at a few sun zeniths, by single
scattering and by the random walk (``optics.scattering = "multiple"``, Jerlov IB's Petzold-like
phase function; sun and sky both walked), each map averaged over the 8 mm collector. The walk
runs with two seeds and its photon noise (half the variance of their difference) is taken out of
the variance of their mean. Frames 2 s apart are pooled. Prints both CVs, their ratio and the
uniform-background estimate exp(−b·d/cos θ_w).

``python -m benchmarks.gernez_scattering [--quick]`` (CPU, a few minutes; ``--quick``: one zenith,
one frame, coarse photons).
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

from benchmarks.field_budget import BEFORE  # the field set-up as these figures were measured
from benchmarks.run import ROOT

ZENITHS_DEG = (20.0, 40.0, 60.0)


def _collected(result, floor) -> np.ndarray:
    """A (K, M, M) floor map summed over its bands and averaged over the config's collector."""
    from warpcaustics.batch.stats import band_integrated, collector_average

    texel = result.map_extent_m / floor.shape[-1]
    return collector_average(band_integrated(floor, result.bin_widths_nm), texel,
                             1e-3 * result.scene.config.stats.collector_mm, periodic=result.map_periodic)


def _cv_pair(overrides: dict, time_s: float) -> tuple[tuple[float, float], tuple[float, float]]:
    """((mean, CV) single, (mean, CV) multiple without photon noise) of one frame, after the
    collector."""
    import warpcaustics as wc
    from warpcaustics.batch.stats import cv_without_noise

    maps = []
    for seed in (1, 2):
        scene = wc.load_scene(ROOT / "configs/field/gernez2009.toml",
                              {**BEFORE, **overrides, "optics.mc_seed": seed})
        r = wc.render(scene, time_s=time_s, device="cpu")
        maps.append(_collected(r, r.floor_irradiance))
    single = _collected(r, r.comparison.floor_irradiance)
    mean, cv_multi = cv_without_noise(maps[0], maps[1])
    return (float(single.mean()), float(single.std() / single.mean())), (float(mean.mean()), float(cv_multi))


def main(argv: list[str] | None = None) -> int:
    from warpcaustics.batch.field import diffuse_fraction, direct_transmission, pooled_statistics
    from warpcaustics.optics.spectra import bins_for, water_optics
    from warpcaustics.scene import load_scene

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="one zenith, one frame, coarse photons")
    args = parser.parse_args(argv)
    zeniths, frames, samples = ((40.0,), 1, 4) if args.quick else (ZENITHS_DEG, 3, 16)
    base = {
        "water.extent_m": 8.0,
        "water.resolution": 256,
        "optics.scattering": "multiple",
        "optics.mc_samples": samples,
    }
    config = load_scene(ROOT / "configs/field/gernez2009.toml", {**BEFORE, **base}).config
    b = float(water_optics(config.optics, bins_for(config.optics)).scattering_per_m[0])
    print(
        f"gernez scattering | 8 m at 256², 1 m window, 8 mm collector, {samples}² photons per cell, "
        f"{frames} frame(s), b = {b:.3f} 1/m, uniform sky of {config.sky.directions} directions"
    )
    for z in zeniths:
        condition = {**base, "sun.elevation_deg": 90.0 - z, "sky.diffuse_fraction": diffuse_fraction(z)}
        pairs = [_cv_pair(condition, 2.0 * i) for i in range(frames)]
        _, cv_single = pooled_statistics([p[0] for p in pairs])
        _, cv_multi = pooled_statistics([p[1] for p in pairs])
        t = direct_transmission(z, config.floor.depth_m, float(config.optics.ior), b)
        print(
            f"zenith {z:4.0f}° | diffuse {condition['sky.diffuse_fraction']:.2f} | "
            f"CV single {cv_single:.3f} | CV multiple {cv_multi:.3f} | "
            f"multiple / single {cv_multi / cv_single:.2f} | uniform-background estimate {t:.2f}",
            flush=True,
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
