"""Eikonal and wave caustic textures (after Mercier 2013) at Mercier's Table 1 sizes, and the
flux-ratio map of the same frame as the baseline measured in the same run.

``configs/mercier_pool.toml`` (a Gaussian bump in the wave pool, 2 m wide and 1.9 m deep, so the
grid is about N³) at t = 0.3 s, with ``caustics.eikonal_resolution`` = N ∈ {64, 128, 256} (quick:
64). Timed: the whole eikonal stage of one frame (front initialisation, layer relaxation, the
Laplacian texture, transport, floor map), median of a few runs after a warm-up frame, device
synchronised; and the whole ``wave3d`` stage (``caustics.wave3d_resolution`` = N, one run: the
leapfrog steps until the front has crossed the floor and settled, then the averaged periods).
Mercier's own timings (his Table 1: fast marching on the CPU, 0.3 s, 2.5 s and 26 s at 64³, 128³
and 256³; his wave texture 17 s, 21 s and 107 s) are quoted as published, not measured here.
``python -m benchmarks.eikonal --help``.
"""

from __future__ import annotations

import sys
import time

from benchmarks.run import CONFIGS, device_record, median_time, point_sun_scene

FULL = [64, 128, 256]
QUICK = [64]
TIME_S = 0.3
MERCIER_TABLE1_S = {64: (0.3, 17.0), 128: (2.5, 21.0), 256: (26.0, 107.0)}
"""Published (Mercier 2013, Table 1): (eikonal by fast marching, wave texture) seconds per size."""


def measure(n: int, device: str, repeats: int) -> dict:
    from warpcaustics.optics.refraction import height_range
    from warpcaustics.pipeline import Renderer

    from benchmarks.sunmap import flux_ratio_pass

    scene = point_sun_scene(CONFIGS / "mercier_pool.toml", {
        "caustics.eikonal_resolution": n, "water.resolution": n, "caustics.map_resolution": 2 * n})
    renderer = Renderer(scene, device)
    renderer.render(TIME_S)  # warm-up: JIT compile, first launches; the pool is now at TIME_S
    surface = renderer.water.at(TIME_S)
    _, highest = height_range(surface, device)
    eik = renderer.method.approximate
    eikonal_s = median_time(lambda: eik.run(surface, highest), repeats, device)
    fluxratio_s = median_time(flux_ratio_pass(renderer, surface, highest), repeats, device)
    nodes = n * n * eik.stats.layers
    published = MERCIER_TABLE1_S.get(n, (None, None))
    wave = _wave(n, device)
    return {**wave, "n": n, "layers": eik.stats.layers, "nodes": nodes, "passes": eik.stats.passes,
            "max_passes_per_layer": eik.stats.max_passes, "eikonal_s": eikonal_s,
            "ns_per_node_pass": eikonal_s / (n * n * eik.stats.passes) * 1e9,
            "fluxratio_s": fluxratio_s, "eikonal_over_fluxratio": eikonal_s / fluxratio_s,
            "mercier_published_eikonal_s": published[0], "mercier_published_wave_s": published[1],
            "device_bytes": eik.bytes_held()}


def _wave(n: int, device: str) -> dict:
    """One wave3d frame at N (timed once: at 256 it takes minutes on a CPU)."""
    import warp as wp

    from warpcaustics.optics.refraction import height_range
    from warpcaustics.pipeline import Renderer

    scene = point_sun_scene(CONFIGS / "mercier_pool.toml", {
        "caustics.method": "wave3d", "caustics.wave3d_resolution": n, "water.resolution": n,
        "caustics.map_resolution": 2 * n})
    renderer = Renderer(scene, device)
    renderer.water.at(TIME_S)
    surface = renderer.water.at(TIME_S)
    _, highest = height_range(surface, device)
    wave = renderer.method.approximate
    wave.run(surface, highest, steps=2)  # warm-up: JIT compile
    wp.synchronize_device(device)
    t0 = time.perf_counter()
    wave.run(surface, highest)
    wp.synchronize_device(device)
    seconds = time.perf_counter() - t0
    st = wave.stats
    return {"wave_layers": st.layers, "wave_steps": st.steps, "wave_node_updates": st.node_updates,
            "wave_s": seconds, "wave_ns_per_node_update": seconds / st.node_updates * 1e9,
            "wave_active_band_saving": 1.0 - st.node_updates / (st.steps * st.layers * n * n),
            "wave_device_bytes": wave.bytes_held()}


def run(quick: bool, device: str) -> dict:
    import warp as wp

    from benchmarks.run import _cpu_name

    repeats = 1 if quick else 3
    record = device_record(device)
    wp_name = record["device_name"]
    print(f"eikonal      configs/mercier_pool.toml t={TIME_S} s | warp {wp.__version__} "
          f"[{device}: {wp_name}] | cpu {_cpu_name()}", flush=True)
    rows = []
    for n in QUICK if quick else FULL:
        row = measure(n, device, repeats)
        rows.append(row)
        print(f"eikonal      N={n:4d} layers={row['layers']:4d} ({row['nodes'] / 1e6:6.2f} M nodes, "
              f"{row['passes']:5d} layer passes) | eikonal {row['eikonal_s']:8.3f} s "
              f"({row['ns_per_node_pass']:5.1f} ns/node/pass) | flux ratio "
              f"{row['fluxratio_s'] * 1e3:8.1f} ms "
              f"| Mercier's published marching {row['mercier_published_eikonal_s']} s | "
              f"{row['device_bytes'] / 2**20:7.1f} MiB", flush=True)
        print(f"wave3d       N={n:4d} layers={row['wave_layers']:4d} steps={row['wave_steps']:5d} "
              f"({row['wave_node_updates'] / 1e9:6.2f} G node updates, active band saves "
              f"{row['wave_active_band_saving']:.0%}) | wave {row['wave_s']:8.2f} s "
              f"({row['wave_ns_per_node_update']:5.1f} ns/node update) | Mercier's published wave "
              f"{row['mercier_published_wave_s']} s | {row['wave_device_bytes'] / 2**20:7.1f} MiB",
              flush=True)
    return {"benchmark": "eikonal_and_wave_textures", **record, "repeats": repeats,
            "scene": "configs/mercier_pool.toml",
            "time_s": TIME_S, "published": "Mercier 2013, Table 1 (quoted, not measured here)",
            "results": rows}


def main(argv: list[str] | None = None) -> int:
    from benchmarks.run import module_main

    return module_main(argv, "eikonal", run, __doc__)


if __name__ == "__main__":
    sys.exit(main())
