"""Field comparison: the model's irradiance fluctuations against Gernez & Antoine (2009).

Gernez, P. and Antoine, D. (2009), "Field characterization of wave-induced underwater light field
fluctuations", J. Geophys. Res. 114, C06025, measured the coefficient of variation (CV = std/mean)
of the downwelling irradiance at 510 nm, 2.7-3.7 m deep, with an 8 mm collector, at the BOUSSOLE
buoy under clear skies, against the sun's zenith angle (their Fig. 8a) and against the wind
(Fig. 8c). The measured values, and the diffuse share of the sky they print along Fig. 8a, come
from the ``jerlov`` package (``gernez2009_cv_by_sun_zenith``, ``gernez2009_cv_by``,
``gernez2009_diffuse_share``), which read them off the figures and records how.

``warpcaustics field gernez2009 SCENE --out DIR`` renders SCENE (``configs/field/gernez2009.toml``)
at each measured zenith, with the paper's diffuse share, and at each wind, as one resumable sweep
(issue 7's runner: ``--workers`` processes), then pools every point's frames and writes
``gernez2009.csv`` and ``gernez2009.png``.

The model's CV is spatial: the CV over the floor-map window after the collector, pooled over the
frames. The measurement's is temporal, at one point over minutes. The two agree for a statistically
homogeneous, stationary sea (ergodicity), which a linear random FFT sea is.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from warpcaustics.batch.field.common import (
    check_frames,
    check_overrides,
    continuous_sky,
    frame_statistics_of,
    pooled_statistics,
    render_points,
)
from warpcaustics.config import Scattering, SkyModel
from warpcaustics.errors import ConfigError
from warpcaustics.io.files import atomic_path, pyplot, write_csv

SERIES = ("zenith", "wind")

WIND_SERIES_ZENITH_DEG = 40.0
"""Sun zenith of the wind series. The paper's Fig. 8c pools all zeniths; 40° is our choice, near the
middle of the 20-85° range it reports."""

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


POINT_KEYS = ("sun.elevation_deg", "sky.diffuse_fraction", "water.wind_speed_m_s")
"""The keys each point sets (Point.overrides): a --set of one of them would be overwritten."""


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

    def overrides(self) -> dict:
        out = {"sun.elevation_deg": 90.0 - self.sun_zenith_deg, "sky.diffuse_fraction": self.diffuse_fraction}
        if self.wind_m_s is not None:
            out["water.wind_speed_m_s"] = self.wind_m_s
        return out


def diffuse_fraction(sun_zenith_deg: float) -> float:
    """The paper's diffuse share E_diffuse/E_total of the above-water irradiance (from its sky model)
    at this zenith: linear between the values printed every 10° (``jerlov.gernez2009_diffuse_share``)."""
    import jerlov

    share = jerlov.gernez2009_diffuse_share()
    return float(np.interp(sun_zenith_deg, share.sun_zenith_deg, share.diffuse_fraction))


def gernez2009_points(series: tuple[str, ...] = SERIES) -> list[Point]:
    """The measured points: CV against the sun's zenith (Fig. 8a) and against √wind (Fig. 8c)."""
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
    return points


def select_points(points: list[Point], zeniths: tuple[float, ...] | None,
                  sqrt_winds: tuple[float, ...] | None) -> list[Point]:
    """The points of the zenith series at ``zeniths`` [deg] and of the wind series at ``sqrt_winds``
    [√(m/s)] (None: all of that series); a value the record does not hold is an error naming them."""
    chosen = []
    for series, wanted, key in (("zenith", zeniths, lambda p: p.sun_zenith_deg),
                                ("wind", sqrt_winds, lambda p: math.sqrt(p.wind_m_s))):
        have = [p for p in points if p.series == series]
        if wanted is None:
            chosen += have
            continue
        for value in wanted:
            match = [p for p in have if abs(key(p) - value) < 1e-6]
            if not match:
                flag = "--zeniths" if series == "zenith" else "--sqrt-winds"
                held = ", ".join(f"{key(p):g}" for p in have) or "none (not in --series)"
                raise ConfigError(f"{flag}: {value:g} is not a measured point; the record holds {held}")
            chosen += match
    return chosen


