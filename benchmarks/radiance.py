"""A radiance sensor at every texel (``floor.view_*``): its cost, ``python -m benchmarks.radiance``.

A warm frame of the Darecki radiance set-up (``configs/field/darecki2011_radiance.toml`` at Fig. 15b's
conditions: 532 nm, single scattering, a point radiance sensor of 4.5°, 2048² cells over 8 m, the
whole patch on 1024² texels; ``--quick``: small sizes) with the sensor looking at the refracted sun,
against the same frame's irradiance map (the baseline), one core; and the sky's kernel against its
float64 numpy twin (``reference/view.py``) on the same texels. The model against Darecki et al.'s
Fig. 15 is the field data set ``warpcaustics field darecki2011_radiance`` (docs/validation.md).
"""

from __future__ import annotations

import math
import sys
import time

import numpy as np

from benchmarks.run import ROOT, device_record, interleaved_times

SCENE = ROOT / "configs/field/darecki2011_radiance.toml"

QUICK = {"water.extent_m": 2.0, "water.resolution": 256, "caustics.map_resolution": 128,
         "sun.disk_samples": 2}


def panel_overrides(panel: str, quick: bool = False) -> tuple[dict, object]:
    """The scene at ``panel``'s conditions (depth, sun, wind, the water's c(555)) and the panel."""
    import warpcaustics as wc
    from warpcaustics.batch.field.darecki2011_radiance import panel_conditions, record

    rec = record(panel)
    base = QUICK if quick else {}
    return {**base, **panel_conditions(wc.load_scene(SCENE, base).config, rec)}, rec


def run(quick: bool, device: str) -> dict:
    """The radiance frame against the irradiance frame, and the sky's kernel against numpy."""
    import warpcaustics as wc
    from warpcaustics.batch.field.darecki2011_radiance import view
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
    from benchmarks.run import module_main

    return module_main(argv, "radiance", run, __doc__)


if __name__ == "__main__":
    sys.exit(main())
