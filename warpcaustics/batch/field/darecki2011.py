"""Field comparison: the CV of downwelling irradiance against depth, Darecki et al. (2011).

Darecki, Stramski & Sokolski (2011), "Measurements of high-frequency light fluctuations induced by
sea surface waves with an Underwater Porcupine Radiometer System", J. Geophys. Res. 116, C00H09,
Fig. 13a: the CV of Ed at 443, 532 and 670 nm at six depths from 0.86 to 9.58 m, Santa Barbara
Channel, sun 30-33° from the zenith, wind 4.1-6.4 m/s, beam attenuation c(555) = 0.68 1/m, a
2.5 mm collector. The values come from the ``jerlov`` package (``darecki2011_irradiance_cv``).

``warpcaustics field darecki2011 SCENE --out DIR`` renders SCENE (``configs/field/darecki2011.toml``,
which holds the record's conditions) with its floor at each of the record's depths (or at the
``--depths`` asked, the record's or others: the model's CV(z) between and beyond the measured
depths, e.g. 0.5 to 10 m), as one resumable sweep, pools each depth's frames per band
(``stats.per_band``) and writes ``darecki2011.csv`` and the profile CV(z) per band,
``darecki2011.png``. As for Gernez & Antoine, the model's CV is spatial over the whole sea —
within the window after the collector, and between the means of the patch's windows from its
coarse map (``patch_windows``; :func:`~warpcaustics.batch.field.common.patch_variance`), pooled
over frames — and the measurement's temporal; the two agree for a stationary, homogeneous sea.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from warpcaustics.batch.field.common import (
    LONG_WAVES_FOLDER,
    band_row,
    band_statistics,
    check_frames,
    check_overrides,
    checked_arguments,
    long_waves_overrides,
    render_points,
    select_measured,
)
from warpcaustics.errors import ConfigError
from warpcaustics.io.files import atomic_path, pyplot, write_csv

POINT_KEYS = ("floor.depth_m",)

QUICK_OVERRIDES = {
    "water.resolution": 64,
    "water.extent_m": 8.0,
    "caustics.map_resolution": 40,
    "caustics.map_extent_m": 0.4,
    "sun.disk_samples": 2,
    "sky.directions": 2,
}
"""``--quick``: a coarse version of every task, to check the command end to end (not a comparison)."""

PLOT_NEEDS = "the comparison's plot needs"


def record():
    """The measured profile (``jerlov.darecki2011_irradiance_cv``)."""
    import jerlov

    return jerlov.darecki2011_irradiance_cv()


def beam_attenuation(config, wavelength_nm: float) -> float:
    """c = a + b [1/m] of the scene's water at ``wavelength_nm``."""
    from dataclasses import replace

    from warpcaustics.optics.spectra import bins_for, water_optics

    optics = replace(config.optics, wavelengths=replace(config.optics.wavelengths, list_nm=(wavelength_nm,)))
    o = water_optics(optics, bins_for(optics))
    return float(o.absorption_per_m[0] + o.scattering_per_m[0])


def check_scene(config, rec) -> None:
    """One band at each of the record's wavelengths, per-band statistics, a stateless sea."""
    listed = tuple(config.optics.wavelengths.list_nm)
    wanted = tuple(float(w) for w in rec.wavelengths_nm)
    if listed != wanted:
        raise ConfigError(f"the Darecki 2011 comparison is of the bands {list(wanted)} nm: set "
                          f"optics.wavelengths = {list(wanted)}")
    if not config.stats.per_band:
        raise ConfigError("the Darecki 2011 comparison needs each band's statistics: set "
                          "stats.per_band = true")
    if config.water.stateful:
        raise ConfigError(f"water.model = {config.water.model.value!r} is stateful; the comparison pools "
                          "independent frames of a wind sea: use water.model = 'fft'")


