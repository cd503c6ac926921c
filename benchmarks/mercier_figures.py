"""Mercier 2013's figures from our configs: ``python -m benchmarks.mercier_figures``.

- Fig. 1, "Evolution of caustics in the pool scene. The water surface is initialized as a Gaussian
  bump and animated with a wave simulation": ``configs/mercier_pool.toml`` (a 2 m pool 1.9 m deep,
  128³ eikonal grid) at several times, by the eikonal method plain and with §3.3's threshold
  post-process, beside the flux-ratio map of the same frames; the correlation of each with the
  flux-ratio map. Writes ``docs/images/mercier_fig1.png`` (rows: flux ratio, eikonal, eikonal with
  §3.3; columns: the times).
- Fig. 7, the *buried in sand* scene, is ``configs/buried_in_sand.toml`` by photons (the paper's
  reference panel; README picture by ``python -m benchmarks.previews``): our eikonal grid lights a
  flat floor only, so the paper's marching panels are not reproduced.

CPU, about a minute; ``--quick`` renders two times at a 64³ grid and writes no picture.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]

TIMES_S = (0.0, 0.2, 0.4, 0.6, 0.9, 1.2)
"""Frames of Fig. 1's evolution [s]: the bump, its ring leaving, and the ring off the walls."""
THRESHOLD = {"caustics.eikonal_threshold_depth_m": 1.2, "caustics.eikonal_spread_deg": 5.0}
"""§3.3's post-process as docs/validation.md measured it best on this scene (chosen by eye, as
Mercier chose his)."""


def evolution(times=TIMES_S, overrides: dict | None = None, device: str = "cpu") -> tuple[list[dict], dict]:
    """Rows (time, correlation and relative L1 of the plain and post-processed eikonal maps vs the
    flux-ratio map, contrasts) and the band-summed maps by variant (lists over ``times``)."""
    import warpcaustics as wc
    from warpcaustics.io.comparison import map_correlation, relative_l1

    variants = {"eikonal": {}, "eikonal_threshold": THRESHOLD}
    renderers = {name: wc.Renderer(wc.load_scene(ROOT / "configs" / "mercier_pool.toml",
                                                 {**(overrides or {}), **extra}), device)
                 for name, extra in variants.items()}
    rows = []
    maps = {"fluxratio": [], **{name: [] for name in variants}}
    for t in times:
        row = {"time_s": float(t)}
        for name, renderer in renderers.items():  # the pool steps forward in each renderer alike
            result = renderer.render(float(t))
            reference = result.comparison
            row[f"correlation_{name}"] = map_correlation(result.floor_irradiance, reference.floor_irradiance,
                                                         result.bin_widths_nm)
            row[f"relative_l1_{name}"] = relative_l1(result.floor_irradiance, reference.floor_irradiance)
            summed = (result.floor_irradiance * result.bin_widths_nm[:, None, None]).sum(0)
            row[f"contrast_{name}"] = float(summed.std() / summed.mean())
            maps[name].append(summed)
            if name == "eikonal":
                ref = (reference.floor_irradiance * result.bin_widths_nm[:, None, None]).sum(0)
                row["contrast_fluxratio"] = float(ref.std() / ref.mean())
                maps["fluxratio"].append(ref)
        rows.append(row)
        print(f"mercier      fig. 1 t={t:4.1f} s | correlation with the flux-ratio map: eikonal "
              f"{row['correlation_eikonal']:.3f}, with §3.3 {row['correlation_eikonal_threshold']:.3f} | "
              f"contrast flux ratio {row['contrast_fluxratio']:.3f}, eikonal {row['contrast_eikonal']:.3f}, "
              f"with §3.3 {row['contrast_eikonal_threshold']:.3f}", flush=True)
    return rows, maps


def picture(maps: dict, path: Path) -> None:
    """Rows of grey maps (flux ratio, eikonal, eikonal with §3.3), each frame scaled by its flux
    ratio's mean so that the rows compare; +y up."""
    from warpcaustics.io.png import write_png

    rows = []
    for name in ("fluxratio", "eikonal", "eikonal_threshold"):
        tiles = []
        for i, m in enumerate(maps[name]):
            scale = 2.5 * maps["fluxratio"][i].mean()
            tiles.append(np.clip(m[::-1] / scale, 0, 1) ** (1 / 2.2))
            tiles.append(np.ones((m.shape[0], 4)))
        rows.append(np.concatenate(tiles[:-1], axis=1))
        rows.append(np.ones((4, rows[-1].shape[1])))
    grey = np.concatenate(rows[:-1], axis=0)
    write_png(path, np.repeat((grey * 255).astype(np.uint8)[..., None], 3, axis=2))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="two times on a 64³ grid, no picture")
    args = parser.parse_args(argv)
    if args.quick:
        evolution((0.0, 0.3), {"caustics.eikonal_resolution": 64, "water.resolution": 64,
                               "caustics.map_resolution": 64})
        return 0
    rows, maps = evolution()
    path = ROOT / "docs" / "images" / "mercier_fig1.png"
    picture(maps, path)
    print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
