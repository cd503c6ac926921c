"""Beam caustics (``caustics.method = "beams"``): the tile rasteriser in Warp vs a vectorised numpy twin.

The numpy twins are ``warpcaustics/reference/beams.py``. Both sides get the same beams and the same
tile lists (built by the Warp stage and read back), so the ratio measures the per-pixel work alone:

- **surface gather** (``kernels/caustics/beams/irradiance.py`` ``point_irradiance``): for every
  receiver point, the point-in-beam test of each beam in its horizontal tile, the flat flux
  density, the receiver's cosine factor and the attenuation, summed per band. Points: a regular
  grid of points (4×4 per map texel) on a rippled floor under the default ocean, shadows by the
  beams' end planes.
- **volume scan planes** (``scan_plane_radiance``): for every camera pixel, the oriented-box test
  and the scan-plane chord of each beam copy in its screen tile, then the midpoint pieces of the
  in-scattering integral (Henyey–Greenstein phase), summed per band. Camera: ``ocean_floor.toml``.

numpy runs the pairs (point or pixel, beam) as flat float64 arrays (no Python loop over pixels or
beams; one loop over the ≤ 16 chord pieces) and accumulates with ``bincount``. Scaling rows time the
whole beam stage (build, bin, flat-floor map) against the beam count and the map resolution.
``python -m benchmarks.beams --help``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from warpcaustics.reference import relative_l1
from warpcaustics.reference.beams import (
    beam_arrays,
    camera_dict,
    horizontal_tile,
    numpy_points,
    numpy_volume,
    tile_lists,
)

from benchmarks.beam_fill import VOLUMES, fill_measure
from benchmarks.run import calls_per_round, device_record, interleaved_times, median_time, point_sun_scene

ROOT = Path(__file__).resolve().parents[1]

FULL = {
    "gather_n": 128,
    "gather_m": 128,
    "camera": (160, 120),
    "camera_n": 64,
    "scaling_n": (32, 64, 128, 256),
    "scaling_m": (128, 256, 512, 1024),
    "adaptive_n": 256,
    "adaptive_m": 256,
}
QUICK = {
    "gather_n": 32,
    "gather_m": 64,
    "camera": (64, 48),
    "camera_n": 32,
    "scaling_n": (16, 32),
    "scaling_m": (32, 64),
    "adaptive_n": 32,
    "adaptive_m": 32,
}
WAVELENGTHS = "rgb"


def _gather_case(n: int, m: int, device: str, warp_repeats: int, numpy_repeats: int) -> dict:
    import warp as wp

    import warpcaustics as wc

    scene = point_sun_scene(
        ROOT / "configs" / "ocean.toml",
        {
            "caustics.method": "beams",
            "water.resolution": n,
            "caustics.map_resolution": m,
            "optics.wavelengths": WAVELENGTHS,
            "floor.shape": "ripples",
            "floor.ripple_amplitude_m": 0.1,
            "floor.ripple_wavelength_m": 16.0 / np.hypot(7, 26),
            "floor.ripple_direction_deg": np.degrees(np.arctan2(26, 7)),
        },
    )
    renderer = wc.Renderer(scene, device)
    renderer.render(0.0)  # warm-up: JIT compile, builds and bins the beams
    stage = renderer.method.caustics[0]
    # Both sides decide shadows by the beam's end plane (the twin has no BVH for shadow rays).
    stage.occluders = False
    # Receiver points: (m·4)² points on the rippled relief (what a camera's G-buffer would hold).
    from warpcaustics.scene.receivers import floor_relief_height

    cfg = scene.config
    u = (np.arange(4 * m) + 0.5) * (cfg.water.extent_m / (4 * m)) - 0.5 * cfg.water.extent_m
    x, y = (a.ravel() for a in np.meshgrid(u, u))
    h = 1e-4
    z = floor_relief_height(cfg.floor, None, cfg.water.extent_m, x, y)
    dzdx = (floor_relief_height(cfg.floor, None, cfg.water.extent_m, x + h, y) - z) / h
    dzdy = (floor_relief_height(cfg.floor, None, cfg.water.extent_m, x, y + h) - z) / h
    nrm = np.stack([-dzdx, -dzdy, np.ones_like(z)], -1)
    nrm /= np.linalg.norm(nrm, axis=-1, keepdims=True)
    pts = np.stack([x, y, z], -1)
    args = (wp.array(pts.astype(np.float32), dtype=wp.vec3, device=device),
            wp.array(nrm.astype(np.float32), dtype=wp.vec3, device=device),
            wp.zeros(len(pts), dtype=wp.int32, device=device),
            wp.empty((stage.k, len(pts)), dtype=wp.float32, device=device))

    def warp_run():
        stage.points(*args)

    warp_run()
    wp.synchronize_device(device)
    warp_out = args[3].numpy().astype(np.float64)
    beams = beam_arrays(stage)
    bins = stage.point_bins
    grid = {
        "origin": np.array(bins.grid.origin, np.float64),
        "size": float(bins.grid.size[0]),
        "n": bins.grid.nx,
    }
    tiles = tile_lists(bins)
    points = args[0].numpy().astype(np.float64)
    normals = args[1].numpy().astype(np.float64)

    numpy_out = []

    def numpy_run():
        numpy_out[:] = [numpy_points(beams, tiles, grid, points, normals, stage.extent_m, stage.periodic)]

    times = interleaved_times({"warp": (warp_run, calls_per_round(warp_repeats, numpy_repeats)),
                               "numpy": (numpy_run, 1)}, numpy_repeats, device)
    warp_s, numpy_s = (float(np.median(times[side])) for side in ("warp", "numpy"))
    numpy_out = numpy_out[0]
    pairs = int(tiles[1][horizontal_tile(points, grid, stage.periodic)].sum())
    return {
        "water_n": n,
        "map_m": m,
        "points": len(points),
        "beams": stage.weight.shape[0],
        "pairs": pairs,
        "warp_s": warp_s,
        "numpy_s": numpy_s,
        "speedup_warp_vs_numpy": numpy_s / warp_s,
        "warp_points_per_s": len(points) / warp_s,
        "numpy_points_per_s": len(points) / numpy_s,
        "relative_l1_numpy_vs_warp": relative_l1(numpy_out, warp_out),
    }


def _bounds_case(n: int, size: tuple[int, int], device: str, repeats: int) -> list[dict]:
    """The volume pass with each of ``caustics.beam_bounds``'s volumes on the benchmark camera
    (``configs/ocean_floor.toml``): the shafts' time (a render with shafts minus one without,
    the three volumes timed in turn), the pixels a rasteriser would touch and their fill
    (:func:`fill_measure`), the (pixel, beam) pairs our boxes test, and the image against the
    hull's."""
    import warpcaustics as wc

    cameras = {}
    for kind in VOLUMES:
        scene = point_sun_scene(ROOT / "configs" / "ocean_floor.toml", {
            "caustics.method": "beams", "water.resolution": n, "optics.wavelengths": WAVELENGTHS,
            "camera.width": size[0], "camera.height": size[1],
            "optics.phase_function": "henyey_greenstein", "caustics.beam_bounds": kind})
        renderer = wc.Renderer(scene, device)
        renderer.render(0.0)  # warm-up
        cameras[kind] = (renderer.method.camera, renderer.method.caustics[0])
    sides = {}
    for kind, (camera, stage) in cameras.items():
        sides[f"{kind} with"] = (lambda c=camera, s=stage: c.render_beams(s, True), 1)
        sides[f"{kind} without"] = (lambda c=camera, s=stage: c.render_beams(s, False), 1)
    times = interleaved_times(sides, repeats, device)
    camera, stage = cameras["hull"]
    fill = fill_measure(stage, camera, 3 if stage.periodic else 1, samples=3000)
    rows = []
    reference = None
    for kind, (camera, stage) in cameras.items():
        camera.render_beams(stage, True)
        shafts = camera.shafts.numpy().astype(np.float64)
        reference = shafts if reference is None else reference
        volume_s = max(float(np.median(np.subtract(times[f"{kind} with"], times[f"{kind} without"]))), 1e-9)
        rows.append({"beam_bounds": kind, "water_n": n, "camera_px": list(size), "volume_s": volume_s,
                     **camera.beam_fill(), "raster_pixels": fill[f"{kind}_pixels"],
                     "raster_fill": fill[f"{kind}_fill"], "beams_measured": fill["beams_measured"],
                     "relative_l1_vs_hull": relative_l1(reference, shafts)})
    for r in rows:
        r["time_vs_hull"] = r["volume_s"] / rows[0]["volume_s"]
    return rows


