"""Field comparison: the model's irradiance fluctuations against Gernez & Antoine (2009).

Gernez, P. and Antoine, D. (2009), "Field characterization of wave-induced underwater light field
fluctuations", J. Geophys. Res. 114, C06025, measured the coefficient of variation (CV = std/mean)
of the downwelling irradiance at 510 nm, 2.7-3.7 m deep, with an 8 mm collector, at the BOUSSOLE
buoy under clear skies, against the sun's zenith angle (their Fig. 8a), against the wind (Fig. 8c)
and against the water's Kd(490) (Fig. 8, the ``water`` series: the model in the Jerlov types). The
measured values, and the diffuse share of the sky they print along Fig. 8a, come
from the ``jerlov`` package (``gernez2009_cv_by_sun_zenith``, ``gernez2009_cv_by``,
``gernez2009_diffuse_share``), which read them off the figures and records how.

``warpcaustics field gernez2009 SCENE --out DIR`` renders SCENE (``configs/field/gernez2009.toml``)
at each measured zenith, with the paper's diffuse share, and at each wind, as one resumable sweep
(issue 7's runner: ``--workers`` processes), then pools every point's frames and writes
``gernez2009.csv`` and ``gernez2009.png``.

The model's CV is spatial, over the whole sea: within the floor-map window after the collector
(each frame's CV about the window's own mean), between the windows of the scene's periodic patch
(the means of the patch's windows on the coarse map of it the window's light is computed beside,
``patch_windows``), and, with ``--long-waves``, the waves longer than the patch, from a coarse
patch of them alone (``water.shortest_wave_m``) rendered at every point too; the three scales nest
(:func:`~warpcaustics.batch.field.common.nested_cv`). The measurement's is temporal, at one point
over minutes. The two agree for a statistically homogeneous, stationary sea (ergodicity), which a
linear random FFT sea is. Before 2026-12-06 the model's CV was the window's frames pooled: three
frames 2 s apart sample the patch's windows poorly (its 8 m waves' period is 2.3 s), which at a low
sun, where most of the variance lies at scales above the window, left it several times too low.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace
from enum import Enum
from pathlib import Path

import numpy as np

from warpcaustics.batch.arguments import names_argument
from warpcaustics.batch.field.common import (
    LONG_WAVES_FOLDER,
    check_frames,
    check_overrides,
    checked_arguments,
    continuous_sky,
    frame_statistics_of,
    long_waves_overrides,
    numbers_of,
    pooled_statistics,
    render_points,
    sea_cv,
    with_background,
    with_beam_scaled,
)
from warpcaustics.config import Scattering, SkyModel, WaterType
from warpcaustics.errors import ConfigError
from warpcaustics.io.files import atomic_path, pyplot, write_csv

SERIES = ("zenith", "wind", "overcast", "water")
"""zenith: Fig. 8a, CV against the sun's zenith under clear skies; wind: Fig. 8c, against √wind;
overcast: Fig. 7a, against the sun's zenith under overcast skies (the sky's light alone); water:
Fig. 8, against the water's Kd(490), the model in the Jerlov types (:data:`WATER_TYPES`)."""

DEFAULT_SERIES = ("zenith", "wind")
"""The series run unless ``--series`` names others: the clear skies of the paper's Fig. 8."""

OVERCAST_SKY = {"sky.model": "cie", "sky.cie_type": 1}
"""The overcast series' sky: the CIE standard overcast sky (type 1, ../shared/data/sky). The paper's
overcast minutes had less than 0.6 of the clear-sky model's irradiance above water."""

OVERCAST_DIFFUSE_FRACTION = 0.99
"""The largest share ``sky.diffuse_fraction`` takes: the sun keeps 1 %, and the overcast series
compares the sky's part of the map alone (run.json's ``sky_irradiance_w_m2``)."""

