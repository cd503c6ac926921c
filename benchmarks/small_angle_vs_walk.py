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
- ``small_angle / walk`` and the same over the surface factor — the band's, and each ring's of whole
  cycles per patch (the factor falls across the finest band, 0.25–1 cycles per texel, where the
  water weights its low end): what is left is the small-angle approximation's own error, and, in
  units of its own standard error, whether it is noise. That error is the jackknife's over the
  seeds (each seed left out in turn from both walks, the one in the water and the one without it,
  whose noise the surface factor carries too), not one pair's spread scaled: four disjoint pairs
  give a standard deviation itself uncertain by ~40 %.

``--set`` changes the scene for every map alike: the walked spread's photons
(``optics.beam_spread_photons``: its own Monte Carlo noise is a fixed realisation per seed, which the
walks' jackknife does not hold) or the waves' amplitude (``water.phillips_amplitude``: does a residual
grow with the slopes?). ``--oversample R`` renders the small-angle maps on R times finer texels and
averages them down to the walk's: the map's texels fold the floor's detail finer than themselves
into its finest band, which the transfer would spread by that band's multiplier instead of the
detail's own (R = 2 takes the fold out here). The figures are in docs/physics.md and
docs/validation.md (issue 32 item 2). About two minutes per geometry on one core with 8 seeds.
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


def cross_power(maps: list[np.ndarray], reduce, fluctuations) -> tuple[np.ndarray, ...]:
    """((K, ...) the cross-power of all pairs of independent walks' maps, averaged and summed by
    ``reduce`` (over radial bands or rings), (n, K, ...) the same with each walk left out in turn (the
    jackknife's samples), (K, ...) the relative standard deviation of one pair's estimate, from
    disjoint pairs)."""
    f = [fluctuations(a) for a in maps]
    n = len(f)
    pairs = {(i, j): reduce((f[i] * np.conj(f[j])).real) for i, j in itertools.combinations(range(n), 2)}
    every = np.mean(list(pairs.values()), axis=0)
    left_out = np.stack([np.mean([p for ij, p in pairs.items() if k not in ij], axis=0) for k in range(n)])
    disjoint = np.stack([pairs[i, i + 1] for i in range(0, n - 1, 2)])
    with np.errstate(invalid="ignore", divide="ignore"):  # rings: k = 0 holds no power
        return every, left_out, disjoint.std(axis=0, ddof=1) / every


def rings(m: int) -> np.ndarray:
    """(M, M) each frequency's ring: ⌈|k| M⌉, the whole cycles per patch it does not exceed, so that
    every ring lies within one of the test's bands (their edges are whole cycles per patch)."""
    k = np.fft.fftfreq(m)
    return np.ceil(np.hypot(*np.meshgrid(k, k)) * m - 1e-9).astype(int)


def jackknife_sd(samples: np.ndarray) -> np.ndarray:
    """The jackknife's standard error of an estimate from its n leave-one-out values (axis 0)."""
    n = len(samples)
    return np.sqrt((n - 1) / n * ((samples - samples.mean(axis=0)) ** 2).sum(axis=0))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=8, help="independent walks (even, ≥ 4; default 8)")
    parser.add_argument("--oversample", type=int, default=1, metavar="R",
                        help="render the small-angle maps on R times finer texels and average them "
                             "down (R x R texels each) to the walk's map (default 1: as the test)")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="a config override on top of the test's scene, for every map alike "
                             "(repeatable), e.g. optics.beam_spread_photons=2097152")
    args = parser.parse_args(argv)
    if args.seeds < 4 or args.seeds % 2:
        parser.error("--seeds: give an even number of at least 4")
    if args.oversample < 1:
        parser.error("--oversample: give a whole number of at least 1")
    from warpcaustics.config import parse_override
    from warpcaustics.errors import ConfigError

    try:
        extra = dict(parse_override(text) for text in args.set)
    except ConfigError as exc:
        parser.error(str(exc))
    fixed = sorted(set(extra) & {"floor.depth_m", "optics.phase_function", "caustics.map_resolution",
                                 "optics.scattering", "optics.beam_spread"})
    if fixed:  # optics.mc_seed is free: the walks set their own, so it seeds the walked spread alone
        parser.error(f"--set {fixed[0]}: the benchmark sets it itself (per geometry, map or method)")
    sys.path.insert(0, str(ROOT / "tests"))
    from helpers import CONFIGS  # noqa: I001 (the tests' folder, put on the path above)
    from test_small_angle import BANDS, SCENE, band_power, fluctuations

    import warpcaustics as wc

    try:  # a bad --set fails in one line before anything renders
        wc.load_scene(CONFIGS / "ocean.toml", {**SCENE, **extra})
    except wc.ConfigError as exc:
        parser.error(f"--set: {exc}")
    m = SCENE["caustics.map_resolution"]
    ring = rings(m)

    def by_ring(spectrum: np.ndarray) -> np.ndarray:
        return np.stack([np.bincount(ring.ravel(), weights=a.ravel()) for a in spectrum])

    def over_surface(power: np.ndarray, single0: np.ndarray, walk0: np.ndarray, walk: np.ndarray):
        """(K, bands) each frequency's power over its ring's surface factor (single0 / walk0, by ring),
        summed by band, over the walk's band power."""
        factor = np.divide(walk0, single0, out=np.ones_like(walk0), where=single0 > 0)  # k = 0: none
        return band_power(power * factor[:, ring], m) / walk

    seeds = range(1, args.seeds + 1)

    def floor(overrides: dict, oversample: int = 1) -> np.ndarray:
        """The floor map, rendered on ``oversample`` times finer texels and averaged down to M²."""
        fine = {**overrides, "caustics.map_resolution": m * oversample}
        a = wc.render(wc.load_scene(CONFIGS / "ocean.toml", fine), device="cpu").floor_irradiance
        return np.asarray(a, np.float64).reshape(-1, m, oversample, m, oversample).mean(axis=(2, 4))

    np.set_printoptions(precision=3, suppress=True, linewidth=120)
    edges = " ".join(f"{lo:.4g}–{hi:.4g}" for lo, hi in zip(BANDS, BANDS[1:]))
    print("radial bands [cycles per texel]:", edges)
    print("rows: the 450, 550 and 650 nm bands of the map (optics.wavelengths = rgb)")
    if extra:
        print("--set:", ", ".join(f"{k}={v}" for k, v in extra.items()))
    if args.oversample > 1:
        print(f"--oversample {args.oversample}: the small-angle maps on {m * args.oversample}² texels, "
              "averaged down")
    for depth, phase in GEOMETRIES:
        start = time.perf_counter()
        base = {**SCENE, "floor.depth_m": depth, "optics.phase_function": phase, **extra}
        bare = {**base, "optics.water_type": "none"}
        walk, walk_k, noise = cross_power(
            [floor({**base, "optics.scattering": "multiple", "optics.mc_seed": s}) for s in seeds],
            lambda a: band_power(a, m), fluctuations)
        walk0, walk0_k, _ = cross_power(
            [floor({**bare, "optics.scattering": "multiple", "optics.mc_seed": s}) for s in seeds],
            by_ring, fluctuations)
        single0 = by_ring(np.abs(fluctuations(floor({**bare, "optics.scattering": "single"}))) ** 2)
        surface = band_power(single0[:, ring], m) / band_power(walk0[:, ring], m)
        print(f"\n{depth:g} m, {phase}, {args.seeds} seeds ({time.perf_counter() - start:.0f} s)")
        print("walk noise (one pair's relative sd):\n", noise)
        print("surface factor (single / walk, no water):\n", surface)
        for spread in SPREADS:
            mode = {**base, "optics.scattering": "small_angle", "optics.beam_spread": spread}
            power = np.abs(fluctuations(floor(mode, args.oversample))) ** 2
            ratio = band_power(power, m) / walk
            left = over_surface(power, single0, walk0, walk)
            samples = [over_surface(power, single0, a, b) for a, b in zip(walk0_k, walk_k)]
            error = jackknife_sd(np.stack(samples))
            print(f"small_angle ({spread}) / walk:\n", ratio)
            print(f"small_angle ({spread}) / walk, over the band's surface factor:\n", ratio / surface)
            print(f"small_angle ({spread}) / walk, over each ring's surface factor:\n", left)
            print("... its jackknife standard error (both walks' noise, over the seeds):\n", error)
            print("... its difference from 1 in those units:\n", (left - 1.0) / error)
            print(f"range over the rings' surface factor ({spread}): {left.min():.3f}–{left.max():.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