def _volume_case(n: int, size: tuple[int, int], device: str, warp_repeats: int, numpy_repeats: int) -> dict:
    import warp as wp

    import warpcaustics as wc
    from warpcaustics.caustics.beams import SCREEN_TILE_PIXELS

    scene = point_sun_scene(
        ROOT / "configs" / "ocean_floor.toml",
        {
            "caustics.method": "beams",
            "water.resolution": n,
            "optics.wavelengths": WAVELENGTHS,
            "camera.width": size[0],
            "camera.height": size[1],
            "optics.phase_function": "henyey_greenstein",
        },
    )
    renderer = wc.Renderer(scene, device)
    renderer.render(0.0)  # warm-up
    camera, stage = renderer.method.camera, renderer.method.caustics[0]

    camera.render_beams(stage, True)
    wp.synchronize_device(device)
    warp_out = camera.shafts.numpy().astype(np.float64)
    fill = camera.beam_fill()
    fill.update(fill_measure(stage, camera, 3 if stage.periodic else 1, samples=3000))
    bins = camera._screen_bins
    cam_np = camera_dict(camera.cam)
    depth = camera.depth.numpy().astype(np.float64)
    boxes = tuple(a.numpy().astype(np.float64) for a in (bins.box_axis, bins.box_lo, bins.box_hi))
    beams = beam_arrays(stage)
    tiles = tile_lists(bins)
    copies = 3 if stage.periodic else 1

    scattering_per_m = camera.scattering_per_m.numpy().astype(np.float64)
    numpy_out = []

    def numpy_run():
        numpy_out[:] = [numpy_volume(beams, tiles, cam_np, depth, copies, stage.extent_m, boxes,
                                     scattering_per_m, float(camera.phase.g), SCREEN_TILE_PIXELS)]

    # The shafts alone: render_beams also gathers the G-buffer points and shades, so each round
    # times it with and without the shafts and takes the difference.
    calls = calls_per_round(warp_repeats, numpy_repeats)
    times = interleaved_times({"with shafts": (lambda: camera.render_beams(stage, True), calls),
                               "without": (lambda: camera.render_beams(stage, False), calls),
                               "numpy": (numpy_run, 1)}, numpy_repeats, device)
    warp_volume_s = max(float(np.median(np.subtract(times["with shafts"], times["without"]))), 1e-9)
    numpy_s = float(np.median(times["numpy"]))
    numpy_out = numpy_out[0]
    pixels = size[0] * size[1]
    return {
        "water_n": n,
        "camera_px": list(size),
        "beams": stage.weight.shape[0],
        "fill": fill,
        "warp_s": warp_volume_s,
        "numpy_s": numpy_s,
        "speedup_warp_vs_numpy": numpy_s / warp_volume_s,
        "warp_pixels_per_s": pixels / warp_volume_s,
        "numpy_pixels_per_s": pixels / numpy_s,
        "warp_chords_per_s": fill["inside_pairs"] / warp_volume_s,
        "relative_l1_numpy_vs_warp": relative_l1(numpy_out, warp_out),
    }