CLEAR_SELECTION = 0.85
"""The paper's clear minutes: above-water irradiance at least this share of its clear-sky model's
(``jerlov.gernez2009_cv_by_sun_zenith().sky``). With the sky's light as modelled, the selection
admits a sun's beam weaker by up to 1 − 0.85 of the total: the ``model_cv_weakest_clear_sun``
column (:func:`weakest_clear_sun`)."""


def weakest_clear_sun(diffuse_fraction: float) -> float:
    """The weakest sun's beam, as a share of the sky model's, that the paper's selection admits with
    the sky's light as modelled (:data:`CLEAR_SELECTION`): (1 − f − 0.15)/(1 − f) for the diffuse
    share f, 0 where the sky alone passes it. A sensitivity, not a bound: a haze that turns beam into
    sky light lets a weaker beam pass and smooths the light further; nor is it a condition the
    record is known to hold."""
    direct = 1.0 - diffuse_fraction
    return max(direct - (1.0 - CLEAR_SELECTION), 0.0) / direct if direct > 0 else 0.0


WIND_SERIES_ZENITH_DEG = 40.0
"""Sun zenith of the wind series. The paper's Fig. 8c pools all zeniths; 40° is our choice, near the
middle of the 20-85° range it reports."""

WATER_TYPES = ("I", "IA", "IB", "II", "III")
"""The water series' waters: the oceanic Jerlov types, whose Kd(490) (Jerlov 1976, from the ``jerlov``
package: 0.023-0.115 1/m) spans the paper's classes (0.025-0.145); the model takes each type's a and
b (``optics.jerlov_source``) at the wind series' sun zenith and the scene's wind. The paper's classes
pool every sun zenith and wind, so the series compares how the CV falls as the water grows turbid;
its level is the zenith and wind series' question."""

MIN_SQRT_WIND = 1.2
"""The wind series starts at the class √U = 1.2 (1.44 m/s): below it a wind sea is nearly flat,
while the buoy still saw swell from elsewhere, which a wind-driven spectrum cannot hold."""

QUICK_OVERRIDES = {
    "water.resolution": 64,
    "caustics.map_resolution": 64,
    "sun.disk_samples": 2,
    "sky.directions": 2,
}
"""``--quick``: a coarse version of every task, to check the command end to end in seconds (CI,
tests). Its CVs are not a comparison: the surface cells (12.5 cm) are far too coarse to focus."""


LONG_WAVES_EXTENT_M = 128.0
"""The side [m] of the patch of the waves longer than the scene's (``--long-waves``): the scene's 8 m
patch holds about half of a 5 m/s sea's elevation variance (its peak is 10 m long), and 128 m hold
all of the wind series' (at 13 m/s over 20 km of fetch the peak is 25 m long; waves over 64 m
carry none of the variance). At a low sun their tilts decide the light (docs/validation.md)."""

POINT_KEYS = ("sun.elevation_deg", "sky.diffuse_fraction", "water.wind_speed_m_s", "sky.model",
              "sky.cie_type", "optics.water_type")
"""The keys a point may set (Point.overrides): a --set of one that the chosen points set would be
overwritten (the sky's model and type only by the overcast series: the clear series take the
scene's, which a row of the error budget sets)."""


@dataclass(frozen=True)
class Point:
    """One condition of the comparison and the paper's CV there."""

    series: str
    sun_zenith_deg: float
    wind_m_s: float | None
    """None: the scene's own wind."""
    diffuse_fraction: float
    measured_cv: float
    measured_cv_sd: float
    water_type: str | None = None
    """The water series' Jerlov type, ``optics.water_type``'s value (None: the scene's water)."""
    kd490_per_m: float | None = None
    """The water series' Kd(490) of that type [1/m], where the measured CV is read."""

    def overrides(self) -> dict:
        out = {"sun.elevation_deg": 90.0 - self.sun_zenith_deg, "sky.diffuse_fraction": self.diffuse_fraction}
        if self.wind_m_s is not None:
            out["water.wind_speed_m_s"] = self.wind_m_s
        if self.water_type is not None:
            out["optics.water_type"] = self.water_type
        if self.series == "overcast":
            out.update(OVERCAST_SKY)
        return out


