"""Field comparison: the CV of the radiance against the zenith angle, Darecki et al. (2011).

Darecki, Stramski & Sokolski (2011), J. Geophys. Res. 116, C00H09, Fig. 15: the CV of the radiance
at 532 nm in a 4.5° field of view (in water) at thirteen zenith angles in the sun's plane (positive
towards the sun), in three panels of their own conditions (a: 0.93 m, sun 33°, 7 m/s, c(555)
0.65 1/m; b: 0.59 m, 41°, 5.4 m/s, 0.31; c: 0.54 m, 35°, 3.6 m/s, 0.31), Santa Barbara Channel.
The values come from the ``jerlov`` package (``darecki2011_radiance_cv``).

A radiance sensor's cone sees the sun only while a facet above it is tilted to refract the sun into
it, so the CV at each angle maps how often the surface is tilted that far: it tests the surface's
slopes more directly than the irradiance does, where many slopes focus light on one collector.

``warpcaustics field darecki2011_radiance SCENE --out DIR`` renders SCENE
(``configs/field/darecki2011_radiance.toml``: the Darecki set-up with a radiance sensor at every
texel, ``floor.view_fov_deg``) at each panel's depth, sun, wind and c(555) (the bio-optical water's
chlorophyll solved for it), turns the sensor to each of the record's zeniths inside Snell's window
(:data:`IN_WINDOW_DEG`; beyond it the sensor sees the upwelling light, which is not modelled), as
one resumable sweep, pools each point's texels and frames and writes ``darecki2011_radiance.csv``
and ``darecki2011_radiance.png`` (CV against zenith per panel, as the paper plots it). The model's
CV is spatial over the patch's texels, the measurement's temporal at one sensor, as in
:mod:`.darecki2011`. The paper gives no wind direction: the scene puts the wind along the sun's
plane (``--set water.wind_direction_deg=90``: across it). The map holds the unscattered light;
beside it each row gives the mean light scattered once into the cone
(:mod:`warpcaustics.caustics.path_radiance`): its share of the cone's light and the CV with it
(:func:`scattered_columns`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from warpcaustics.batch.field.common import (
    band_row,
    check_frames,
    check_overrides,
    checked_arguments,
    frame_statistics_of,
    pooled_statistics,
    render_points,
    select_measured,
    with_beam_scaled,
)
from warpcaustics.batch.field.darecki2011 import PLOT_NEEDS, beam_attenuation, chlorophyll_for
from warpcaustics.config import SkyModel
from warpcaustics.errors import ConfigError
from warpcaustics.io.files import atomic_path, pyplot, write_csv

POINT_KEYS = ("floor.depth_m", "sun.elevation_deg", "water.wind_speed_m_s", "optics.chlorophyll_mg_m3",
              "floor.view_zenith_deg", "floor.view_azimuth_deg")
"""What each point sets: its panel's conditions and the sensor's direction."""

IN_WINDOW_DEG = 40.0
"""The record's zeniths the model takes: a 4.5° cone about them lies inside Snell's window
(48.6°); at ±60° and ±90° the sea's sensor saw the upwelling light."""

QUICK_OVERRIDES = {"water.extent_m": 2.0, "water.resolution": 128, "caustics.map_resolution": 64,
                   "sun.disk_samples": 2}
"""``--quick``: a coarse version of every task, to check the command end to end (not a comparison)."""


def record(panel: str):
    """One panel of the record (``jerlov.darecki2011_radiance_cv``)."""
    import jerlov

    return jerlov.darecki2011_radiance_cv(panel)


