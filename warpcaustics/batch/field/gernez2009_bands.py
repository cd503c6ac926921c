"""Field comparison: the CV of downwelling irradiance per band against the sun's zenith, Gernez &
Antoine (2009) Fig. 10a.

Gernez & Antoine's Fig. 10a gives the median CV of the downwelling irradiance at 443, 490, 510,
560, 670 and 683 nm at the upper depth (2.7-3.7 m) under clear skies against the sun's zenith (its
510 nm line is Fig. 8a's), read off the figure by the ``jerlov`` package
(``gernez2009_band_cv("sun_zenith_deg")``). The red's CV is 1.5 times the blue's at a 20° sun and
2.7 times at 80°.

``warpcaustics field gernez2009_bands SCENE --out DIR`` renders the Gernez scene
(``configs/field/gernez2009.toml``) in those six bands at once (:func:`band_overrides`) at each of
the record's zeniths (``--zeniths``), pools each zenith's frames per band over the whole sea as
:mod:`.gernez2009` does (the window, the patch's windows and, with ``--long-waves``, the waves
longer than the patch) and writes ``gernez2009_bands.csv`` and ``gernez2009_bands.png``.

The sky: the paper prints one diffuse share per zenith (from Gregg & Carder's 1990 sky model) and
not at which wavelength; the scene holds it over the six bands, each band's own share following
the sky's spectral shape (``sky.spectrum``, by default the diffuse part of ASTM G173-03, bluer than
the sun; the ``sky_share`` column). The level of the CV is the question of :mod:`.gernez2009`; the
ratio CV(λ)/CV(510 nm) (the ``*_over_510`` columns) is free of what acts on every band alike (the
surface's slopes, the collector, a sensor's response time) and holds what depends on the
wavelength: the sky's share of the light, the water's absorption along the sky's longer slant
paths, the water's scattering.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from warpcaustics.batch.field.common import (
    LONG_WAVES_FOLDER,
    check_frames,
    check_overrides,
    checked_arguments,
    continuous_sky,
    frame_statistics_of,
    long_waves_overrides,
    render_points,
    select_measured,
)
from warpcaustics.batch.field.gernez2009 import (
    LONG_WAVES_EXTENT_M,
    PLOT_NEEDS,
    QUICK_OVERRIDES,
    check_conditions,
    diffuse_fraction,
    direct_transmission,
    weakest_clear_sun,
    whole_sea,
)
from warpcaustics.config import Scattering
from warpcaustics.io.files import atomic_path, pyplot, write_csv

POINT_KEYS = ("sun.elevation_deg", "sky.diffuse_fraction")
"""What each point sets: the sun's zenith and the paper's diffuse share there."""

REFERENCE_NM = 510.0
"""The band the ratios are taken to: the paper's Fig. 8 band, the level comparison's."""


def record():
    """Fig. 10a: the median CV per band against the sun's zenith (``jerlov.gernez2009_band_cv``)."""
    import jerlov

    return jerlov.gernez2009_band_cv("sun_zenith_deg")


def band_overrides(rec) -> dict:
    """The record's six bands, rendered at once, with each band's statistics."""
    return {"optics.wavelengths": [float(w) for w in rec.wavelengths_nm], "stats.per_band": True}


def sky_shares(scene) -> np.ndarray:
    """(K,) each band's share of the above-water global horizontal irradiance that comes from the
    sky, E_sky / (E_sky + E_sun sin(elevation)), as the scene lights it (``sky.diffuse_fraction``
    over all its bands, shaped by ``sky.spectrum``)."""
    from warpcaustics.optics import spectra

    bins = spectra.bins_for(scene.config.optics)
    sun = spectra.sun_irradiance(bins, scene.config.sun, scene.base_dir)
    sky = scene.sky_irradiance(sun)
    beam = np.asarray(sun, np.float64) * math.sin(math.radians(scene.config.sun.elevation_deg))
    return sky / (sky + beam)