def diffuse_fraction(sun_zenith_deg: float) -> float:
    """The paper's diffuse share E_diffuse/E_total of the above-water irradiance (from its sky model)
    at this zenith: linear between the values printed every 10° (``jerlov.gernez2009_diffuse_share``)."""
    import jerlov

    share = jerlov.gernez2009_diffuse_share()
    return float(np.interp(sun_zenith_deg, share.sun_zenith_deg, share.diffuse_fraction))


def gernez2009_points(series: tuple[str, ...] = DEFAULT_SERIES) -> list[Point]:
    """The measured points: CV against the sun's zenith (Fig. 8a) and against √wind (Fig. 8c) under
    clear skies, and against the sun's zenith under overcast skies (Fig. 7a)."""
    import jerlov

    points = []
    if "zenith" in series:
        by_zenith = jerlov.gernez2009_cv_by_sun_zenith()
        for z, cv, sd in zip(by_zenith.sun_zenith_deg, by_zenith.cv, by_zenith.cv_sd):
            points.append(Point("zenith", float(z), None, diffuse_fraction(float(z)), float(cv), float(sd)))
    if "wind" in series:
        by_wind = jerlov.gernez2009_cv_by("sqrt_wind")
        f = diffuse_fraction(WIND_SERIES_ZENITH_DEG)
        for x, cv, sd in zip(by_wind.x, by_wind.cv, by_wind.cv_sd):
            if x >= MIN_SQRT_WIND:
                points.append(Point("wind", WIND_SERIES_ZENITH_DEG, float(x) ** 2, f, float(cv), float(sd)))
    if "overcast" in series:
        by_zenith = jerlov.gernez2009_cv_by("sun_zenith_deg", sky="overcast")
        for z, cv, sd in zip(by_zenith.x, by_zenith.cv, by_zenith.cv_sd):
            points.append(Point("overcast", float(z), None, OVERCAST_DIFFUSE_FRACTION, float(cv), float(sd)))
    if "water" in series:
        points += water_points()
    return points


def water_points() -> list[Point]:
    """The water series: each Jerlov type of :data:`WATER_TYPES` at its Kd(490) (Jerlov 1976), the
    measured CV (and its standard deviation) linear in Kd(490) between the medians of the paper's
    classes (0.01 1/m wide, at their centres; held at the first class's below its centre), at the
    wind series' sun zenith and the scene's wind."""
    import jerlov

    by_kd = jerlov.gernez2009_cv_by("kd490_per_m")
    has_sd = ~np.isnan(by_kd.cv_sd)  # two classes print no spread
    f = diffuse_fraction(WIND_SERIES_ZENITH_DEG)
    points = []
    for name in WATER_TYPES:
        kd = float(jerlov.water(name, source="jerlov1976").kd(490.0))
        cv = float(np.interp(kd, by_kd.x, by_kd.cv))
        sd = float(np.interp(kd, by_kd.x[has_sd], by_kd.cv_sd[has_sd]))
        points.append(Point("water", WIND_SERIES_ZENITH_DEG, None, f, cv, sd, f"jerlov_{name}", kd))
    return points