def panels_of(panels) -> list[str]:
    """The record's panels asked for (None: all), in the record's order; another is an error naming
    --panels."""
    import jerlov

    have = tuple(jerlov.DARECKI2011_PANELS)
    if panels is None:
        return list(have)
    if isinstance(panels, (str, bytes)) or not hasattr(panels, "__iter__"):
        raise ConfigError(f"--panels = {panels!r} must be a list of the record's panels, e.g. ('a', 'b')")
    wanted = [str(p).strip() for p in panels]
    bad = [p for p in wanted if p not in have]
    if bad:
        raise ConfigError(f"--panels: {bad[0]!r} is not a panel of Fig. 15; the record holds "
                          + ", ".join(have))
    return [p for p in have if p in wanted]


def panel_conditions(config, rec) -> dict:
    """The overrides of ``rec``'s panel: its depth, sun, wind, and the chlorophyll at which the
    scene's bio-optical water has its c(555) (:func:`~.darecki2011.chlorophyll_for`)."""
    return {"floor.depth_m": float(rec.depth_m), "sun.elevation_deg": 90.0 - float(rec.sun_zenith_deg),
            "water.wind_speed_m_s": float(rec.wind_m_s),
            "optics.chlorophyll_mg_m3": round(chlorophyll_for(config, float(rec.beam_attenuation_555)), 6)}


def view(zenith_deg: float) -> dict:
    """The sensor's axis at a signed zenith in the sun's plane (the sun at the scene's azimuth 0;
    positive towards it)."""
    return {"floor.view_zenith_deg": abs(zenith_deg),
            "floor.view_azimuth_deg": 0.0 if zenith_deg >= 0 else 180.0}


def check_scene(config, rec) -> None:
    """The record's band and field of view, per-band statistics, a sky, the sun in the sensor's
    plane, a stateless sea, the map the whole patch (the rest a radiance sensor needs, the scene's
    own checks say)."""
    if tuple(config.optics.wavelengths.list_nm) != (float(rec.wavelength_nm),):
        raise ConfigError(f"the Darecki 2011 radiance comparison is of one band: set optics.wavelengths = "
                          f"[{rec.wavelength_nm:g}]")
    if config.floor.view_fov_deg != float(rec.field_of_view_deg):
        raise ConfigError(f"the record's sensor has a {rec.field_of_view_deg:g}° field of view: set "
                          f"floor.view_fov_deg = {rec.field_of_view_deg:g}")
    if not config.stats.per_band:
        raise ConfigError("the Darecki 2011 radiance comparison needs its band's statistics: set "
                          "stats.per_band = true")
    if config.sun.azimuth_deg != 0.0:
        raise ConfigError(f"sun.azimuth_deg = {config.sun.azimuth_deg:g}: the sensor turns in the plane of "
                          "azimuth 0; set sun.azimuth_deg = 0 (turn the wind instead)")
    if config.sky.model is SkyModel.NONE or not config.sky.diffuse_fraction:
        raise ConfigError("the record's sensor sees the sky away from the sun: set sky.model = "
                          "'cie_clear' with its sky.diffuse_fraction")
    if config.water.stateful:
        raise ConfigError(f"water.model = {config.water.model.value!r} is stateful; the comparison pools "
                          "independent frames of a wind sea: use water.model = 'fft'")
    if config.map_window[0] < config.water.extent_m * (1.0 - 1e-9):
        raise ConfigError(f"caustics.map_extent_m = {config.caustics.map_extent_m:g}: the radiance "
                          "comparison pools the whole patch's texels; set caustics.map_extent_m = 0 (finer "
                          "texels: caustics.map_resolution)")


