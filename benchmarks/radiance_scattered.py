"""The light scattered into a radiance sensor with the caustics along its line of sight:
``python -m benchmarks.radiance_scattered``.

Darecki et al. (2011)'s Fig. 15 (the field data set ``darecki2011_radiance``) takes the light scattered
once into the sensor's 4.5° cone by more than 3° as a uniform background, its mean from
``caustics/path_radiance.py`` (``model_cv_scattered_smooth``). Here the sun's part of it keeps the
caustics it is scattered from: the unscattered sun's irradiance is rendered on ``--slices``
horizontal planes from just below the deepest trough to the sensor (a point sun, its disk's blur and
the cone's added per plane in Fourier space; the layer above as its mean, ``--top``), and each
texel's line of sight gathers them
(:func:`~warpcaustics.caustics.path_radiance.line_of_sight_modulation`); the sky's part stays a
background (the sky's light under the waves varies by a few per cent). For each panel and zenith it
prints the CV as rendered, with the scattered light smooth (as the data set), and with the sun's
scattered light structured, pooled over the frames, beside the record; and the scattered light's own
CV. One core; ``--quick``: small sizes, panel a at one zenith.
"""

from __future__ import annotations

import argparse
import csv
import math
import sys
import time
from pathlib import Path

import numpy as np

from benchmarks.run import ROOT

SCENE = ROOT / "configs/field/darecki2011_radiance.toml"
QUICK = {"water.extent_m": 2.0, "water.resolution": 256, "caustics.map_resolution": 128,
         "sun.disk_samples": 2}
AWAY = (-30.0, -15.0, 0.0)
"""The record's zeniths away from the sun inside Snell's window (the default)."""
TROUGH_MARGIN_M = 0.01
"""How far below the frames' deepest trough the shallowest plane lies."""


def sun_slices(point: dict, depth_m: float, count: int, times: tuple[float, ...], device: str,
               top: str = "mean") -> tuple[list[np.ndarray], np.ndarray, np.ndarray]:
    """The unscattered point sun's irradiance between the surface and the sensor (the point's sea and
    water, no sky, irradiance maps of the whole patch): per frame (count + 1, M, M), and the planes'
    depths and thicknesses. A horizontal plane above the deepest trough would cut the waves, so
    ``count`` planes are midpoints of equal steps from :data:`TROUGH_MARGIN_M` below the deepest
    trough of the frames to the sensor, and the layer above them is one more: the shallowest
    plane's mean (``top = "mean"``) or its pattern (``"pattern"``: a bracket), scaled to the layer's
    middle by the attenuation between the two shallowest planes."""
    import warpcaustics as wc
    from warpcaustics.optics.refraction import height_range

    def scene_at(z: float):
        return wc.load_scene(SCENE, {**point, "floor.depth_m": float(z), "floor.view_fov_deg": 0.0,
                                     "sky.model": "none", "sky.diffuse_fraction": 0.0,
                                     "sun.angular_diameter_deg": 0.0})

    deepest = wc.Renderer(scene_at(depth_m), device=device)
    lowest = min(height_range(deepest.water.at(t), deepest.device)[0] for t in times)
    z_top = -lowest + TROUGH_MARGIN_M
    if z_top >= depth_m:
        raise SystemExit(f"the waves' troughs reach {-lowest:.3f} m, the sensor is at {depth_m:g} m")
    step = (depth_m - z_top) / count
    depths = z_top + (np.arange(count) + 0.5) * step
    frames = [[] for _ in times]
    for z in depths:
        renderer = wc.Renderer(scene_at(z), device=device)
        for f, t in enumerate(times):
            frames[f].append(renderer.render(t).floor_irradiance[0].astype(np.float64))
    out = []
    for planes in frames:
        first, second = planes[0], planes[1]
        scale = (first.mean() / second.mean()) ** ((depths[0] - 0.5 * z_top) / step)
        layer = scale * (np.full_like(first, first.mean()) if top == "mean" else first)
        out.append(np.stack([layer, *planes]))
    return out, np.concatenate([[0.5 * z_top], depths]), np.concatenate([[z_top], np.full(count, step)])