def select_points(points: list[Point], zeniths: tuple[float, ...] | None,
                  sqrt_winds: tuple[float, ...] | None) -> list[Point]:
    """The points of the zenith and overcast series at ``zeniths`` [deg] and of the wind series at
    ``sqrt_winds`` [√(m/s)] (None: all of that series); a value the record does not hold is an error
    naming them; a value given twice is chosen once. The water series is kept whole."""
    chosen = [p for p in points if p.series == "water"]
    zeniths, sqrt_winds = numbers_of("--zeniths", zeniths), numbers_of("--sqrt-winds", sqrt_winds)
    flags = ((("zenith", "overcast"), zeniths, lambda p: p.sun_zenith_deg, "--zeniths"),
             (("wind",), sqrt_winds, lambda p: math.sqrt(p.wind_m_s), "--sqrt-winds"))
    for series, wanted, key, flag in flags:
        have = [p for p in points if p.series in series]
        if wanted is None:
            chosen += have
            continue
        for value in wanted:
            match = [p for p in have if abs(key(p) - value) < 1e-6]
            if not match:
                held = ", ".join(sorted({f"{key(p):g}" for p in have}, key=float)) or "none (not in --series)"
                raise ConfigError(f"{flag}: {value:g} is not a measured point; the record holds {held}")
            chosen += [p for p in match if p not in chosen]
    return chosen


def direct_transmission(sun_zenith_deg: float, depth_m: float, ior: float, scattering_per_m: float) -> float:
    """exp(−b·d/cos θ_w): the share of the sun's refracted beam not scattered on its way down. The
    rest, lost by single scattering, is mostly scattered forward (Petzold's mean cosines are
    0.87-0.95, docs/physics.md) and arrives spread over tens of centimetres, wider than the
    caustics: a uniform background is its limit."""
    sin_w = math.sin(math.radians(sun_zenith_deg)) / ior
    return math.exp(-scattering_per_m * depth_m / math.sqrt(1.0 - sin_w * sin_w))


@checked_arguments
def run_gernez2009(
    scene: str | Path,
    out: str | Path,
    *,
    series: tuple[str, ...] = DEFAULT_SERIES,
    frames: int = 3,
    frame_interval_s: float = 2.0,
    workers: int = 1,
    device: str | None = None,
    quick: bool = False,
    quiet: bool = False,
    force: bool = False,
    overrides: dict | None = None,
    zeniths: tuple[float, ...] | None = None,
    sqrt_winds: tuple[float, ...] | None = None,
    long_waves_m: float = LONG_WAVES_EXTENT_M,
) -> dict[str, Path]:
    """Render every point of the comparison (a resumable sweep into ``out``), pool each point's
    frames and write ``gernez2009.csv`` and ``gernez2009.png``. ``overrides``: config keys set on
    every point (``--set``: a row of the error budget); ``zeniths`` / ``sqrt_winds``: only these of
    the record's points (None: all). ``long_waves_m``: the side of a coarse patch of the waves longer
    than the scene's, rendered at every point too (a second sweep, into ``out/long_waves``) and
    combined with the scene's (:func:`~warpcaustics.batch.field.common.nested_cv`); 0: the scene's waves
    alone."""
    from warpcaustics.scene import load_scene

    series = names_argument("--series", series, SERIES)
    unknown = set(series) - set(SERIES)
    if not series or unknown:
        raise ConfigError(f"--series {','.join(series)!r} must name some of: {', '.join(SERIES)}")
    times = check_frames(frames, frame_interval_s)
    scene_path = Path(scene).resolve()
    fixed = {**(QUICK_OVERRIDES if quick else {}), **(overrides or {})}
    base = load_scene(scene_path, fixed)
    _check_scene(base.config)
    pyplot(PLOT_NEEDS)  # before the sweep, not after it
    points = select_points(gernez2009_points(series), zeniths, sqrt_winds)
    if not points:
        raise ConfigError("--zeniths / --sqrt-winds chose no point of the record: name at least one")
    check_overrides(overrides, tuple({k for p in points for k in p.overrides()}),
                    "--zeniths / --sqrt-winds / --series")
    if quick:  # the first and last zenith, the first wind, the first overcast zenith, the two end waters
        ends = {"zenith": lambda ps: ps[:1] + ps[1:][-1:], "wind": lambda ps: ps[:1],
                "overcast": lambda ps: ps[:1], "water": lambda ps: ps[:1] + ps[1:][-1:]}
        points = [p for s in series for p in ends[s]([q for q in points if q.series == s])]
    long_fixed = long_waves_overrides(base.config, fixed, long_waves_m, quick, scene_path)
    overrides, variants = point_variants(points, base.config)
    out = Path(out)
    sweep = render_points(scene_path, fixed, variants, times, out, workers=workers, device=device,
                          quiet=quiet, force=force)
    long = None
    if long_fixed is not None:
        long_out = out / LONG_WAVES_FOLDER
        long = (render_points(scene_path, long_fixed, variants, times, long_out, workers=workers,
                              device=device, quiet=quiet, force=force), long_out)
    rows = _rows(points, overrides, (sweep, out), long, base.config)
    paths = {"csv": out / "gernez2009.csv", "png": out / "gernez2009.png"}
    write_csv(paths["csv"], rows)
    _plot(rows, paths["png"], quick)
    return paths