@checked_arguments
def run_gernez2009_bands(
    scene: str | Path,
    out: str | Path,
    *,
    zeniths: tuple[float, ...] | None = None,
    frames: int = 3,
    frame_interval_s: float = 2.0,
    workers: int = 1,
    device: str | None = None,
    quick: bool = False,
    quiet: bool = False,
    force: bool = False,
    overrides: dict | None = None,
    long_waves_m: float = LONG_WAVES_EXTENT_M,
) -> dict[str, Path]:
    """Render SCENE in the record's six bands at each of its zeniths (or ``zeniths``) as one
    resumable sweep into ``out`` (and its longer waves into ``out/long_waves``, ``long_waves_m``:
    0 for none), pool each zenith's frames per band and write ``gernez2009_bands.csv`` and
    ``gernez2009_bands.png``. ``overrides``: config keys set at every point (``--set``)."""
    from warpcaustics.scene import load_scene

    rec = record()
    times = check_frames(frames, frame_interval_s)
    bands = band_overrides(rec)
    check_overrides(overrides, POINT_KEYS + tuple(bands), "--zeniths (the bands are the record's)")
    scene_path = Path(scene).resolve()
    fixed = {**(QUICK_OVERRIDES if quick else {}), **(overrides or {}), **bands}
    base = load_scene(scene_path, fixed)
    check_conditions(base.config)
    pyplot(PLOT_NEEDS)  # before the sweep, not after it
    chosen = select_measured(rec.x, zeniths, "--zeniths", "sun zenith [deg]")
    if quick:
        chosen = [chosen[0], chosen[-1]] if len(chosen) > 1 else chosen
    variants = [{"sun.elevation_deg": 90.0 - z, "sky.diffuse_fraction": diffuse_fraction(z)} for z in chosen]
    long_fixed = long_waves_overrides(base.config, fixed, long_waves_m, quick, scene_path)
    out = Path(out)
    sweep = render_points(scene_path, fixed, variants, times, out, workers=workers, device=device,
                          quiet=quiet, force=force)
    long_out = out / LONG_WAVES_FOLDER
    long = None if long_fixed is None else render_points(
        scene_path, long_fixed, variants, times, long_out, workers=workers, device=device, quiet=quiet,
        force=force)
    rows = []
    for z, variant in zip(chosen, variants):
        stats = frame_statistics_of(sweep, out, variant)
        longer = None if long is None else frame_statistics_of(long, long_out, variant)
        at_point = load_scene(scene_path, {**fixed, **variant})
        k = int(np.argmin(np.abs(rec.x - z)))
        rows += _zenith_rows(at_point, z, rec.wavelengths_nm, rec.cv[k], stats, longer)
    paths = {"csv": out / "gernez2009_bands.csv", "png": out / "gernez2009_bands.png"}
    write_csv(paths["csv"], rows)
    _plot(rows, paths["png"], quick)
    return paths


def band_frames(stats: list[dict], wavelength_nm: float) -> list[dict]:
    """One band's statistics of each frame, under the names of the band-integrated fields
    (:data:`~warpcaustics.batch.field.gernez2009.STAT_FIELDS`): the band, its direct sun's part and
    its sky's."""
    key = f"{wavelength_nm:g}nm_w_m2_nm"
    return [{"irradiance_w_m2": s["bands"][key], "direct_irradiance_w_m2": s["bands_direct"][key],
             "sky_irradiance_w_m2": s["bands_sky"][key]} for s in stats]