def pooled_cv(maps: list[np.ndarray]) -> float:
    """CV of all texels of equal-sized maps together."""
    values = np.concatenate([m.ravel() for m in maps])
    return float(values.std() / values.mean())


def point_row(panel: str, zenith: float, rec, point: dict, slices: tuple, times, device: str) -> dict:
    """Render the sensor at ``zenith`` for each frame, and its CVs with the scattered light smooth and
    structured (the module docstring)."""
    import warpcaustics as wc
    from warpcaustics.batch.field.darecki2011_radiance import near_gains, view
    from warpcaustics.caustics.path_radiance import (
        line_of_sight_modulation,
        sensor_path_radiance,
        sun_disk_footprint,
    )
    from warpcaustics.caustics.view import view_axis

    scene = wc.load_scene(SCENE, {**point, **view(zenith)})
    renderer = wc.Renderer(scene, device=device)
    began = time.perf_counter()
    results = [renderer.render(t) for t in times]
    rendered = (time.perf_counter() - began) / len(times)
    total = [r.floor_irradiance[0].astype(np.float64) for r in results]
    sky = [r.sky_floor_irradiance[0].astype(np.float64) for r in results]
    direct = [t - s for t, s in zip(total, sky)]
    scattered = sensor_path_radiance(scene)
    wide_sun, wide_sky = float(scattered.wide_sun[0]), float(scattered.wide_sky[0])
    *gains, unseen = near_gains(scattered, float(np.mean([d.mean() for d in direct])),
                                float(np.mean([s.mean() for s in sky])))
    background = wide_sky + unseen
    cfg = scene.config
    c = float(results[0].attenuation_per_m[0])
    axis = view_axis(cfg.floor.view_zenith_deg, cfg.floor.view_azimuth_deg)
    disk = sun_disk_footprint(scene.sun_direction, cfg.sun.angular_diameter_deg, float(results[0].ior[0]))
    texel = results[0].map_extent_m / total[0].shape[-1]
    maps, depths, thickness = slices
    began = time.perf_counter()
    modulation = [line_of_sight_modulation(s, depths, texel, depth_m=cfg.floor.depth_m, axis=axis,
                                           fov_deg=cfg.floor.view_fov_deg, c=c, thickness_m=thickness,
                                           sun_disk=disk) for s in maps]
    gathered = (time.perf_counter() - began) / len(times)
    kept = [gains[0] * d + gains[1] * s for d, s in zip(direct, sky)]
    smooth = [k + background + wide_sun for k in kept]
    structured = [k + background + wide_sun * f for k, f in zip(kept, modulation)]
    light = [background + wide_sun * f for f in modulation]
    measured = float(rec.cv[int(np.argmin(np.abs(rec.zenith_deg - zenith)))])
    corr = np.corrcoef(np.concatenate([k.ravel() for k in kept]),
                       np.concatenate([f.ravel() for f in modulation]))
    row = {"panel": panel, "zenith_deg": zenith, "measured_cv": measured,
           "model_cv": pooled_cv(total), "model_cv_scattered_smooth": pooled_cv(smooth),
           "model_cv_scattered_structured": pooled_cv(structured),
           "scattered_share": (wide_sun + wide_sky) / float(np.mean([s.mean() for s in structured])),
           "sun_share_of_scattered": wide_sun / (wide_sun + wide_sky),
           "scattered_light_cv": pooled_cv(light), "sun_scattered_cv": pooled_cv(modulation),
           "correlation_with_map": float(corr[0, 1]), "slices": len(depths) - 1,
           "trough_m": float(thickness[0]) - TROUGH_MARGIN_M, "frames": len(times),
           "radiance_frame_s": rendered, "modulation_s": gathered}
    row["structured_over_measured"] = row["model_cv_scattered_structured"] / measured
    return row