def point_variants(points: list[Point], config) -> tuple[list[dict], list[dict]]:
    """Each point's overrides, setting every varied key (the scene's value where the point leaves
    it) so that a point's tasks are found by their overrides alone; and the distinct ones, to
    render (points of the two series share a condition when the scene's wind is a wind class)."""
    keys = sorted({k for p in points for k in p.overrides()})
    overrides = [{k: p.overrides().get(k, _scene_value(config, k)) for k in keys} for p in points]
    return overrides, [o for i, o in enumerate(overrides) if o not in overrides[:i]]


def _check_scene(config) -> None:
    """The comparison needs one band at the paper's 510 nm (its CV is of that band) and the
    conditions of :func:`check_conditions`."""
    wl = config.optics.wavelengths
    one_band = (wl.list_nm == (510.0,)) or (
        not wl.list_nm and wl.bins == 1 and wl.min_nm <= 510.0 <= wl.max_nm
    )
    if not one_band:
        raise ConfigError(
            "the Gernez 2009 comparison is of one band at 510 nm: set optics.wavelengths = [510.0]"
        )
    check_conditions(config)


def check_conditions(config) -> None:
    """Every Gernez comparison needs a stateless sea (each frame pooled is its own task) and a sky
    that can take the paper's diffuse share (uniform or a CIE sky, scaled to it)."""
    if config.water.stateful:
        raise ConfigError(
            f"water.model = {config.water.model.value!r} is stateful; the comparison pools "
            "independent frames of a wind sea: use water.model = 'fft'"
        )
    if config.sky.model is SkyModel.NONE:
        raise ConfigError(
            "the Gernez 2009 comparison needs the sky's diffuse share: set sky.model = 'uniform' or "
            "'cie_clear'"
        )


def _scene_value(config, key: str):
    section, name = key.split(".")
    value = getattr(getattr(config, section), name)
    return value.value if isinstance(value, Enum) else value


def _columns(stats: list[dict], t: float, *, overcast: bool = False, key=lambda s: s,
             weakest_sun: float = 1.0) -> dict:
    """Each frame's (mean, CV) of the map as rendered, with the sky as a uniform background (its
    directions' own caustics removed), with the sun's scattered light, lost by single
    scattering (direct transmission ``t``), back as a uniform background too, and with the sun's
    part ``weakest_sun`` times as strong (:func:`weakest_clear_sun`); ``key`` picks the
    texels' statistics or the patch's windows' (``patch_windows``: None where a frame has none).
    Under an overcast sky the map is the sky's part alone, and the two columns that remove the
    sky's own pattern have nothing left to say."""
    if any(key(s[name]) is None for s in stats for name in STAT_FIELDS):
        return None

    def frames(name: str) -> list[tuple[float, float]]:
        return [(key(s[name])["mean"], key(s[name])["cv"]) for s in stats]

    if overcast:
        return {"model_cv": frames("sky_irradiance_w_m2")}
    total, direct, sky = (frames(name) for name in STAT_FIELDS)
    sky_mean = [m for m, _ in sky]
    scattered = [m_sky + m * (1.0 / t - 1.0) for (m, _), m_sky in zip(direct, sky_mean)]
    return {"model_cv": total, "model_cv_uniform_sky": with_background(direct, sky_mean),
            "model_cv_uniform_sky_scattered": with_background(direct, scattered),
            "model_cv_weakest_clear_sun": with_beam_scaled(total, direct, sky, weakest_sun)}