def _zenith_rows(scene, zenith: float, wavelengths_nm, measured, stats: list[dict],
                 longer: list[dict] | None) -> list[dict]:
    """One row per band at one zenith (``scene``: the scene at that point): the measured CV beside
    the model's columns over the whole sea (:func:`~warpcaustics.batch.field.gernez2009.whole_sea`),
    the sky's share of the light above the water (``sky_share``) and at the sensor
    (``model_sky_share_at_depth``), and each CV over the reference band's at that zenith."""
    from warpcaustics.optics.spectra import bins_for, water_optics

    config = scene.config
    shares = sky_shares(scene)
    scattering = water_optics(config.optics, bins_for(config.optics)).scattering_per_m
    rows = []
    for j, nm in enumerate(wavelengths_nm):
        frames = band_frames(stats, float(nm))
        # a map that holds the scattered light already (optics.scattering = "small_angle") adds none
        t = 1.0
        if config.optics.scattering is Scattering.SINGLE:
            t = direct_transmission(zenith, config.floor.depth_m, float(config.optics.ior),
                                    float(scattering[j]))
        sea = whole_sea(frames, None if longer is None else band_frames(longer, float(nm)), t,
                        weakest_sun=weakest_clear_sun(config.sky.diffuse_fraction))
        mean = sea.pop("model_mean_w_m2")  # of the band: W m⁻² nm⁻¹
        sky = float(np.mean([f["sky_irradiance_w_m2"]["mean"] for f in frames]))
        cv = float(measured[j])
        rows.append({"sun_zenith_deg": zenith, "wavelength_nm": float(nm),
                     "diffuse_fraction": round(config.sky.diffuse_fraction, 4),
                     "sky_share": round(float(shares[j]), 4), "measured_cv": round(cv, 4), **sea,
                     "model_over_measured": round(sea["model_cv"] / cv, 3),
                     "model_cv_continuous_sky": continuous_sky([f["irradiance_w_m2"] for f in frames]),
                     "direct_transmission": round(t, 4), "frames": len(frames),
                     "model_mean_w_m2_nm": mean,
                     "model_sky_share_at_depth": round(sky / mean, 4) if mean else None})
    ref = int(np.argmin(np.abs(np.asarray(wavelengths_nm, np.float64) - REFERENCE_NM)))
    for r in rows:
        for name in RATIO_COLUMNS:
            base = rows[ref][name]
            r[f"{name}_over_510"] = round(r[name] / base, 3) if base else None
    return rows


RATIO_COLUMNS = ("measured_cv", "model_cv", "model_cv_uniform_sky", "model_cv_window")
"""The columns also given over the 510 nm band's at the same zenith (``…_over_510``)."""


def _plot(rows: list[dict], path: Path, quick: bool) -> None:
    """Left: CV against the sun's zenith per band, measured and model. Right: each band's CV over
    510 nm's against the sun's zenith, measured and model."""
    plt = pyplot(PLOT_NEEDS)
    fig, (left, right) = plt.subplots(1, 2, figsize=(12.0, 4.4))
    bands = sorted({r["wavelength_nm"] for r in rows})
    colours = plt.get_cmap("turbo")(np.linspace(0.08, 0.95, len(bands)))
    for nm, colour in zip(bands, colours):
        rs = [r for r in rows if r["wavelength_nm"] == nm]
        x = [r["sun_zenith_deg"] for r in rs]
        left.plot(x, [r["measured_cv"] for r in rs], "o", color=colour, label=f"{nm:g} nm measured")
        left.plot(x, [r["model_cv"] for r in rs], "s-", color=colour, mfc="none", label=f"{nm:g} nm model")
    left.set_xlabel("sun zenith angle [deg]")
    left.set_ylabel("CV of downwelling irradiance")
    left.set_title("clear sky, 3.2 m: Gernez & Antoine 2009 Fig. 10a (dots), model (squares)")
    for nm, colour in zip(bands, colours):
        rs = [r for r in rows if r["wavelength_nm"] == nm]
        if nm == REFERENCE_NM:
            continue
        x = [r["sun_zenith_deg"] for r in rs]
        right.plot(x, [r["measured_cv_over_510"] for r in rs], "o", color=colour, label=f"{nm:g} nm measured")
        if all(r["model_cv_over_510"] is not None for r in rs):  # none where 510 nm's CV is 0
            right.plot(x, [r["model_cv_over_510"] for r in rs], "s-", color=colour, mfc="none",
                       label=f"{nm:g} nm model")
    right.axhline(1.0, color="k", lw=0.5)
    right.set_xlabel("sun zenith angle [deg]")
    right.set_ylabel("CV / CV at 510 nm")
    right.set_title("each band's CV over 510 nm's (measured: dots; model: squares)")
    for ax in (left, right):
        ax.set_ylim(bottom=0.0)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7, ncol=2)
    if quick:
        fig.suptitle("--quick: coarse check of the command, not a comparison", color="tab:red")
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)
