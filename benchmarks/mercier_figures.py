"""Mercier 2013's figures from our configs: ``python -m benchmarks.mercier_figures``.

- Fig. 1, "Evolution of caustics in the pool scene. The water surface is initialized as a Gaussian
  bump and animated with a wave simulation": ``configs/mercier_pool.toml`` (a 2 m pool 1.9 m deep,
  128³ eikonal grid) at several times, by the eikonal method plain and with §3.3's threshold
  post-process, beside the flux-ratio map of the same frames; the correlation of each with the
  flux-ratio map. Writes ``docs/images/mercier_fig1.png`` (rows: flux ratio, eikonal, eikonal with
  §3.3; columns: the times).
- Fig. 7, "Buried in sand scene computed with photon mapping and the marching method":
  ``configs/buried_in_sand.toml`` (three objects half buried in a 10° sand slope under a wave pool)
  at t = 1 s by photons (the reference panel; ours light the objects too, the paper's did not), and
  the sand alone by photons and by the eikonal method on a 256³ grid (the paper's size) plain and
  with §3.3's post-process: the eikonal texture sampled at the slope's heights (its "marching"
  panels; as in the paper, without the objects, whose shadows and caustics the texture does not
  know); correlation and relative L1 of each against the photons' sand. Writes
  ``docs/images/mercier_fig7.png`` (photons with the objects, photons' sand, eikonal, with §3.3).

CPU, a few minutes (``--fig1`` / ``--fig7``: one of them); ``--quick`` renders both on 64³ grids and
writes no picture.
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


FIG7_TIME_S = 1.0
"""Fig. 7's frame [s]: the config's two drops spread into rings over the sand."""


def buried_in_sand(overrides: dict | None = None, device: str = "cpu") -> tuple[dict, dict]:
    """Fig. 7's panels (band-summed floor maps) and the eikonal variants' correlation, relative L1
    and contrast against the photons' map of the sand alone."""
    import warpcaustics as wc
    from warpcaustics.io.comparison import map_correlation, relative_l1

    sand = {"receivers": [], "camera.enabled": False}
    eikonal = {**sand, "caustics.method": "eikonal", "caustics.eikonal_resolution": 256}
    variants = {"photons_objects": {"camera.enabled": False}, "photons": sand, "eikonal": eikonal,
                "eikonal_threshold": {**eikonal, **THRESHOLD}}
    results = {}
    for name, extra in variants.items():
        scene = wc.load_scene(ROOT / "configs" / "buried_in_sand.toml", {**extra, **(overrides or {})})
        results[name] = wc.Renderer(scene, device).render(FIG7_TIME_S)
    widths = results["photons"].bin_widths_nm
    maps = {name: (r.floor_irradiance * widths[:, None, None]).sum(0) for name, r in results.items()}
    reference = results["photons"].floor_irradiance
    row = {"time_s": FIG7_TIME_S, "contrast_photons": float(maps["photons"].std() / maps["photons"].mean())}
    for name in ("eikonal", "eikonal_threshold"):
        r = results[name]
        row[f"correlation_{name}"] = map_correlation(r.floor_irradiance, reference, widths)
        row[f"relative_l1_{name}"] = relative_l1(r.floor_irradiance, reference)
        row[f"contrast_{name}"] = float(maps[name].std() / maps[name].mean())
    print(f"mercier      fig. 7 t={FIG7_TIME_S:.1f} s | against the photons' sand: eikonal correlation "
          f"{row['correlation_eikonal']:.3f}, L1 {row['relative_l1_eikonal']:.3f}; with §3.3 "
          f"{row['correlation_eikonal_threshold']:.3f}, {row['relative_l1_eikonal_threshold']:.3f} | "
          f"contrast photons {row['contrast_photons']:.3f}, eikonal {row['contrast_eikonal']:.3f}, "
          f"with §3.3 {row['contrast_eikonal_threshold']:.3f}", flush=True)
    return row, maps


def grey_grid(rows: list[list[np.ndarray]], path: Path) -> None:
    """Rows of maps already divided by their scale, as grey tiles (clipped to [0, 1], gamma 2.2,
    +y up) 4 white pixels apart."""
    from warpcaustics.io.png import write_png

    lines = []
    for row in rows:
        tiles = [x for m in row for x in (np.clip(m[::-1], 0, 1) ** (1 / 2.2), np.ones((m.shape[0], 4)))]
        lines.append(np.concatenate(tiles[:-1], axis=1))
        lines.append(np.ones((4, lines[-1].shape[1])))
    grey = np.concatenate(lines[:-1], axis=0)
    write_png(path, np.repeat((grey * 255).astype(np.uint8)[..., None], 3, axis=2))


def fig7_picture(maps: dict, path: Path) -> None:
    """The four panels side by side, grey, each scaled by the photons' sand mean; +y up."""
    scale = 2.5 * maps["photons"].mean()
    names = ("photons_objects", "photons", "eikonal", "eikonal_threshold")
    grey_grid([[maps[name] / scale for name in names]], path)


def picture(maps: dict, path: Path) -> None:
    """Rows of grey maps (flux ratio, eikonal, eikonal with §3.3), each frame scaled by its flux
    ratio's mean so that the rows compare; +y up."""
    grey_grid([[m / (2.5 * maps["fluxratio"][i].mean()) for i, m in enumerate(maps[name])]
               for name in ("fluxratio", "eikonal", "eikonal_threshold")], path)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="both figures on 64³ grids, no picture")
    parser.add_argument("--fig1", action="store_true", help="Fig. 1 only")
    parser.add_argument("--fig7", action="store_true", help="Fig. 7 only")
    args = parser.parse_args(argv)
    small = {"caustics.eikonal_resolution": 64, "water.resolution": 64, "caustics.map_resolution": 64}
    if args.quick:
        evolution((0.0, 0.3), small)
        buried_in_sand({**small, "caustics.photon_subdivisions": 2})
        return 0
    images = ROOT / "docs" / "images"
    if not args.fig7:
        rows, maps = evolution()
        picture(maps, images / "mercier_fig1.png")
        print(f"wrote {images / 'mercier_fig1.png'}")
    if not args.fig1:
        _, maps = buried_in_sand()
        fig7_picture(maps, images / "mercier_fig7.png")
        print(f"wrote {images / 'mercier_fig7.png'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