STAT_FIELDS = ("irradiance_w_m2", "direct_irradiance_w_m2", "sky_irradiance_w_m2")
"""The run.json statistics the columns read."""


def _rows(points: list[Point], overrides: list[dict], fine, long, config) -> list[dict]:
    """One row per point: the measured CV beside the model's, from the scene's frames (``fine``:
    (sweep, folder)) and, with ``long`` ((sweep, folder) or None), the long waves' patch's."""
    from warpcaustics.optics.spectra import bins_for, water_optics

    bins = bins_for(config.optics)
    band = int(np.argmin(np.abs(bins.centres_nm - 510.0)))
    rows = []
    for point, o in zip(points, overrides):
        stats = frame_statistics_of(*fine, o)
        water = WaterType(o.get("optics.water_type", config.optics.water_type))
        optics = replace(config.optics, water_type=water)
        # a map that holds the scattered light already (optics.scattering = "small_angle") adds none
        t = 1.0
        if config.optics.scattering is Scattering.SINGLE:
            b = float(water_optics(optics, bins).scattering_per_m[band])
            t = direct_transmission(point.sun_zenith_deg, config.floor.depth_m, float(config.optics.ior), b)
        sea = whole_sea(stats, None if long is None else frame_statistics_of(*long, o), t,
                        overcast=point.series == "overcast",
                        weakest_sun=weakest_clear_sun(point.diffuse_fraction))
        mean = sea.pop("model_mean_w_m2")
        wind = point.wind_m_s if point.wind_m_s is not None else config.water.wind_speed_m_s
        rows.append(
            {
                "series": point.series,
                "sun_zenith_deg": point.sun_zenith_deg,
                "wind_m_s": round(wind, 4),
                "sqrt_wind": round(math.sqrt(wind), 4),
                "diffuse_fraction": round(point.diffuse_fraction, 4),
                "water_type": optics.water_type.value,
                "kd490_per_m": point.kd490_per_m,
                "measured_cv": round(point.measured_cv, 4),
                "measured_cv_sd": round(point.measured_cv_sd, 4),
                **sea,
                "model_cv_continuous_sky": continuous_sky([s["irradiance_w_m2"] for s in stats]),
                "direct_transmission": round(t, 4),
                "frames": len(stats),
                "model_mean_w_m2": mean,
            }
        )
    return rows


def whole_sea(stats: list[dict], longer: list[dict] | None, t: float, *, overcast: bool = False,
              weakest_sun: float = 1.0) -> dict:
    """The model's columns at one point from its frames' statistics (``stats``: each frame's fields
    :data:`STAT_FIELDS`) and, where rendered, the longer waves' (``longer``): each of
    :data:`CV_COLUMNS` over the whole sea (:func:`_columns` with the sun's direct transmission ``t``,
    pooled within the window and between the patch's windows, nested with the longer waves), the
    window alone, the patch, the longer waves alone, the frames' spread of the window's CV and its
    mean."""
    kw = dict(overcast=overcast, weakest_sun=weakest_sun)
    window = _columns(stats, t, **kw)
    windows = _columns(stats, t, key=lambda s: s.get("patch_windows"), **kw)
    waves = None if longer is None else _columns(longer, t, **kw)
    mean, cv_window = pooled_statistics(window["model_cv"])
    # within the window, between the windows of the whole patch, and over the longer waves' patch
    sea = {name: sea_cv(frames, None if windows is None else windows[name],
                        None if waves is None else waves[name]) for name, frames in window.items()}
    cv_long = sea["model_cv"][2]
    return {
        **{name: round(sea[name][0], 4) if name in sea else None for name in CV_COLUMNS},
        "model_cv_window": round(cv_window, 4),
        "model_cv_patch": round(math.sqrt(sea["model_cv"][1]), 4),
        "model_cv_long_waves": None if cv_long is None else round(cv_long, 4),
        "model_cv_frame_sd": round(float(np.std([c for _, c in window["model_cv"]])), 4),
        "model_mean_w_m2": mean,
    }