@checked_arguments
def run_darecki2011(
    scene: str | Path,
    out: str | Path,
    *,
    depths: tuple[float, ...] | None = None,
    frames: int = 3,
    frame_interval_s: float = 5.0,
    workers: int = 1,
    device: str | None = None,
    quick: bool = False,
    quiet: bool = False,
    force: bool = False,
    overrides: dict | None = None,
    long_waves_m: float = 0.0,
) -> dict[str, Path]:
    """Render SCENE at each of the record's depths (or at ``depths``: any positive depths, those the
    record lacks with no measured value beside them) as one resumable sweep into ``out``, pool each
    depth's frames per band and write ``darecki2011.csv`` and ``darecki2011.png``. ``overrides``:
    config keys set at every depth (``--set``). The frames are ``frame_interval_s`` apart, by
    default 5 s, longer than the peak waves' period (2.6 s at the record's wind): each frame is a
    new realisation of the largest scales, which decide the CV at depth (docs/validation.md).
    ``long_waves_m`` > 0: a coarse patch that wide of the waves longer than the scene's patch,
    rendered at every depth too (into ``out/long_waves``) and nested with the scene's CV as in the
    Gernez comparison (:func:`~warpcaustics.batch.field.common.nested_cv`); 0 (the default): the
    scene's waves alone."""
    rec = record()
    config, points = render_record(
        scene, out, rec, POINT_KEYS[0], rec.depth_m, depths, ("--depths", "depth"), frames=frames,
        frame_interval_s=frame_interval_s, workers=workers, device=device, quick=quick, quiet=quiet,
        force=force, overrides=overrides, unmeasured=True, long_waves_m=long_waves_m)
    c555 = beam_attenuation(config, 555.0)
    rows = []
    for depth, k, bands, longer in points:
        for j, band in enumerate(bands):
            measured = None if k is None else float(rec.cv[k, j])
            rows.append({"depth_m": depth, "wavelength_nm": float(rec.wavelengths_nm[j]),
                         "measured_cv": None if measured is None else round(measured, 4),
                         **band_row(band, measured, None if longer is None else longer[j]),
                         "model_c555_per_m": round(c555, 4),
                         "measured_c555_per_m": float(rec.beam_attenuation_555)})
    out = Path(out)
    paths = {"csv": out / "darecki2011.csv", "png": out / "darecki2011.png"}
    write_csv(paths["csv"], rows)
    plot_profile(rows, paths["png"], quick)
    return paths


def render_record(scene: str | Path, out: str | Path, rec, key: str, have: np.ndarray,
                  wanted: tuple[float, ...] | None, flag: tuple[str, str], *, frames: int,
                  frame_interval_s: float, workers: int, device: str | None, quick: bool, quiet: bool,
                  force: bool, overrides: dict | None, unmeasured: bool = False, long_waves_m: float = 0.0):
    """What every Darecki comparison shares: SCENE checked against the record ``rec``, rendered with
    config ``key`` at each of the record's values ``have`` (or those ``wanted``; ``flag``: the
    command's flag choosing them and what they are; ``unmeasured``: values the record lacks too) as
    one resumable sweep, ``frames`` frames ``frame_interval_s`` apart, and with ``long_waves_m`` > 0
    a second sweep of the waves longer than the scene's patch on a patch that wide
    (:func:`~warpcaustics.batch.field.common.long_waves_overrides`). Returns the scene's config
    and, per value, (value, its index in ``have`` or None where the record lacks it, per band of the
    record the statistics of every frame, the same of the long waves' frames or None)."""
    from warpcaustics.scene import load_scene

    times = check_frames(frames, frame_interval_s)
    check_overrides(overrides, (key,), flag[0])
    scene_path = Path(scene).resolve()
    fixed = {**(QUICK_OVERRIDES if quick else {}), **(overrides or {})}
    base = load_scene(scene_path, fixed)
    check_scene(base.config, rec)
    pyplot(PLOT_NEEDS)  # before the sweep, not after it
    chosen = select_measured(have, wanted, *flag, unmeasured=unmeasured)
    if quick:
        chosen = [chosen[0], chosen[-1]] if len(chosen) > 1 else chosen
    long_fixed = long_waves_overrides(base.config, fixed, long_waves_m, quick, scene_path)
    variants = [{key: v} for v in chosen]
    sweep = render_points(scene_path, fixed, variants, times, out, workers=workers, device=device,
                          quiet=quiet, force=force, chosen_by=(key, flag[0]))
    long_out = Path(out) / LONG_WAVES_FOLDER
    long = None if long_fixed is None else render_points(
        scene_path, long_fixed, variants, times, long_out, workers=workers, device=device, quiet=quiet,
        force=force)
    points = [(v, measured_index(have, v), band_statistics(sweep, out, {key: v}, rec.wavelengths_nm),
               None if long is None else band_statistics(long, long_out, {key: v}, rec.wavelengths_nm))
              for v in chosen]
    return base.config, points