def direct_transmission(sun_zenith_deg: float, depth_m: float, ior: float, scattering_per_m: float) -> float:
    """exp(−b·d/cos θ_w): the share of the sun's refracted beam not scattered on its way down. The
    rest, lost by single scattering, is mostly scattered forward (Petzold's mean cosines are
    0.87-0.95, docs/physics.md) and arrives spread over tens of centimetres, wider than the
    caustics: a uniform background is its limit."""
    sin_w = math.sin(math.radians(sun_zenith_deg)) / ior
    return math.exp(-scattering_per_m * depth_m / math.sqrt(1.0 - sin_w * sin_w))


def run_gernez2009(
    scene: str | Path,
    out: str | Path,
    *,
    series: tuple[str, ...] = SERIES,
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
) -> dict[str, Path]:
    """Render every point of the comparison (a resumable sweep into ``out``), pool each point's
    frames and write ``gernez2009.csv`` and ``gernez2009.png``. ``overrides``: config keys set on
    every point (``--set``: a row of the error budget); ``zeniths`` / ``sqrt_winds``: only these of
    the record's points (None: all)."""
    from warpcaustics.scene import load_scene

    unknown = set(series) - set(SERIES)
    if not series or unknown:
        raise ConfigError(f"--series {','.join(series)!r} must name some of: {', '.join(SERIES)}")
    times = check_frames(frames, frame_interval_s)
    check_overrides(overrides, POINT_KEYS, "--zeniths / --sqrt-winds")
    scene_path = Path(scene).resolve()
    fixed = {**(QUICK_OVERRIDES if quick else {}), **(overrides or {})}
    base = load_scene(scene_path, fixed)
    _check_scene(base.config)
    pyplot(PLOT_NEEDS)  # before the sweep, not after it
    points = select_points(gernez2009_points(series), zeniths, sqrt_winds)
    if not points:
        raise ConfigError("--zeniths / --sqrt-winds chose no point of the record: name at least one")
    if quick:  # the first and last zenith, the first wind
        ends = {"zenith": lambda ps: ps[:1] + ps[1:][-1:], "wind": lambda ps: ps[:1]}
        points = [p for s in series for p in ends[s]([q for q in points if q.series == s])]
    overrides, variants = point_variants(points, base.config)
    sweep = render_points(scene_path, fixed, variants, times, out, workers=workers, device=device,
                          quiet=quiet, force=force)
    rows = _rows(points, overrides, sweep, Path(out), base.config)
    out = Path(out)
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
    """The comparison needs one band at the paper's 510 nm (its CV is of that band), a sky that can
    take the paper's diffuse share (uniform or a CIE sky, scaled to it) and a stateless sea (each
    frame pooled is its own task)."""
    wl = config.optics.wavelengths
    one_band = (wl.list_nm == (510.0,)) or (
        not wl.list_nm and wl.bins == 1 and wl.min_nm <= 510.0 <= wl.max_nm
    )
    if not one_band:
        raise ConfigError(
            "the Gernez 2009 comparison is of one band at 510 nm: set optics.wavelengths = [510.0]"
        )
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
    return getattr(getattr(config, section), name)