CV_COLUMNS = ("model_cv", "model_cv_uniform_sky", "model_cv_uniform_sky_scattered",
              "model_cv_weakest_clear_sun")
"""The model's CVs from the scene's patch and, with ``--long-waves``, the longer waves' (:func:`_columns`)."""

PLOT_NEEDS = "the comparison's plot needs"
"""How the missing-matplotlib error begins (io.files.pyplot)."""


TITLES = {"zenith": "clear sky: CV at 510 nm, 3.2 m, 8 mm collector",
          "wind": f"clear sky: CV against the wind, sun zenith {WIND_SERIES_ZENITH_DEG:g}°",
          "overcast": "overcast sky (CIE type 1): the sky's light alone",
          "water": f"clear sky: CV against Kd(490), Jerlov I-III, sun zenith {WIND_SERIES_ZENITH_DEG:g}°"}
"""Each series' panel."""

X_COLUMNS = {"wind": "sqrt_wind", "water": "kd490_per_m"}
X_LABELS = {"wind": "√(wind speed) [√(m/s)]",
            "water": "Kd(490) [1/m] (the paper's classes; the model's Jerlov types)"}
"""Each series' abscissa other than the sun's zenith."""


def _plot(rows: list[dict], path: Path, quick: bool) -> None:
    plt = pyplot(PLOT_NEEDS)
    series = [s for s in SERIES if any(r["series"] == s for r in rows)]
    fig, axes = plt.subplots(1, len(series), figsize=(5.5 * len(series), 4.2), squeeze=False)
    for ax, s in zip(axes[0], series):
        rs = [r for r in rows if r["series"] == s]
        x = [r[X_COLUMNS.get(s, "sun_zenith_deg")] for r in rs]
        ax.errorbar(x, [r["measured_cv"] for r in rs], yerr=[r["measured_cv_sd"] for r in rs], fmt="ko",
                    capsize=3, label="Gernez & Antoine 2009 (median ± sd)")
        ax.errorbar(x, [r["model_cv"] for r in rs], yerr=[r["model_cv_frame_sd"] for r in rs], fmt="s-",
                    color="tab:blue", capsize=3,
                    label="model as rendered (over the whole sea)")
        for column, style, colour, label in (
            ("model_cv_window", "s:", "tab:gray", "model, the window alone (its frames pooled)"),
            ("model_cv_uniform_sky", "v--", "tab:green", "model, sky as a uniform background"),
            ("model_cv_uniform_sky_scattered", "^:", "tab:orange", "… and the sun's scattered light too"),
            ("model_cv_continuous_sky", "D-", "tab:purple",
             "model, the sky's continuum (sky.sampling = halves)"),
        ):
            if column == "model_cv_window" and all(r[column] == r["model_cv"] for r in rs):
                continue  # the window is the model
            if all(r[column] is not None for r in rs):
                ax.plot(x, [r[column] for r in rs], style, color=colour, mfc="none", label=label)
        if s == "water":  # name each model point's Jerlov type
            for xi, r in zip(x, rs):
                ax.annotate(r["water_type"].removeprefix("jerlov_"), (xi, r["model_cv"]), fontsize=8,
                            textcoords="offset points", xytext=(4, 4))
        ax.set_xlabel(X_LABELS.get(s, "sun zenith angle [deg]"))
        ax.set_title(TITLES[s])
        ax.set_ylabel("CV of downwelling irradiance")
        ax.set_ylim(bottom=0.0)
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    if quick:
        fig.suptitle("--quick: coarse check of the command, not a comparison", color="tab:red")
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)
