"""``run.json``: the resolved config, versions, device, and each frame's record (files, timings,
fluxes, statistics); written last, so its presence marks a complete run."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from warpcaustics.config import config_to_dict
from warpcaustics.errors import WarpcausticsError
from warpcaustics.io.comparison import comparison_entry
from warpcaustics.io.files import jsonable, versions, write_json


def frame_entry(frame: int, r) -> dict:
    """run.json's record of one frame (JSON-ready: arrays become lists)."""
    entry = {
        "frame": frame,
        "time_s": r.time_s,
        "files": [f"frame_{frame:04d}.exr", f"frame_{frame:04d}.png"] + (
            [f"camera_{frame:04d}.exr", f"camera_{frame:04d}.png"] if r.camera_radiance is not None else []),
        "timings_s": r.timings_s,
        "floor_mean_irradiance_w_m2_nm": r.floor_irradiance.mean(axis=(1, 2), dtype=np.float64),
        **({"sky_floor_mean_irradiance_w_m2_nm": r.sky_floor_irradiance.mean(axis=(1, 2), dtype=np.float64)}
           if r.sky_floor_irradiance is not None else {}),
        "floor_flux_w_nm": r.floor_flux_w_nm,
        "transmitted_flux_w_nm": r.transmitted_flux_w_nm,
        **({"delivered_flux_w_nm": r.delivered_flux_w_nm} if r.delivered_flux_w_nm is not None else {}),
        "fold_fraction": r.fold_fraction,
        **({"photons": r.photon_stats} if r.photon_stats is not None else {}),
        **({"beams": r.beam_stats} if r.beam_stats is not None else {}),
        **({"eikonal": r.eikonal_stats} if r.eikonal_stats is not None else {}),
        **({"wave3d": r.wave3d_stats} if r.wave3d_stats is not None else {}),
        **({"multiple_scattering": r.multiple_scattering_stats} if r.multiple_scattering_stats is not None
           else {}),
        **({"comparison": comparison_entry(frame, r)} if r.comparison is not None else {}),
        "statistics": frame_statistics_entry(r),
    }
    return json.loads(json.dumps(entry, default=jsonable))


def frame_statistics_entry(r) -> dict:
    """run.json's irradiance statistics of a frame, with the probe values an animation's time
    statistics are built from."""
    from warpcaustics.batch.stats import frame_statistics, probe_values

    cfg = r.scene.config.stats
    return {**frame_statistics(r, cfg), "probe_irradiance_w_m2": probe_values(r, cfg).tolist()}


def integration_frames(integration_s: float, dt_s: float) -> int:
    """The frames an animation ``dt_s`` apart needs for a radiometer's integration over
    ``integration_s`` to give three samples (``time_statistics.integrated``): the first whole window
    ends ⌈T/dt⌉ frames in."""
    return int(math.ceil(integration_s / dt_s - 1e-9)) + 3


def time_statistics(frames: list[dict], first) -> dict | None:
    """Statistics of the probes' E(t) over an animation (three frames or more, equally spaced);
    ``first`` is the first frame's RenderResult (for the config and the map)."""
    from warpcaustics.batch.stats import integrate_series, probe_points, series_statistics

    if len(frames) < 3:
        return None
    stats_cfg = first.scene.config.stats
    times = np.array([f["time_s"] for f in frames])
    series = np.array([f["statistics"]["probe_irradiance_w_m2"] for f in frames])
    dt = float(np.mean(np.diff(times)))
    out = {"probes_m": [list(p) for p in probe_points(stats_cfg, first.map_center_m)], "dt_s": dt,
           **series_statistics(series, dt, stats_cfg.flash_threshold)}
    if stats_cfg.integration_s > 0.0:
        needed = integration_frames(stats_cfg.integration_s, dt)
        if len(frames) < needed:  # the render command refuses it before rendering; a sweep's task fails
            raise WarpcausticsError(f"stats.integration_s = {stats_cfg.integration_s:g} needs {needed} "
                                    f"frames {dt:.4g} s apart for its time statistics; the animation has "
                                    f"{len(frames)}")
        integrated = integrate_series(series, dt, stats_cfg.integration_s)
        if len(integrated) >= 3:  # a radiometer's samples, each its mean over the integration time
            out["integrated"] = {"integration_s": stats_cfg.integration_s, "samples": len(integrated),
                                 **series_statistics(integrated, dt, stats_cfg.flash_threshold)}
    return out


def write_run_json(out_dir: Path, results: list, *, frames: list[dict] | None = None) -> Path:
    """Write ``run.json`` (resolved config, versions, device, per-frame timings and totals).

    ``frames``: the per-frame records (:func:`frame_entry`) when they are not all in ``results``
    (a resumed pool animation); by default one per result, numbered from 0. Written last, after
    every frame file: its presence marks a complete run.
    """
    first = results[0]
    path = out_dir / "run.json"
    frames = frames if frames is not None else [frame_entry(i, r) for i, r in enumerate(results)]
    series = time_statistics(frames, first)
    write_json(path, {
        "source": first.scene.source,
        "config": config_to_dict(first.scene.config),
        "device": first.device,
        "versions": versions(),
        "wavelengths_nm": first.wavelengths_nm,
        "bin_widths_nm": first.bin_widths_nm,
        "attenuation_per_m": first.attenuation_per_m,
        "ior": first.ior,
        "sun_irradiance_w_m2_nm": first.sun_irradiance,
        "frames": frames,
        **({"time_statistics": series} if series is not None else {}),
    })
    return path
