"""A radiance sensor at every texel (``floor.view_*``): its cost, and the model against Darecki et al.
(2011)'s Fig. 15: ``python -m benchmarks.radiance [--fig15]``.

``run`` (``benchmarks.run``'s child; ``--quick``: small sizes): a warm frame of the Darecki set-up
(``configs/field/darecki2011.toml`` at 532 nm, single scattering, a point radiance sensor: 2048²
cells over 8 m, the whole patch on 1024² texels) with the sensor looking at the refracted sun,
against the same frame's irradiance map (the baseline), one core; and the sky's kernel against its
float64 numpy twin (``reference/view.py``) on the same texels.

``--fig15``: Darecki, Stramski & Sokolski (2011), Fig. 15 (``jerlov.darecki2011_radiance_cv``): the
CV of the radiance at 532 nm in a 4.5° field of view at thirteen zenith angles in the sun's plane
(positive towards the sun), in three panels (a: 0.93 m, sun 33°, 7 m/s, c(555) 0.65; b: 0.59 m,
41°, 5.4 m/s, 0.31; c: 0.54 m, 35°, 3.6 m/s, 0.31). The model renders each panel's conditions (the
Darecki set-up's Elfouhaily sea at the panel's wind, its bio-optical water at the panel's c(555),
the CIE clear sky at the set-up's 18 % diffuse share) at the nine zeniths inside Snell's window
(±40°; beyond it the sensor sees the upwelling light, which is not modelled), ``--frames`` frames 5 s
apart, the whole 8 m patch on ``--texels`` texels a side, and pools each point's texels and frames.
The scattered light is left out (``optics.scattering = "single"``): where it is smooth it only
lowers the CV, so the model's CV is an upper bound on what its surface gives. Each row also gives
the share of the texels that see the sun at all (its light above a tenth of the sky's mean): the
off-sun CV of the record is that of rare, bright glints. ``--panels`` and ``--zeniths`` choose
points; ``--workers`` renders points in parallel processes.
"""

from __future__ import annotations

import argparse
import math
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from benchmarks.run import ROOT, device_record, interleaved_times

SCENE = ROOT / "configs/field/darecki2011.toml"
SET_UP = {"optics.wavelengths": [532.0], "stats.per_band": False, "optics.scattering": "single",
          "optics.beam_spread": "wells", "water.extent_m": 8.0, "water.resolution": 2048,
          "caustics.map_extent_m": 0.0, "caustics.map_resolution": 1024, "sun.disk_samples": 8,
          "sky.model": "cie_clear", "stats.collector_mm": 0.0, "floor.view_fov_deg": 4.5}
"""The Darecki set-up as a radiance sensor: one band, the scattered light left out, the converged
surface (3.9 mm cells over 8 m), the whole patch's texels, a point sensor of 4.5°."""

QUICK = {"water.extent_m": 2.0, "water.resolution": 256, "caustics.map_resolution": 128,
         "sun.disk_samples": 2}

IN_WINDOW_DEG = 40.0
"""The record's zeniths the model takes: a 4.5° cone about them lies inside Snell's window (48.6°)."""

SUN_SHARE = 0.1
"""A texel sees the sun where the sun's light in its cone exceeds this share of the sky's mean."""


def panel_overrides(panel: str, quick: bool = False) -> tuple[dict, object]:
    """The set-up at ``panel``'s conditions (depth, sun, wind, the water's c(555)) and the panel."""
    import jerlov

    import warpcaustics as wc
    from warpcaustics.batch.field.darecki2011 import chlorophyll_for

    rec = jerlov.darecki2011_radiance_cv(panel)
    base = {**SET_UP, **(QUICK if quick else {})}
    config = wc.load_scene(SCENE, base).config
    chlorophyll = chlorophyll_for(config, float(rec.beam_attenuation_555))
    sun = {"sun.elevation_deg": 90.0 - float(rec.sun_zenith_deg)}
    return {**base, "floor.depth_m": float(rec.depth_m), **sun, "water.wind_speed_m_s": float(rec.wind_m_s),
            "optics.chlorophyll_mg_m3": chlorophyll}, rec


def view(zenith_deg: float) -> dict:
    """The sensor's axis at a signed zenith in the sun's plane (the sun at azimuth 0; positive towards
    it)."""
    return {"floor.view_zenith_deg": abs(zenith_deg),
            "floor.view_azimuth_deg": 0.0 if zenith_deg >= 0 else 180.0}


