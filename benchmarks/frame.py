"""One ocean frame's floor caustics: Warp vs the vectorised numpy implementation of the same algorithm.

Both start from the same water surface (the Warp FFT ocean at t = 0) and compute per-vertex
refraction plus the flux-ratio floor map (K spectral bins). Each measurement runs in a fresh
process so its peak resident memory is its own.
"""

from __future__ import annotations

import resource
import time

from benchmarks.run import CONFIGS, point_sun_scene


def _rss_mib() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0  # Linux: KiB


def _scene(n: int, m: int, bins: int):
    return point_sun_scene(CONFIGS / "ocean.toml", {"water.resolution": n, "caustics.map_resolution": m,
                                                   "optics.wavelengths.bins": bins})


def measure_warp(n: int, m: int, bins: int, device: str, repeats: int) -> dict:
    """Median wall time of refraction + floor caustics, and of a whole frame, on a Warp device."""
    import numpy as np
    import warp as wp

    from warpcaustics.optics.refraction import height_range, refract_to_floor, sun_visibility
    from warpcaustics.pipeline import Renderer, scene_bytes

    scene = _scene(n, m, bins)
    renderer = Renderer(scene, device)
    rss0 = _rss_mib()
    renderer.render(0.0)  # warm-up: JIT compile and first allocations are not timed
    surface = renderer.water.at(0.0)
    cfg = scene.config

    def stages():
        _, highest = height_range(surface, device)
        visible = sun_visibility(surface, scene.sun_direction, highest, device, out=renderer.visible)
        r = refract_to_floor(surface, visible, renderer.light.group_ior, scene.sun_direction,
                             -cfg.floor.depth_m, device, out=renderer.method.refracted)
        renderer.method.floor.run(surface, r, scene.sun_direction)
        wp.synchronize_device(device)

    stage_times, frame_times = [], []
    for _ in range(repeats):
        t0 = time.perf_counter()
        stages()
        stage_times.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        renderer.render(0.0)
        frame_times.append(time.perf_counter() - t0)
    return {"stages_s": float(np.median(stage_times)), "frame_s": float(np.median(frame_times)),
            "peak_rss_mib": _rss_mib(), "rss_before_mib": rss0,
            "device_bytes_estimate": scene_bytes(scene, device),
            "device_name": str(wp.get_device(device).name)}


def measure_numpy(n: int, m: int, bins: int, repeats: int) -> dict:
    """Median wall time of the float64 numpy implementation of refraction + floor caustics."""
    import numpy as np

    from warpcaustics import reference
    from warpcaustics.pipeline import Renderer

    scene = _scene(n, m, bins)
    renderer = Renderer(scene, "cpu")
    result = renderer.render(0.0)
    pos, nrm = result.surface_positions.astype(np.float64), result.surface_normals.astype(np.float64)
    rss0 = _rss_mib()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        floor, _ = reference.floor_caustics(pos, nrm, scene.sun_direction, scene.config.optics.ior,
                                            scene.config.floor.depth_m, renderer.sun_irradiance,
                                            renderer.attenuation_per_m, scene.config.water.extent_m, m)
        times.append(time.perf_counter() - t0)
    l1 = float(np.abs(result.floor_irradiance - floor).sum() / np.abs(floor).sum())
    return {"stages_s": float(np.median(times)), "peak_rss_mib": _rss_mib(), "rss_before_mib": rss0,
            "relative_l1_vs_warp": l1}