def measured_index(have: np.ndarray, value: float) -> int | None:
    """The index of ``value`` in the record's ``have`` (None: not a measured value)."""
    k = int(np.argmin(np.abs(np.asarray(have, np.float64) - value)))
    return k if abs(float(have[k]) - value) < 1e-6 else None


def plot_profile(rows: list[dict], path: Path, quick: bool = False) -> None:
    """CV(z), one panel per band: the measured profile and the model's, from the rows of
    ``darecki2011.csv`` (its columns, numbers as floats; a depth not measured has ``measured_cv`` None)."""
    plt = pyplot(PLOT_NEEDS)
    bands = sorted({r["wavelength_nm"] for r in rows})
    fig, axes = plt.subplots(1, len(bands), figsize=(3.8 * len(bands), 4.2), sharey=True, squeeze=False)
    for ax, nm in zip(axes[0], bands):
        rs = [r for r in rows if r["wavelength_nm"] == nm]
        z = [r["depth_m"] for r in rs]
        measured = [r for r in rs if r["measured_cv"] is not None]
        ax.plot([r["measured_cv"] for r in measured], [r["depth_m"] for r in measured], "ko-",
                label="Darecki et al. 2011 (Fig. 13a)")
        ax.errorbar([r["model_cv"] for r in rs], z, xerr=[r["model_cv_frame_sd"] for r in rs], fmt="s-",
                    color="tab:blue", capsize=3, label="model, the whole sea")
        if any(r["model_cv_window"] != r["model_cv"] for r in rs):
            ax.plot([r["model_cv_window"] for r in rs], z, "s:", color="tab:gray",
                    label="model, the window alone (its frames pooled)")
        if all(r["model_cv_continuous_sky"] is not None for r in rs):
            ax.plot([r["model_cv_continuous_sky"] for r in rs], z, "D-", color="tab:purple",
                    label="model, the sky's continuum")
        ax.set_xscale("log")
        ax.xaxis.set_major_locator(plt.LogLocator(subs=(1.0, 2.0, 5.0)))  # labels within a decade too
        ax.xaxis.set_major_formatter(plt.FormatStrFormatter("%g"))
        ax.xaxis.set_minor_formatter(plt.NullFormatter())  # the minor ticks' labels overlap
        ax.set_title(f"{nm:g} nm")
        ax.set_xlabel("CV of Ed")
        ax.grid(alpha=0.3, which="both")
    axes[0][0].invert_yaxis()
    axes[0][0].set_ylabel("depth [m]")
    axes[0][0].legend(fontsize=8)
    if quick:
        fig.suptitle("--quick: coarse check of the command, not a comparison", color="tab:red")
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)


def chlorophyll_for(config, c_per_m: float, wavelength_nm: float = 555.0) -> float:
    """The chlorophyll [mg m⁻³] at which the scene's bio-optical water has beam attenuation
    ``c_per_m`` at ``wavelength_nm`` (bisection in log chlorophyll on the package's own IOPs): how
    ``configs/field/darecki2011.toml`` got its value from the record's c(555)."""
    from dataclasses import replace

    lo, hi = 1e-3, 100.0
    for _ in range(60):
        mid = math.sqrt(lo * hi)
        cfg = replace(config, optics=replace(config.optics, chlorophyll_mg_m3=mid))
        lo, hi = (mid, hi) if beam_attenuation(cfg, wavelength_nm) < c_per_m else (lo, mid)
    return math.sqrt(lo * hi)
