"""The small-angle map's spatial spectrum against the random walk's, with the walk's noise measured:
``python -m benchmarks.small_angle_vs_walk``.

The scene of ``tests/test_small_angle.py`` (``configs/ocean.toml``, 128² over 16 m, a 128² map,
coastal water, a black floor, a point sun): 3 m with Henyey–Greenstein and 6 m with Petzold. Per rgb
band and per radial band of spatial frequency (the test's six, 2 cycles per patch to the Nyquist
limit), the power of the ``small_angle`` map against the walk's, whose photon noise is taken out by
the cross-spectra of ``--seeds`` independent walks (all pairs averaged). Printed:

- ``walk noise``: the relative standard deviation of one pair's estimate (over disjoint pairs) — the
  noise of the test's reference, which uses one pair;
- ``surface factor``: the single-scattering map's power over the walk's with no water at all (water
  type ``none``, the same seeds): what the two methods' surfaces differ by (flat facets against the
  walk's bilinear normals), with no scattering in it;
- ``small_angle / walk`` and the same over the surface factor: what is left is the small-angle
  approximation's own error, and, in walk-noise units, whether it is noise.

The figures are in docs/physics.md and docs/validation.md (issue 32 item 2). About a minute per
geometry on one core with 8 seeds.
"""

from __future__ import annotations

import argparse
import itertools
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
GEOMETRIES = ((3.0, "henyey_greenstein"), (6.0, "petzold"))
SPREADS = ("wells", "walk")
"""The two ``optics.beam_spread`` transfers of the small-angle mode."""


def cross_power(maps: list[np.ndarray], m: int, band_power, fluctuations) -> tuple[np.ndarray, np.ndarray]:
    """((K, bands) the cross-power of all pairs of independent walks' maps, averaged, (K, bands) the
    relative standard deviation of one pair's estimate, from disjoint pairs)."""
    f = [fluctuations(a) for a in maps]
    every = np.mean([band_power((f[i] * np.conj(f[j])).real, m)
                     for i, j in itertools.combinations(range(len(f)), 2)], axis=0)
    disjoint = np.stack([band_power((f[i] * np.conj(f[i + 1])).real, m) for i in range(0, len(f) - 1, 2)])
    return every, disjoint.std(axis=0, ddof=1) / every


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=8, help="independent walks (even, ≥ 4; default 8)")
    args = parser.parse_args(argv)
    if args.seeds < 4 or args.seeds % 2:
        parser.error("--seeds: give an even number of at least 4")
    sys.path.insert(0, str(ROOT / "tests"))
    from helpers import CONFIGS  # noqa: I001 (the tests' folder, put on the path above)
    from test_small_angle import BANDS, SCENE, band_power, fluctuations

    import warpcaustics as wc

    m = SCENE["caustics.map_resolution"]
    seeds = range(1, args.seeds + 1)

    def floor(overrides: dict) -> np.ndarray:
        return wc.render(wc.load_scene(CONFIGS / "ocean.toml", overrides), device="cpu").floor_irradiance

    np.set_printoptions(precision=3, suppress=True, linewidth=120)
    edges = " ".join(f"{lo:.4g}–{hi:.4g}" for lo, hi in zip(BANDS, BANDS[1:]))
    print("radial bands [cycles per texel]:", edges)
    print("rows: the 450, 550 and 650 nm bands of the map (optics.wavelengths = rgb)")
    for depth, phase in GEOMETRIES:
        start = time.perf_counter()
        base = {**SCENE, "floor.depth_m": depth, "optics.phase_function": phase}
        bare = {**base, "optics.water_type": "none"}
        walk, noise = cross_power([floor({**base, "optics.scattering": "multiple", "optics.mc_seed": s})
                                   for s in seeds], m, band_power, fluctuations)
        walk0, _ = cross_power([floor({**bare, "optics.scattering": "multiple", "optics.mc_seed": s})
                                for s in seeds], m, band_power, fluctuations)
        single0 = floor({**bare, "optics.scattering": "single"})
        surface = band_power(np.abs(fluctuations(single0)) ** 2, m) / walk0
        print(f"\n{depth:g} m, {phase}, {args.seeds} seeds ({time.perf_counter() - start:.0f} s)")
        print("walk noise (one pair's relative sd):\n", noise)
        print("surface factor (single / walk, no water):\n", surface)
        for spread in SPREADS:
            mode = {**base, "optics.scattering": "small_angle", "optics.beam_spread": spread}
            ratio = band_power(np.abs(fluctuations(floor(mode))) ** 2, m) / walk
            left = ratio / surface
            print(f"small_angle ({spread}) / walk:\n", ratio)
            print(f"small_angle ({spread}) / walk over the surface factor:\n", left)
            print("... its difference from 1 in units of the walk's noise of the averaged pairs:\n",
                  (left - 1.0) / (noise / np.sqrt(args.seeds / 2)))
            print(f"range over the surface factor ({spread}): {left.min():.3f}–{left.max():.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