def run(quick: bool, device: str, panels: tuple[str, ...] = ("a", "b", "c"),
        zeniths: tuple[float, ...] = AWAY, slices: int = 16, frames: int = 2, top: str = "mean") -> dict:
    """Every panel's points (``quick``: panel a at the zenith, small sizes, 4 planes, one frame), and
    the cost: the planes of a frame against its radiance frame (the baseline), and the gathering."""
    from benchmarks.radiance import panel_overrides
    from benchmarks.run import device_record

    if quick:
        panels, zeniths, slices, frames = ("a",), (0.0,), 4, 1
    times = tuple(5.0 * i for i in range(frames))
    rows, costs = [], []
    for panel in panels:
        began = time.perf_counter()
        point, rec = panel_overrides(panel, quick)
        planes = sun_slices(point, float(rec.depth_m), slices, times, device, top)
        sliced = (time.perf_counter() - began) / len(times)
        for zenith in zeniths:
            row = point_row(panel, zenith, rec, point, planes, times, device)
            rows.append(row)
            print(f"{panel} {zenith:+5.0f}°: measured {row['measured_cv']:.3f}, as rendered "
                  f"{row['model_cv']:.3f}, scattered smooth {row['model_cv_scattered_smooth']:.3f}, "
                  f"structured {row['model_cv_scattered_structured']:.3f} "
                  f"(/ measured {row['structured_over_measured']:.2f}); scattered share "
                  f"{row['scattered_share']:.3f} (the sun's {row['sun_share_of_scattered']:.2f}), its CV "
                  f"{row['scattered_light_cv']:.3f} (the sun's {row['sun_scattered_cv']:.3f}), "
                  f"correlation with the map {row['correlation_with_map']:+.2f}", flush=True)
        frame = float(np.median([r["radiance_frame_s"] for r in rows if r["panel"] == panel]))
        costs.append({"panel": panel, "planes_per_frame_s": sliced, "radiance_frame_s": frame,
                      "ratio": sliced / frame})
        print(f"panel {panel}: {slices} planes below {2.0 * planes[1][0]:.3f} m (--top {top}), "
              f"{sliced:.1f} s a frame against its radiance frame's {frame:.1f} s: x{sliced / frame:.2f}; "
              f"gathering them {rows[-1]['modulation_s']:.2f} s", flush=True)
    return {"benchmark": "radiance_scattered", **device_record(device), "quick": quick, "slices": slices,
            "frames": frames, "top": top, "rows": rows, "costs": costs}


def main(argv: list[str] | None = None) -> int:
    from warpcaustics.cli import _signed_lists

    from benchmarks.run import save_record

    p = argparse.ArgumentParser(prog="python -m benchmarks.radiance_scattered",
                                description=__doc__.splitlines()[0])
    p.add_argument("--panels", default="a,b,c", help="the record's panels (default a,b,c)")
    p.add_argument("--view-zeniths", default=",".join(f"{z:g}" for z in AWAY),
                   help="signed zeniths, + towards the sun (default -30,-15,0: away from it)")
    p.add_argument("--slices", type=int, default=16, help="planes between the surface and the sensor (16)")
    p.add_argument("--frames", type=int, default=2, help="frames 5 s apart, as the data set (2)")
    p.add_argument("--top", choices=("mean", "pattern"), default="mean",
                   help="the layer above the deepest trough: the shallowest plane's mean (default) or its "
                        "pattern (a bracket)")
    p.add_argument("--quick", action="store_true", help="small sizes, panel a at one zenith")
    p.add_argument("--device", default="cpu")
    p.add_argument("--csv", type=Path, default=None, help="write the rows here")
    args = p.parse_args(_signed_lists(sys.argv[1:] if argv is None else list(argv)))  # --view-zeniths -30,0
    if args.slices < 2 or args.frames < 1:
        p.error("--slices must be at least 2 and --frames at least 1")
    record = run(args.quick, args.device, tuple(s.strip() for s in args.panels.split(",") if s.strip()),
                 tuple(float(z) for z in args.view_zeniths.split(",")), args.slices, args.frames, args.top)
    save_record(record, None, "radiance_scattered", args.quick, args.device)
    if args.csv:
        args.csv.parent.mkdir(parents=True, exist_ok=True)
        with open(args.csv, "w", newline="", encoding="utf-8") as fh:
            writer = csv.DictWriter(fh, fieldnames=list(record["rows"][0]))
            writer.writeheader()
            writer.writerows({k: round(v, 5) if isinstance(v, float) and math.isfinite(v) else v
                              for k, v in r.items()} for r in record["rows"])
        print(f"wrote {args.csv}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
