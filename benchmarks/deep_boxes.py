"""Does light scattered widely wash out the long waves' focusing deep down? The small-angle transfer
against the random walk at metre scales: ``python -m benchmarks.deep_boxes``.

Darecki et al. (2011)'s conditions at their deepest depth (``configs/field/darecki2011.toml`` at
9.58 m: b z ≈ 5.7, almost all the light scattered) on a 512² sea over 32 m (the peak waves, 10.6 m
long, kept; the short ones, which do not change the CV down there, dropped), a point sun and no
sky, the whole patch's floor map on 25 cm texels. The spatial spread of the map's means over boxes
1, 2 and 4 m across (the field comparison's 2 m window is such a box) by single scattering (the
unscattered pattern), by the small-angle transfer (``optics.scattering = "small_angle"``, with
either ``optics.beam_spread``), and by
the random walk (``"multiple"``, 64 photons per cell, which scatters at every angle and lengthens
its paths as it does), with the walk's photon noise taken out by the covariance of two seeds.
Prints each relative standard deviation and the small-angle map's over the walk's. About two
minutes on one core.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
EXTENT_M = 32.0
MAP = 128
SCENE = {"floor.depth_m": 9.58, "water.resolution": 512, "caustics.map_extent_m": 0.0,
         "caustics.map_resolution": MAP, "sun.angular_diameter_deg": 0.0, "sky.model": "none",
         "sky.diffuse_fraction": 0.0, "stats.collector_mm": 0.0, "optics.mc_samples": 8}


def box_spread(maps: list[np.ndarray], box_m: float) -> np.ndarray:
    """(K,) the relative standard deviation of the box means of one map, or, given two independent
    maps of the same field, the square root of their covariance (the noise of each taken out)."""
    b = int(round(box_m / (EXTENT_M / MAP)))

    def relative(a: np.ndarray) -> np.ndarray:
        k, m, _ = a.shape
        means = np.asarray(a, np.float64).reshape(k, m // b, b, m // b, b).mean(axis=(2, 4))
        return means / means.mean(axis=(1, 2), keepdims=True) - 1.0

    r = [relative(a) for a in maps]
    if len(r) == 1:
        return r[0].std(axis=(1, 2))
    return np.sqrt(np.maximum((r[0] * r[1]).mean(axis=(1, 2)), 0.0))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--time", type=float, default=0.0, help="the sea's time [s] (default 0)")
    args = parser.parse_args(argv)
    import warpcaustics as wc

    def floor(mode: str, seed: int = 1, spread: str = "wells") -> np.ndarray:
        scene = wc.load_scene(ROOT / "configs/field/darecki2011.toml",
                              {**SCENE, "optics.scattering": mode, "optics.mc_seed": seed,
                               "optics.beam_spread": spread})
        return wc.render(scene, time_s=args.time, device="cpu").floor_irradiance

    start = time.perf_counter()
    single = floor("single")
    small = {spread: floor("small_angle", spread=spread) for spread in ("wells", "walk")}
    walks = [floor("multiple", seed) for seed in (1, 2)]
    np.set_printoptions(precision=4, suppress=True)
    print(f"9.58 m, 512² over 32 m, 25 cm texels; rows of each array: the config's bands "
          f"({time.perf_counter() - start:.0f} s)")
    for box in (1.0, 2.0, 4.0):
        s_single = box_spread([single], box)
        s_walk = box_spread(walks, box)
        noise = np.sqrt(np.maximum(box_spread(walks[:1], box) ** 2 - s_walk**2, 0.0))
        print(f"{box:g} m boxes: single {s_single}  walk {s_walk} (one walk's noise {noise})")
        for spread, a in small.items():
            s_small = box_spread([a], box)
            print(f"    small_angle ({spread} spread) {s_small}  small_angle / walk {s_small / s_walk}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