@checked_arguments
def run_darecki2011_radiance(
    scene: str | Path,
    out: str | Path,
    *,
    panels: tuple[str, ...] | None = None,
    view_zeniths: tuple[float, ...] | None = None,
    frames: int = 2,
    frame_interval_s: float = 5.0,
    workers: int = 1,
    device: str | None = None,
    quick: bool = False,
    quiet: bool = False,
    force: bool = False,
    overrides: dict | None = None,
) -> dict[str, Path]:
    """Render SCENE at each of the record's ``panels`` (None: a, b, c) with the sensor at each of
    its zeniths inside Snell's window (or those of ``view_zeniths``) as one resumable sweep into
    ``out``, pool each point's frames and write ``darecki2011_radiance.csv`` and
    ``darecki2011_radiance.png``. The frames are ``frame_interval_s`` apart (5 s: longer than the
    peak waves' period, 2.1-3.0 s at the panels' winds over 20 km of fetch); ``overrides``: config
    keys set at every point (``--set``). ``quick``: the first panel at its first and last zenith,
    coarse."""
    from warpcaustics.scene import load_scene

    times = check_frames(frames, frame_interval_s)
    check_overrides(overrides, POINT_KEYS, "--panels and --view-zeniths")
    chosen = panels_of(panels)
    scene_path = Path(scene).resolve()
    fixed = {**(QUICK_OVERRIDES if quick else {}), **(overrides or {})}
    base = load_scene(scene_path, fixed).config
    records = {p: record(p) for p in chosen}
    check_scene(base, records[chosen[0]])
    pyplot(PLOT_NEEDS)  # before the sweep, not after it
    inside = records[chosen[0]].zenith_deg[np.abs(records[chosen[0]].zenith_deg) <= IN_WINDOW_DEG]
    zeniths = select_measured(inside, view_zeniths, "--view-zeniths", "zenith inside Snell's window [deg]")
    if quick:
        chosen, zeniths = chosen[:1], ([zeniths[0], zeniths[-1]] if len(zeniths) > 1 else zeniths)
    points = [(p, z, {**panel_conditions(base, records[p]), **view(z)}) for p in chosen for z in zeniths]
    sweep = render_points(scene_path, fixed, [v for _, _, v in points], times, out, workers=workers,
                          device=device, quiet=quiet, force=force)
    band = f"{float(records[chosen[0]].wavelength_nm):g}nm_w_m2_nm"
    rows = []
    for panel, zenith, variant in points:
        rec = records[panel]
        measured = float(rec.cv[int(np.argmin(np.abs(rec.zenith_deg - zenith)))])
        stats = frame_statistics_of(sweep, out, variant)
        sky = [s["bands_sky"][band]["mean"] / s["bands"][band]["mean"] for s in stats]
        sun = [s["bands_direct"][band]["sun_in_view"] for s in stats]
        frames = [s["bands"][band] for s in stats]
        at = load_scene(scene_path, {**fixed, **variant})
        rows.append({"panel": panel, "zenith_deg": zenith, "measured_cv": round(measured, 4),
                     **_shared(band_row(frames, measured)),
                     **scattered_columns(at, stats, band, measured),
                     "model_sun_in_view": float(np.mean(sun)),
                     "model_sky_share": round(float(np.mean(sky)), 4),
                     "depth_m": float(rec.depth_m), "sun_zenith_deg": float(rec.sun_zenith_deg),
                     "wind_m_s": float(rec.wind_m_s),
                     "wind_direction_deg": base.water.wind_direction_deg,
                     "model_c555_per_m": round(beam_attenuation(at.config, 555.0), 4),
                     "measured_c555_per_m": float(rec.beam_attenuation_555),
                     "texel_mm": round(1e3 * base.map_window[0] / base.caustics.map_resolution, 2)})
    out = Path(out)
    paths = {"csv": out / "darecki2011_radiance.csv", "png": out / "darecki2011_radiance.png"}
    write_csv(paths["csv"], rows)
    plot(rows, paths["png"], quick)
    return paths


def near_gains(scattered, direct_mean: float, sky_mean: float) -> tuple[float, float, float]:
    """How the light scattered by less than a few degrees (``scattered``, band 0) scales the map's
    direct and sky parts of these means, 1 + near / mean each, and the near light of a part never
    in view (its mean 0), which is a background too: (sun's gain, sky's gain, that background)."""
    gains, unseen = [], 0.0
    for near, mean in ((float(scattered.near_sun[0]), direct_mean), (float(scattered.near_sky[0]), sky_mean)):
        gains.append(1.0 + near / mean if mean > 0.0 else 1.0)
        unseen += 0.0 if mean > 0.0 else near
    return gains[0], gains[1], unseen