def point(args: tuple) -> dict:
    """One (panel, zenith): its frames' pooled CV, the share of texels that see the sun, the sky's
    share of the mean."""
    import warpcaustics as wc
    from warpcaustics.batch.field.common import pooled_statistics

    panel, zenith, frames, texels, wind_direction, quick = args
    overrides, rec = panel_overrides(panel, quick)
    overrides["water.wind_direction_deg"] = wind_direction
    if texels:
        overrides["caustics.map_resolution"] = texels
    renderer = wc.Renderer(wc.load_scene(SCENE, {**overrides, **view(zenith)}), device="cpu")
    began = time.perf_counter()
    stats, sees_sun, sky_share = [], [], []
    for i in range(frames):
        r = renderer.render(5.0 * i)
        total = r.floor_irradiance[0].astype(np.float64)
        sky = r.sky_floor_irradiance[0].astype(np.float64)
        stats.append((float(total.mean()), float(total.std() / total.mean())))
        sees_sun.append(float(np.mean(total - sky > SUN_SHARE * sky.mean())))
        sky_share.append(float(sky.mean() / total.mean()))
    mean, cv = pooled_statistics(stats)
    k = int(np.argmin(np.abs(rec.zenith_deg - zenith)))
    measured = float(rec.cv[k])
    return {"panel": panel, "zenith_deg": zenith, "measured_cv": measured, "model_cv": round(cv, 4),
            "model_over_measured": round(cv / measured, 3), "sees_sun": float(np.mean(sees_sun)),
            "sky_share": round(float(np.mean(sky_share)), 4), "frames": frames,
            "wind_direction_deg": wind_direction,
            "texel_mm": round(1e3 * overrides["water.extent_m"] / overrides["caustics.map_resolution"], 2),
            "seconds": round(time.perf_counter() - began, 1)}


def fig15(panels, zeniths, frames: int, texels: int, wind_direction: float, workers: int,
          quick: bool) -> list[dict]:
    import jerlov

    jobs = []
    for panel in panels:
        rec = jerlov.darecki2011_radiance_cv(panel)
        for z in rec.zenith_deg:
            if abs(z) <= IN_WINDOW_DEG and (zeniths is None or any(abs(z - w) < 1e-6 for w in zeniths)):
                jobs.append((panel, float(z), frames, texels, wind_direction, quick))
    with ProcessPoolExecutor(max_workers=workers) as pool:
        rows = []
        for row in pool.map(point, jobs):
            print(f"Fig. 15{row['panel']} {row['zenith_deg']:+5.0f} deg: measured {row['measured_cv']:.3f}, "
                  f"model {row['model_cv']:.3f} (x{row['model_over_measured']:.2f}); texels seeing the sun "
                  f"{row['sees_sun']:.2e}, sky {row['sky_share']:.1%} of the mean, {row['seconds']} s",
                  flush=True)
            rows.append(row)
    return rows


