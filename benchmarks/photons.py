"""Photon-splatting caustics (``caustics.method = "photons"``): Warp vs a vectorised numpy twin.

The twin, :func:`~warpcaustics.reference.photons.numpy_photons`, does in float64 what
``kernels/caustics/photons.py`` does for a periodic sea over a flat floor: emit s×s photons on the
bilinear patch of every surface quad, refract them (Snell + exact Fresnel), move each start by whole
periods so it lands in the patch, intersect the floor and deposit the flux. Intersections:
``newton`` is Shah's iteration with the kernel's look-ups (bilinear between texel centres showing
one receiver, else the nearest texel) on the very light-view position buffer the Warp stage
renders; ``exact`` is, in numpy, the analytic ray/plane intersection (numpy has no BVH, so its exact
mode does less work than Warp's BVH ray query: a ratio against it flatters numpy). Both sides run in
one process on the same surface; numpy is single-threaded, and so is Warp's ``cpu`` device.
``python -m benchmarks.photons --help``.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

from warpcaustics.reference import relative_l1
from warpcaustics.reference.photons import LightViewArrays, numpy_photons

from benchmarks.run import calls_per_round, device_record, interleaved_times, point_sun_scene

ROOT = Path(__file__).resolve().parents[1]

# (water N, photon subdivisions s, floor map M) full / quick; 'rgb': three bands, one index group.
FULL = (256, 4, 512)
QUICK = (64, 2, 128)
WAVELENGTHS = "rgb"
QUICK_CAMERA = {"water.resolution": 64, "caustics.photon_subdivisions": 2, "caustics.map_resolution": 128,
                "camera.width": 80, "camera.height": 60}
"""Overrides for the camera frames in quick mode."""


def photon_scene(n: int, s: int, m: int, intersection: str, wavelengths=WAVELENGTHS):
    """The ocean with photons, under the point sun of the numpy twin, deposited per texel (the twin's
    histogram; the footprint splats are measured in benchmarks/photon_splats.py)."""
    return point_sun_scene(ROOT / "configs" / "ocean.toml", {
        "caustics.method": "photons", "caustics.intersection": intersection, "caustics.photon_splat": "texel",
        "caustics.photon_subdivisions": s, "caustics.map_resolution": m, "water.resolution": n,
        "optics.wavelengths": wavelengths})


class PhotonCase:
    """One Warp renderer of the photon ocean and the inputs of its photon stage at t = 0."""

    def __init__(self, n: int, s: int, m: int, intersection: str, device: str):
        import warpcaustics as wc
        from warpcaustics.optics.refraction import height_range, sun_visibility

        self.scene = photon_scene(n, s, m, intersection)
        self.renderer = r = wc.Renderer(self.scene, device)
        self.device = device
        self.surface = r.water.at(0.0)
        _, highest = height_range(self.surface, device)
        self.visible = sun_visibility(self.surface, self.scene.sun_direction, highest, device, out=r.visible)
        self.intersection = intersection

    @property
    def photon_count(self) -> int:
        return int(self.renderer.method.caustics[0].weight.shape[0])

    def pass_stats(self) -> dict:
        """The photon counts of one pass of the sun (``RenderResult.photon_stats``)."""
        from warpcaustics.caustics.stage import Stopwatch

        r = self.renderer
        sun, irradiance = self.scene.sun_direction, r.light.sun_irradiance
        done = r.method.caustics[0].light_pass(self.surface, self.visible, sun, irradiance,
                                               Stopwatch(self.device), stage="photons")
        return done.stats

    def run_warp(self) -> np.ndarray:
        """The Warp photon stage once, device synchronised; the (K, M, M) map on the host."""
        import warp as wp

        r = self.renderer
        irr = r.method.caustics[0].trace(self.surface, self.visible, self.scene.sun_direction,
                                         r.light.sun_irradiance)
        wp.synchronize_device(self.device)
        return irr.numpy().copy()

    def numpy_inputs(self) -> dict:
        r = self.renderer
        cfg = self.scene.config
        view = (LightViewArrays.from_warp(r.method.caustics[0].view, r.method.receivers.face_receiver_np)
                if self.intersection == "newton" else None)
        return dict(positions=self.surface.positions.numpy().copy(),
                    normals=self.surface.normals.numpy().copy(), visible=self.visible.numpy().copy(),
                    ior=r.light.group_ior, sun_dir=self.scene.sun_direction,
                    s=cfg.caustics.photon_subdivisions,
                    extent_m=float(self.surface.extent_m), floor_z=-cfg.floor.depth_m,
                    sun_irradiance=r.sun_irradiance, attenuation_per_m=r.attenuation_per_m,
                    map_resolution=cfg.caustics.map_resolution, mode=self.intersection,
                    newton_iterations=cfg.caustics.newton_iterations,
                    view=view)


def _camera_frames(quick: bool, device: str) -> list[dict]:
    """One camera frame of every config in configs/ with ``camera.enabled = true`` (none: [])."""
    import warpcaustics as wc
    from warpcaustics.config import read_toml
    from warpcaustics.errors import WarpcausticsError

    rows = []
    for path in sorted((ROOT / "configs").glob("*.toml")):
        try:
            if read_toml(path).get("camera", {}).get("enabled") is not True:
                continue
            overrides = QUICK_CAMERA if quick else {}
            scene = point_sun_scene(path, overrides)
            renderer = wc.Renderer(scene, device)
            renderer.render(0.0)  # warm-up: JIT compile, first allocations
            t0 = time.perf_counter()
            result = renderer.render(0.0)
            frame_s = time.perf_counter() - t0
        except WarpcausticsError as exc:
            print(f"camera frame {path.name}: skipped ({exc})", flush=True)
            continue
        except Exception as exc:  # a broken camera stage must not lose the photon figures
            print(f"camera frame {path.name}: FAILED ({type(exc).__name__}: {exc})", flush=True)
            rows.append({"config": path.name, "error": f"{type(exc).__name__}: {exc}"})
            continue
        cam = scene.config.camera
        rows.append({"config": path.name, "overrides": overrides, "frame_s": frame_s,
                     "timings_s": dict(result.timings_s), "camera_px": [cam.width, cam.height],
                     "water_n": scene.water_resolution, "photon_stats": result.photon_stats})
        stages = ", ".join(f"{k} {v * 1e3:.1f}" for k, v in result.timings_s.items())
        print(f"camera frame {path.name:18s} {cam.width}x{cam.height} N={scene.water_resolution} | "
              f"frame {frame_s * 1e3:8.1f} ms | stages [ms]: {stages}", flush=True)
    if not rows:
        print("camera frame: no config in configs/ has camera.enabled = true; skipped", flush=True)
    return rows


def run(quick: bool, device: str) -> dict:
    """Photons/s of the Warp stage (exact, newton) and of numpy (plane, newton) on the default ocean."""
    import warp as wp

    from benchmarks.run import _cpu_name

    n, s, m = QUICK if quick else FULL
    warp_repeats, numpy_repeats = (2, 1) if quick else (5, 3)
    record = device_record(device)
    wp_name = record["device_name"]
    print(f"photons      ocean N={n} s={s} M={m} wavelengths={WAVELENGTHS} | warp {wp.__version__} "
          f"[{device}: {wp_name}] | cpu {_cpu_name()} | numpy exact = analytic ray/plane (no BVH)",
          flush=True)
    cases = {}
    for intersection in ("exact", "newton"):
        case = PhotonCase(n, s, m, intersection, device)
        warp_map = case.run_warp()  # warm-up: JIT compile, first launch
        inputs = case.numpy_inputs()
        numpy_map = numpy_photons(**inputs)
        # Timed in turn, round by round, so both sides see the same machine.
        times = interleaved_times({"warp": (case.run_warp, calls_per_round(warp_repeats, numpy_repeats)),
                                   "numpy": (lambda inputs=inputs: numpy_photons(**inputs), 1)},
                                  numpy_repeats, device)
        warp_s, numpy_s = (float(np.median(times[side])) for side in ("warp", "numpy"))
        count = case.photon_count
        stats = case.pass_stats()
        row = {"photons": count, "photon_stats": stats, "warp_s": warp_s, "numpy_s": numpy_s,
               "warp_photons_per_s": count / warp_s, "numpy_photons_per_s": count / numpy_s,
               "speedup_warp_vs_numpy": numpy_s / warp_s,
               "relative_l1_numpy_vs_warp": relative_l1(numpy_map, warp_map),
               # Insensitive to the few photons that float32 rounding moves across a texel edge.
               "relative_flux_diff_numpy_vs_warp": float(abs(warp_map.sum(dtype=np.float64) / numpy_map.sum()
                                                             - 1.0))}
        if intersection == "newton":
            cfg = case.scene.config.caustics
            row.update(newton_iterations=cfg.newton_iterations,
                       newton_buffer_resolution=cfg.newton_buffer_resolution)
        cases[intersection] = row
        np_label = "plane " if intersection == "exact" else "newton"
        print(f"photons      {intersection:6s} {count:9d} photons | warp[{device}] "
              f"{row['warp_photons_per_s'] / 1e6:8.2f} Mph/s ({warp_s * 1e3:8.2f} ms) | numpy {np_label} "
              f"{row['numpy_photons_per_s'] / 1e6:8.2f} Mph/s ({numpy_s * 1e3:8.1f} ms) | ratio "
              f"{row['speedup_warp_vs_numpy']:6.1f}x | rel L1 numpy vs warp "
              f"{row['relative_l1_numpy_vs_warp']:.2e} (total flux "
              f"{row['relative_flux_diff_numpy_vs_warp']:.1e})",
              flush=True)
    return {"benchmark": "photon_splatting", "water_n": n, "photon_subdivisions": s, "map_m": m,
            "wavelengths": WAVELENGTHS, **record, "rounds": numpy_repeats,
            "warp_calls_per_round": calls_per_round(warp_repeats, numpy_repeats),
            "timing": "median wall time of PhotonCaustics.run after one warm-up call, device synchronised; "
                      "Warp and numpy timed in turn, round by round (benchmarks.run.interleaved_times); "
                      "light view (newton) built once per scene, outside the timing, on both sides",
            "numpy_exact_is": "analytic ray/plane intersection (numpy has no BVH; Warp queries its BVH)",
            "cases": cases, "camera_frames": _camera_frames(quick, device)}


def main(argv: list[str] | None = None) -> int:
    from benchmarks.run import module_main

    return module_main(argv, "photons", run, __doc__)


if __name__ == "__main__":
    sys.exit(main())