def _stage_time(n: int, m: int, device: str, repeats: int) -> dict:
    """The whole beam stage on a flat floor (build, bin, clipped texel map) per frame."""
    import warp as wp

    import warpcaustics as wc

    scene = point_sun_scene(
        ROOT / "configs" / "ocean.toml",
        {
            "caustics.method": "beams",
            "water.resolution": n,
            "caustics.map_resolution": m,
            "optics.wavelengths": WAVELENGTHS,
        },
    )
    renderer = wc.Renderer(scene, device)
    renderer.render(0.0)
    surface = renderer.water.at(0.0)

    def run():
        renderer.method.caustics[0].trace(surface, renderer.visible, scene.sun_direction,
                                          renderer.light.sun_irradiance)
        wp.synchronize_device(device)

    s = median_time(run, repeats)
    beams = renderer.method.caustics[0].weight.shape[0]
    return {
        "water_n": n,
        "map_m": m,
        "beams": beams,
        "stage_s": s,
        "beams_per_s": beams / s,
        "texels_per_s": m * m / s,
    }


NEVER_SPLIT = 1.0e6
"""caustics.beam_tolerance's largest value [surface cells]: no refracted ray misses by a million
cells, so the tolerance never splits a quad (the coarse uniform grids' baseline)."""


def _adaptive_rows(config: str, overrides: dict, levels: int, device: str, repeats: int) -> list[dict]:
    """Adaptive beams (caustics.beam_levels) against the uniform grid: beams, frame time and the
    floor map's relative L1 from the uniform grid's, for a range of tolerances; the coarse uniform
    grids (every quad kept at level 1, 2, …: tolerance ∞) are the baselines at equal beam counts."""
    import warpcaustics as wc

    base = {"caustics.method": "beams", "optics.wavelengths": WAVELENGTHS, "optics.water_type": "none",
            **overrides}
    rows = []
    reference = None
    cases = ([(0, 0.0)] + [(levels, t) for t in (0.05, 0.1, 0.25, 0.5, 1.0)]
             + [(lv, NEVER_SPLIT) for lv in range(1, levels + 1)])
    for lv, tol in cases:
        renderer = wc.Renderer(point_sun_scene(ROOT / "configs" / config, {
            **base, "caustics.beam_levels": lv, "caustics.beam_tolerance": tol}), device)
        renderer.render(0.0)  # warm-up
        s = median_time(lambda renderer=renderer: renderer.render(0.0), repeats)
        result = renderer.render(0.0)
        if reference is None:
            reference = result.floor_irradiance.astype(np.float64)
        l1 = relative_l1(reference, result.floor_irradiance)
        label = "uniform" if lv == 0 else (f"uniform x{1 << lv} cells" if tol >= NEVER_SPLIT else
                                           f"adaptive L={lv} tol={tol:g}")
        rows.append({"config": config, "case": label, "beam_levels": lv,
                     "beam_tolerance": None if tol >= NEVER_SPLIT else tol,
                     "beams": result.beam_stats["beams"],
                     "frame_s": s, "beams_stage_s": result.timings_s["beams"], "relative_l1_vs_uniform": l1})
        print(f"beams        {config:11s} {label:24s} {rows[-1]['beams']:8d} beams | frame {s * 1e3:8.1f} ms "
              f"| L1 vs uniform {l1:.2e}", flush=True)
    return rows