def scattered_columns(scene, stats: list[dict], band: str, measured: float) -> dict:
    """The light scattered once into the sensor (:func:`~warpcaustics.caustics.path_radiance.
    sensor_path_radiance`), which the rendered map leaves out, from the frames' statistics ``stats``
    of ``band``: the share of the cone's light scattered by more than a few degrees
    (``model_scattered_share``), and the CV with it (``model_cv_scattered_smooth``), the light
    scattered by less following the part it comes from (the sun's the map's direct part, the sky's
    its sky part: from nearly the directions the sensor sees) and the rest a uniform background
    (its own flicker left out: the light of the whole lit water column)."""
    from warpcaustics.caustics.path_radiance import sensor_path_radiance

    scattered = sensor_path_radiance(scene)
    parts = [[(s[group][band]["mean"], s[group][band]["cv"]) for s in stats]
             for group in ("bands", "bands_direct", "bands_sky")]
    sun_gain, sky_gain, unseen = near_gains(scattered, float(np.mean([m for m, _ in parts[1]])),
                                            float(np.mean([m for m, _ in parts[2]])))
    background = float(scattered.wide[0]) + unseen
    scaled = with_beam_scaled(*parts, sun_gain, sky_gain)
    mean, cv = pooled_statistics(scaled, [background] * len(scaled))
    return {"model_scattered_share": round(float(scattered.wide[0]) / mean, 4),
            "model_cv_scattered_smooth": round(cv, 4),
            "model_scattered_smooth_over_measured": round(cv / measured, 3)}


def _shared(row: dict) -> dict:
    """Of the columns every Darecki row shares (:func:`~.common.band_row`), those of a whole patch's
    map with no long waves and no sky in halves."""
    return {k: row[k] for k in ("model_cv", "model_cv_frame_sd", "model_over_measured", "frames")}


def plot(rows: list[dict], path: Path, quick: bool = False) -> None:
    """CV against the zenith per panel, as Fig. 15: the record's thirteen angles and the model's, from
    the rows of ``darecki2011_radiance.csv``."""
    plt = pyplot(PLOT_NEEDS)
    panels = sorted({r["panel"] for r in rows})
    fig, axes = plt.subplots(1, len(panels), figsize=(4.2 * len(panels), 3.8), sharey=True, squeeze=False)
    for ax, panel in zip(axes[0], panels):
        rec = record(panel)
        rs = sorted((r for r in rows if r["panel"] == panel), key=lambda r: r["zenith_deg"])
        ax.plot(rec.zenith_deg, rec.cv, "ko-", label="Darecki et al. 2011, Fig. 15")
        ax.plot([r["zenith_deg"] for r in rs], [r["model_cv"] for r in rs], "s--", color="tab:blue",
                label="model, unscattered light")
        ax.plot([r["zenith_deg"] for r in rs], [r["model_cv_scattered_smooth"] for r in rs], "v:",
                color="tab:green", label="model, with the scattered light smooth")
        ax.axvline(rec.refracted_sun_zenith_deg, color="tab:orange", lw=0.8, label="refracted sun")
        ax.set_yscale("log")
        ax.set_title(f"{panel}: {rec.depth_m:g} m, sun {rec.sun_zenith_deg:g}°, {rec.wind_m_s:g} m/s",
                     fontsize=9)
        ax.set_xlabel("zenith angle [deg] (+: towards the sun)")
        ax.grid(alpha=0.3, which="both")
    axes[0][0].set_ylabel(f"CV of radiance, {rec.wavelength_nm:g} nm, {rec.field_of_view_deg:g}° FOV")
    axes[0][0].legend(fontsize=7)
    if quick:
        fig.suptitle("--quick: coarse check of the command, not a comparison", color="tab:red")
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)