def run(quick: bool, device: str) -> dict:
    """The radiance frame against the irradiance frame, and the sky's kernel against numpy."""
    import warpcaustics as wc
    from warpcaustics.caustics.view import view_axis
    from warpcaustics.caustics.window import MapWindow
    from warpcaustics.reference.view import view_sky

    overrides, rec = panel_overrides("b", quick)
    rounds = 2 if quick else 3
    renderers = {}
    for name, extra in (("irradiance", {"floor.view_fov_deg": 0.0}),
                        ("radiance", view(float(rec.refracted_sun_zenith_deg)))):
        renderers[name] = wc.Renderer(wc.load_scene(SCENE, {**overrides, **extra}), device=device)
        renderers[name].render(0.0)  # warm-up: the kernels
    times = interleaved_times({name: (lambda r=r: r.render(0.5), 1) for name, r in renderers.items()}, rounds,
                              device)
    frame = {name: float(np.median(t)) for name, t in times.items()}
    scene = renderers["radiance"].scene
    result = renderers["radiance"].render(0.5)
    window = MapWindow(scene.config)
    cfg = scene.config.floor
    began = time.perf_counter()
    view_sky(result.surface_positions.astype(np.float64), result.surface_normals.astype(np.float64),
             result.extent_m, window.texel_x, window.texel_y, -cfg.depth_m,
             view_axis(cfg.view_zenith_deg, cfg.view_azimuth_deg), cfg.view_fov_deg, 12, scene.sun_direction,
             scene.sky_irradiance(result.sun_irradiance), result.ior.astype(np.float64),
             result.attenuation_per_m.astype(np.float64))
    numpy_sky = time.perf_counter() - began
    kernel_sky = result.timings_s.get("sky", math.nan)
    ratio = frame["radiance"] / frame["irradiance"]
    print(f"radiance frame {frame['radiance']:.2f} s, irradiance frame {frame['irradiance']:.2f} s: "
          f"x{ratio:.2f}; the sky's trace {kernel_sky:.2f} s (kernel) against {numpy_sky:.2f} s "
          f"(float64 numpy): x{numpy_sky / kernel_sky:.1f}")
    return {"benchmark": "radiance", **device_record(device), "quick": quick, "rounds": rounds,
            "overrides": overrides, "frame_seconds": frame, "radiance_over_irradiance": ratio,
            "sky_seconds": {"kernel": kernel_sky, "numpy_float64": numpy_sky}}


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m benchmarks.radiance", description=__doc__.splitlines()[0])
    p.add_argument("--fig15", action="store_true", help="the model against Darecki et al. (2011)'s Fig. 15")
    p.add_argument("--panels", default="a,b,c", help="--fig15: panels, comma-separated (default a,b,c)")
    p.add_argument("--zeniths", default=None, help="--fig15: the record's zeniths [deg] (default ±40 and in)")
    p.add_argument("--frames", type=int, default=2, help="--fig15: frames per point, 5 s apart (default 2)")
    p.add_argument("--texels", type=int, default=0,
                   help="--fig15: texels a side of the 8 m patch (default 1024)")
    p.add_argument("--wind-direction", type=float, default=0.0,
                   help="--fig15: the wind's azimuth from the sun's [deg] (default 0: the sensor's plane "
                        "up-wind, where the slopes are steepest; the paper gives none)")
    p.add_argument("--workers", type=int, default=1, help="--fig15: processes (default 1)")
    p.add_argument("--plot", type=Path, default=None, help="--fig15: a PNG of CV against zenith per panel")
    p.add_argument("--csv", type=Path, default=None, help="--fig15: write the rows here")
    p.add_argument("--quick", action="store_true", help="small sizes")
    p.add_argument("--device", default="cpu")
    p.add_argument("--out", type=Path, default=None)
    args = p.parse_args(argv)
    if not args.fig15:
        from benchmarks.run import module_main

        rest = (["--quick"] if args.quick else []) + ["--device", args.device]
        return module_main(rest + (["--out", str(args.out)] if args.out else []), "radiance", run, __doc__)
    if args.csv is not None and not args.csv.parent.is_dir():
        p.error(f"--csv: the folder {args.csv.parent} does not exist")
    zeniths = None if args.zeniths is None else [float(z) for z in args.zeniths.split(",")]
    for path in (args.csv, args.plot):
        if path is not None and not path.parent.is_dir():
            p.error(f"the folder {path.parent} does not exist")
    rows = fig15(args.panels.split(","), zeniths, args.frames, args.texels, args.wind_direction, args.workers,
                 args.quick)
    if args.csv is not None:
        from warpcaustics.io.files import write_csv

        write_csv(args.csv, rows)
    if args.plot is not None:
        plot(rows, args.plot)
    return 0


def plot(rows: list[dict], path: Path) -> None:
    """CV against the zenith per panel, as Fig. 15: the record's thirteen angles and the model's."""
    import jerlov

    from warpcaustics.io.files import pyplot

    plt = pyplot("the Fig. 15 plot needs")
    panels = sorted({r["panel"] for r in rows})
    fig, axes = plt.subplots(1, len(panels), figsize=(4.2 * len(panels), 3.8), sharey=True, squeeze=False)
    for ax, panel in zip(axes[0], panels):
        rec = jerlov.darecki2011_radiance_cv(panel)
        rs = sorted((r for r in rows if r["panel"] == panel), key=lambda r: r["zenith_deg"])
        ax.plot(rec.zenith_deg, rec.cv, "ko-", label="Darecki et al. 2011, Fig. 15")
        ax.plot([r["zenith_deg"] for r in rs], [r["model_cv"] for r in rs], "s--", color="tab:blue",
                label="model, unscattered light")
        ax.axvline(rec.refracted_sun_zenith_deg, color="tab:orange", lw=0.8, label="refracted sun")
        ax.set_yscale("log")
        ax.set_title(f"{panel}: {rec.depth_m:g} m, sun {rec.sun_zenith_deg:g}°, {rec.wind_m_s:g} m/s",
                     fontsize=9)
        ax.set_xlabel("zenith angle [deg] (+: towards the sun)")
        ax.grid(alpha=0.3, which="both")
    axes[0][0].set_ylabel("CV of radiance, 532 nm, 4.5° FOV")
    axes[0][0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


if __name__ == "__main__":
    sys.exit(main())