def _fill_vs_depth(depths, n: int, size: tuple[int, int], device: str,
                   overrides: dict | None = None) -> list[dict]:
    """Hull / prism fill as the light focuses: ocean_floor.toml (with ``overrides``, e.g. a steeper
    sea) over a flat floor at several depths (floor caustic contrast std/mean beside it), the camera
    aimed at the floor."""
    import warpcaustics as wc

    rows = []
    for depth in depths:
        scene = point_sun_scene(ROOT / "configs" / "ocean_floor.toml", {
            "caustics.method": "beams", "water.resolution": n, "floor.shape": "flat",
            "floor.depth_m": depth,
            "camera.width": size[0], "camera.height": size[1], "caustics.shafts": False,
            "optics.wavelengths": WAVELENGTHS, "camera.position_m": [0.0, -6.0, -1.0],
            "camera.look_at_m": [0.0, 0.0, -0.6 * depth], **(overrides or {})})
        renderer = wc.Renderer(scene, device)
        result = renderer.render(0.0)
        fill = fill_measure(renderer.method.caustics[0], renderer.method.camera, 3, samples=2000)
        floor = result.floor_irradiance[1].astype(np.float64)
        rows.append({"floor_depth_m": depth, "contrast": float(floor.std() / floor.mean()), **fill})
        print(f"beams        fill at floor depth {depth:5.1f} m (contrast {rows[-1]['contrast']:.2f}): "
              f"hull/prism {fill['hull_over_prism']:.3f}, hull/Ernst {fill['hull_over_ernst']:.3f} on "
              f"{fill['beams_measured']} beams; fill (beam pixels / touched) hull {fill['hull_fill']:.2f}, "
              f"prism {fill['prism_fill']:.2f}, Ernst {fill['ernst_fill']:.2f}", flush=True)
    return rows