def _rows(points: list[Point], overrides: list[dict], sweep, out: Path, config) -> list[dict]:
    from warpcaustics.optics.spectra import bins_for, water_optics

    bins = bins_for(config.optics)
    band = int(np.argmin(np.abs(bins.centres_nm - 510.0)))
    b = float(water_optics(config.optics, bins).scattering_per_m[band])
    rows = []
    for point, o in zip(points, overrides):
        whole, direct, sky = [], [], []
        for s in frame_statistics_of(sweep, out, o):
            whole.append(s["irradiance_w_m2"])
            direct.append((s["direct_irradiance_w_m2"]["mean"], s["direct_irradiance_w_m2"]["cv"]))
            sky.append(s["sky_irradiance_w_m2"]["mean"])
        total = [(w["mean"], w["cv"]) for w in whole]
        mean, cv = pooled_statistics(total)
        per_frame = [c for _, c in total]
        # the sky as a uniform background: its K directions' own caustics removed
        _, cv_uniform_sky = pooled_statistics(direct, sky)
        # and the sun's scattered light, lost by single scattering, back as a uniform background (a
        # map that holds the scattered light already, optics.scattering = "small_angle", adds none)
        t = 1.0
        if config.optics.scattering is Scattering.SINGLE:
            t = direct_transmission(point.sun_zenith_deg, config.floor.depth_m, float(config.optics.ior), b)
        scattered = [m_sky + m * (1.0 / t - 1.0) for (m, _), m_sky in zip(direct, sky)]
        _, cv_scattered = pooled_statistics(direct, scattered)
        wind = point.wind_m_s if point.wind_m_s is not None else config.water.wind_speed_m_s
        rows.append(
            {
                "series": point.series,
                "sun_zenith_deg": point.sun_zenith_deg,
                "wind_m_s": round(wind, 4),
                "sqrt_wind": round(math.sqrt(wind), 4),
                "diffuse_fraction": round(point.diffuse_fraction, 4),
                "measured_cv": round(point.measured_cv, 4),
                "measured_cv_sd": round(point.measured_cv_sd, 4),
                "model_cv": round(cv, 4),
                "model_cv_frame_sd": round(float(np.std(per_frame)), 4),
                "model_cv_uniform_sky": round(cv_uniform_sky, 4),
                "model_cv_uniform_sky_scattered": round(cv_scattered, 4),
                "model_cv_continuous_sky": continuous_sky(whole),
                "direct_transmission": round(t, 4),
                "frames": len(total),
                "model_mean_w_m2": mean,
            }
        )
    return rows


PLOT_NEEDS = "the comparison's plot needs"
"""How the missing-matplotlib error begins (io.files.pyplot)."""


def _plot(rows: list[dict], path: Path, quick: bool) -> None:
    plt = pyplot(PLOT_NEEDS)
    series = [s for s in SERIES if any(r["series"] == s for r in rows)]
    fig, axes = plt.subplots(1, len(series), figsize=(5.5 * len(series), 4.2), squeeze=False)
    for ax, s in zip(axes[0], series):
        rs = [r for r in rows if r["series"] == s]
        x = [r["sun_zenith_deg"] if s == "zenith" else r["sqrt_wind"] for r in rs]
        ax.errorbar(
            x,
            [r["measured_cv"] for r in rs],
            yerr=[r["measured_cv_sd"] for r in rs],
            fmt="ko",
            capsize=3,
            label="Gernez & Antoine 2009 (median ± sd)",
        )
        ax.errorbar(
            x,
            [r["model_cv"] for r in rs],
            yerr=[r["model_cv_frame_sd"] for r in rs],
            fmt="s-",
            color="tab:blue",
            capsize=3,
            label="model as rendered (sky over its directions)",
        )
        ax.plot(
            x,
            [r["model_cv_uniform_sky"] for r in rs],
            "v--",
            color="tab:green",
            label="model, sky as a uniform background",
        )
        ax.plot(
            x,
            [r["model_cv_uniform_sky_scattered"] for r in rs],
            "^:",
            color="tab:orange",
            label="… and the sun's scattered light too",
        )
        if all(r["model_cv_continuous_sky"] is not None for r in rs):
            ax.plot(x, [r["model_cv_continuous_sky"] for r in rs], "D-", color="tab:purple",
                    label="model, the sky's continuum (sky.sampling = halves)")
        if s == "zenith":
            ax.set_xlabel("sun zenith angle [deg]")
            ax.set_title("CV at 510 nm, 3.2 m, 8 mm collector")
        else:
            ax.set_xlabel("√(wind speed) [√(m/s)]")
            ax.set_title(f"CV against the wind, sun zenith {WIND_SERIES_ZENITH_DEG:g}°")
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