def _slope(rows: list[dict], x: str, y: str) -> float:
    return float(np.polyfit(np.log([r[x] for r in rows]), np.log([r[y] for r in rows]), 1)[0])


def run(quick: bool, device: str) -> dict:
    import warp as wp

    from benchmarks.run import _cpu_name

    sizes = QUICK if quick else FULL
    warp_repeats, numpy_repeats = (2, 1) if quick else (5, 3)
    record = device_record(device)
    wp_name = record["device_name"]
    print(f"beams        warp {wp.__version__} [{device}: {wp_name}] | cpu {_cpu_name()} | numpy twins "
          "float64, same beams and tile lists", flush=True)
    gather = _gather_case(sizes["gather_n"], sizes["gather_m"], device, warp_repeats, numpy_repeats)
    g = gather
    print(f"beams        surface gather N={g['water_n']} {g['points']} points, {g['pairs']} pairs | "
          f"warp[{device}] {g['warp_points_per_s'] / 1e6:8.2f} Mpt/s ({g['warp_s'] * 1e3:8.2f} ms) | numpy "
          f"{g['numpy_points_per_s'] / 1e6:8.2f} Mpt/s ({g['numpy_s'] * 1e3:8.1f} ms) | ratio "
          f"{g['speedup_warp_vs_numpy']:6.1f}x | rel L1 {g['relative_l1_numpy_vs_warp']:.1e}", flush=True)
    volume = _volume_case(sizes["camera_n"], sizes["camera"], device, warp_repeats, numpy_repeats)
    v = volume
    print(f"beams        volume scan planes N={v['water_n']} {v['camera_px'][0]}x{v['camera_px'][1]} "
          f"{v['fill']['inside_pairs']} chords | warp[{device}] {v['warp_pixels_per_s'] / 1e3:8.1f} kpx/s "
          f"({v['warp_s'] * 1e3:8.1f} ms) | numpy {v['numpy_pixels_per_s'] / 1e3:8.1f} kpx/s "
          f"({v['numpy_s'] * 1e3:8.1f} ms) | ratio {v['speedup_warp_vs_numpy']:6.1f}x | rel L1 "
          f"{v['relative_l1_numpy_vs_warp']:.1e}", flush=True)
    fill = volume["fill"]
    print(f"beams        fill: (pixel, beam) pairs in axis-aligned boxes {fill['box_pixels']:.3g}, in tile "
          f"lists {fill['tile_pairs']:.3g}, in oriented boxes {fill['oriented_box_pairs']:.3g}, with a "
          f"chord {fill['inside_pairs']:.3g}", flush=True)
    print(f"beams        bounding volumes on {fill['beams_measured']} beams in view: tight hull "
          f"{fill['hull_pixels']:.4g} px, prism {fill['prism_pixels']:.4g} px, Ernst's prism "
          f"{fill['ernst_pixels']:.4g} px; where the beams are {fill['beam_pixels']} px: fill hull "
          f"{fill['hull_fill']:.2f}, prism {fill['prism_fill']:.2f}, Ernst {fill['ernst_fill']:.2f}",
          flush=True)
    bounds = _bounds_case(sizes["camera_n"], sizes["camera"], device, max(warp_repeats, 3))
    for r in bounds:
        print(f"beams        beam_bounds = {r['beam_bounds']:5s} volume pass {r['volume_s'] * 1e3:8.1f} ms "
              f"({r['time_vs_hull']:4.2f}x the hull's) | rasterised {r['raster_pixels']:.4g} px, fill "
              f"{r['raster_fill']:.2f} | boxes test {r['oriented_box_pairs']:.3g} pairs for "
              f"{r['inside_pairs']:.3g} chords, {r['hull_fallbacks']} copies fell back to the hull | L1 vs "
              f"hull {r['relative_l1_vs_hull']:.1e}", flush=True)
    by_n = [_stage_time(n, sizes["scaling_m"][1], device, warp_repeats) for n in sizes["scaling_n"]]
    by_m = [_stage_time(sizes["scaling_n"][1], m, device, warp_repeats) for m in sizes["scaling_m"]]
    for rows, key in ((by_n, "beams"), (by_m, "map_m")):
        slope = _slope(rows, "beams" if key == "beams" else "map_m", "stage_s")
        for r in rows:
            print(
                f"beams        stage N={r['water_n']:5d} M={r['map_m']:5d} {r['beams']:8d} beams | "
                f"{r['stage_s'] * 1e3:9.2f} ms | {r['beams_per_s'] / 1e6:7.2f} Mbeams/s",
                flush=True,
            )
        what = "beam count" if key == "beams" else "map side M"
        print(f"  log-log slope of stage time vs {what}: {slope:.2f}")
        for r in rows:
            r[f"loglog_slope_vs_{key}"] = slope
    fill_rows = _fill_vs_depth((3.0, 12.0) if quick else (3.0, 6.0, 12.0, 24.0), 32 if quick else 64,
                               (64, 48) if quick else (160, 120), device)
    adaptive = _adaptive_rows("ocean.toml", {"water.resolution": sizes["adaptive_n"],
                                             "caustics.map_resolution": sizes["adaptive_m"]}, 2, device,
                              warp_repeats)
    adaptive += _adaptive_rows("lens.toml", {} if not quick else {"caustics.map_resolution": 64}, 3, device,
                               warp_repeats)
    return {
        "adaptive_vs_uniform": adaptive,
        "fill_vs_depth": fill_rows,
        "benchmark": "beam_rasteriser",
        **record,
        "wavelengths": WAVELENGTHS,
        "warp_repeats": warp_repeats,
        "interleaved_rounds": numpy_repeats,
        "warp_calls_per_round": calls_per_round(warp_repeats, numpy_repeats),
        "timing": "median wall time after a warm-up frame, device synchronised; the gather and volume "
        "passes time Warp and numpy in turn, interleaved_rounds rounds of warp_calls_per_round Warp calls "
        "(averaged) and one numpy call (benchmarks.run.interleaved_times); the stage and adaptive rows "
        "take the median of warp_repeats; beams and tile lists built by Warp once and shared with numpy",
        "surface_gather": gather,
        "volume_scan_planes": volume,
        "beam_bounds": bounds,
        "stage_vs_beams": by_n,
        "stage_vs_map": by_m,
    }


def main(argv: list[str] | None = None) -> int:
    from benchmarks.run import module_main

    return module_main(argv, "beams", run, __doc__)


if __name__ == "__main__":
    sys.exit(main())
