"""What every field comparison shares: its points rendered as one resumable sweep (issue 7's
runner, ``--workers`` processes), the frames of a point found again by its overrides, and the
statistics pooled over them."""

from __future__ import annotations

import functools
import json
import math
import numbers
from pathlib import Path

import numpy as np

from warpcaustics.batch.arguments import overrides_argument, path_argument, workers_argument
from warpcaustics.batch.stats import continuous_sky_cv
from warpcaustics.config.loading import dotted_keys
from warpcaustics.errors import ConfigError, WarpcausticsError


def checked_arguments(run):
    """A field data set's function with the arguments they all take checked first, each a one-line
    error naming it (from Python a wrong type had surfaced from pathlib, or only after every variant
    had loaded): SCENE and ``out`` (paths), ``overrides`` (a dict of dotted keys), ``workers``."""
    name = run.__name__

    @functools.wraps(run)
    def checked(scene, out, **kwargs):
        scene = path_argument(name, "scene", scene, "a scene's .toml file")
        out = path_argument(name, "out", out, "the output folder")
        if "overrides" in kwargs:
            kwargs["overrides"] = overrides_argument(name, kwargs["overrides"])
        if "workers" in kwargs:
            kwargs["workers"] = workers_argument(kwargs["workers"])
        return run(scene, out, **kwargs)

    return checked


def _is_number(value, kind: type = numbers.Real) -> bool:
    """Whether ``value`` is a number of ``kind`` (numpy's included), not a bool."""
    return isinstance(value, kind) and not isinstance(value, (bool, np.bool_))


def numbers_of(flag: str, values) -> tuple[float, ...] | None:
    """``values`` (a flag's numbers from Python: a list or tuple; None for all) as floats, or a
    one-line error naming ``flag`` (a bare number or a string had raised TypeError deep inside)."""
    if values is None:
        return None
    if isinstance(values, (str, bytes)) or not hasattr(values, "__iter__"):
        raise ConfigError(f"{flag} = {values!r} must be a list of numbers, e.g. (20.0, 40.0)")
    values = tuple(values)
    if not all(_is_number(v) for v in values):
        raise ConfigError(f"{flag} = {values!r} must be a list of numbers, e.g. (20.0, 40.0)")
    return tuple(float(v) for v in values)


def check_frames(frames: int, frame_interval_s: float) -> tuple[float, ...]:
    """The frame times ``i · frame_interval_s``, i < ``frames``, once both flags are sane."""
    if not _is_number(frames, numbers.Integral):
        raise ConfigError(f"--frames = {frames!r} must be a whole number of frames, e.g. 3")
    if not _is_number(frame_interval_s):
        raise ConfigError(f"--frame-interval = {frame_interval_s!r} must be a number of seconds, e.g. 2")
    frames, frame_interval_s = int(frames), float(frame_interval_s)
    if frames < 1:
        raise ConfigError(f"--frames = {frames} must be at least 1")
    from warpcaustics.batch.sweep import MAX_SWEEP_FRAMES

    if frames > MAX_SWEEP_FRAMES:
        raise ConfigError(f"--frames = {frames} is more than {MAX_SWEEP_FRAMES} frames a point; render fewer "
                          "(frames further apart than the waves' periods are independent)")
    if not (math.isfinite(frame_interval_s) and frame_interval_s > 0):
        raise ConfigError(f"--frame-interval = {frame_interval_s} must be a positive number of seconds, "
                          "e.g. 2 (frames further apart than the waves' periods are independent)")
    from warpcaustics.pipeline import check_time

    check_time("--frame-interval × (--frames − 1)", (frames - 1) * frame_interval_s)
    return tuple(i * frame_interval_s for i in range(frames))


def check_overrides(overrides: dict | None, point_keys: tuple[str, ...], choose: str) -> None:
    """A ``--set`` of a key the comparison sets at each point, or of a key inside one (``--set
    optics.wavelengths.bins=4`` where the comparison sets ``optics.wavelengths``), would be
    overwritten or clash with it: say so."""
    given = dotted_keys(overrides or {})
    varied = sorted(k for k in given if any(k == p or k.startswith(p + ".") for p in point_keys))
    if varied:
        raise ConfigError(f"--set {varied[0]}: the comparison sets it at each point; choose the points "
                          f"with {choose} instead")


def render_points(scene_path: Path, fixed: dict, variants: list[dict], times: tuple[float, ...],
                  out: str | Path, *, workers: int, device: str | None, quiet: bool, force: bool,
                  chosen_by: tuple[str, str] | None = None):
    """Render every variant (a dict of overrides on top of ``fixed``) at ``times`` as one sweep
    into ``out``; returns the sweep. A variant the scene cannot take fails before anything renders
    (naming the flag, where ``chosen_by`` = (config key, the command's flag that chose its values)
    says which); failed tasks raise after the rest have run (rerun the same command to finish them)."""
    from warpcaustics.batch.sweep import expand_sweep, format_report, run_sweep

    zipped = {k: [o[k] for o in variants] for k in variants[0]}
    sweep = expand_sweep(scene_path, fixed, {}, zipped, times, scene_path)
    bad = next((t for t in sweep.tasks if t.error is not None), None)
    if bad is not None:
        key, flag = chosen_by or (None, None)
        if key in bad.overrides and bad.error.startswith(f"{key} "):  # the flag's own value is refused
            raise ConfigError(f"{flag} {bad.overrides[key]:g}: the scene cannot take it ({bad.error})")
        raise ConfigError(f"{scene_path.name} cannot take the comparison's conditions: {bad.error}")
    report = run_sweep(sweep, out, workers=workers, device=device, quiet=quiet, force=force)
    if not quiet:
        print(format_report(report))
    if report.failed:  # the first task's own error names the cause (the rest are in the manifest)
        raise WarpcausticsError(
            f"{len(report.failed)} task(s) failed, the first: {report.failed[0][1]} (all in "
            f"{Path(out) / 'manifest.jsonl'}); fix the cause and rerun the same command to finish them"
        )
    return sweep


def frame_statistics_of(sweep, out: str | Path, overrides: dict) -> list[dict]:
    """The run.json statistics of every frame whose task has these overrides."""
    found = []
    for task in sweep.tasks:
        if all(task.overrides.get(k) == v for k, v in overrides.items()):
            run = json.loads((Path(out) / task.id / "run.json").read_text())
            found += [f["statistics"] for f in run["frames"]]
    return found


def pooled_statistics(
    frames: list[tuple[float, float]], background: list[float] | None = None
) -> tuple[float, float]:
    """Mean and CV of all texels of several equal-sized frames, from each frame's (mean μᵢ, CVᵢ):
    E[E²] = mean over frames of μᵢ²(1 + CVᵢ²), so CV² = E[E²]/μ² − 1 with μ the mean of the μᵢ.
    ``background``: a uniform irradiance Bᵢ added to every texel of frame i (its mean grows by
    Bᵢ, its variance does not)."""
    if background is not None:
        frames = with_background(frames, background)
    mu = np.array([m for m, _ in frames], np.float64)
    sd = mu * np.array([c for _, c in frames], np.float64)
    mean = float(mu.mean())
    second = float(np.mean(mu**2 + sd**2))
    return mean, math.sqrt(max(second / mean**2 - 1.0, 0.0)) if mean > 0 else 0.0


def continuous_sky(stats: list[dict]) -> float | None:
    """The CV with the sky's continuum pooled over the frames' statistics of one field (None: the
    sky was not drawn in halves, ``sky.sampling``)."""
    moments = [s.get("continuous_sky") for s in stats]
    if not moments or any(m is None for m in moments):
        return None
    cv = continuous_sky_cv(moments)
    return None if cv is None else round(cv, 4)


def with_background(frames: list[tuple[float, float]], background: list[float]) -> list[tuple[float, float]]:
    """Each frame's (mean, CV) with a uniform irradiance Bᵢ added to every texel (its mean grows by
    Bᵢ, its variance does not)."""
    return [(m + b, c * m / (m + b) if m + b > 0 else 0.0) for (m, c), b in zip(frames, background)]


def with_beam_scaled(total: list[tuple[float, float]], direct: list[tuple[float, float]],
                     sky: list[tuple[float, float]], scale: float,
                     sky_scale: float = 1.0) -> list[tuple[float, float]]:
    """Each frame's (mean, CV) were its direct sun's part ``scale`` times as strong (and its sky's
    ``sky_scale`` times), from the (mean, CV) of the map (``total``) and of its two parts (total =
    direct + sky, texel by texel): the covariance of the parts is what the total's variance holds
    beyond theirs, so the scaled map's variance is a² σ_d² + s² σ_s² + 2 a s cov, exactly, without
    the maps."""
    frames = []
    for (m, c), (md, cd), (ms, cs) in zip(total, direct, sky):
        var_d, var_s = (md * cd) ** 2, (ms * cs) ** 2
        cov = 0.5 * ((m * c) ** 2 - var_d - var_s)
        mean = scale * md + sky_scale * ms
        var = scale * scale * var_d + sky_scale**2 * var_s + 2.0 * scale * sky_scale * cov
        frames.append((mean, math.sqrt(max(var, 0.0)) / mean if mean > 0 else 0.0))
    return frames


def nested_cv(*relative_variances: float) -> float:
    """The CV of a field built of nested, independent scales, each given by its relative variance
    r = CV²: 1 + CV² = Π (1 + rᵢ). For a window of a patch, the law of total variance splits the
    patch's variance into the mean within the windows, r_w Ē_w² (r_w each window's CV² about its own
    mean), and that between their means, r_b Ē²: where the large scales scale the small ones
    without changing their contrast, 1 + CV² = (1 + r_w)(1 + r_b). Longer waves that the patch cannot
    hold and that tilt and lift it as a whole add a factor of their own."""
    product = 1.0
    for r in relative_variances:
        product *= 1.0 + r
    return math.sqrt(max(product - 1.0, 0.0))


def patch_variance(window: list[tuple[float, float]], windows: list[tuple[float, float]] | None) -> float:
    """The relative variance of a periodic patch's irradiance from the frames (mean, CV) of a window
    of it and, per frame, the (mean, CV) of the means of all its windows (``patch_windows`` of the
    statistics; None: the map is the whole patch, or no such statistics, and the frames pool as they
    are): within, the mean of the frames' CV²; between, the windows' pooled CV² (:func:`nested_cv`)."""
    if not window:
        raise ValueError("patch_variance needs the window's frames")
    if windows is None:
        return pooled_statistics(window)[1] ** 2
    within = float(np.mean([c * c for _, c in window]))
    between = pooled_statistics(windows)[1] ** 2
    return nested_cv(within, between) ** 2


LONG_WAVES_OVERRIDES = {"water.resolution": 256, "caustics.map_resolution": 256}
"""The grid of a patch of the waves longer than the scene's (``--long-waves``): 256² cells (50 cm
over the Gernez comparison's 128 m, 16 or more a wave) and the floor map of the whole patch on
texels as large (measured against finer grids: docs/validation.md); ``--quick`` uses 64 cells
and texels."""

LONG_WAVES_SKY_DIRECTIONS = 16
"""The most sky directions the long waves' patch takes (the scene's, if fewer). Its 50 cm cells and
the sky's smooth light there need fewer cones than the scene's window: with 16 instead of the
Gernez config's 64 the long waves' own CV is within 0.6 % at 20°–50° and 1–3 % lower at 55°–85°,
and the whole sea's (nested) within 0.1 % up to 70° and 0.3–1.4 % lower at 75°–85°
(docs/validation.md), at a third of the patch's time."""

LONG_WAVES_FOLDER = "long_waves"
"""The long waves' sweep, inside the comparison's folder."""


def long_waves_overrides(config, fixed: dict, extent_m: float, quick: bool, scene_path: Path) -> dict | None:
    """The overrides of the long waves' patch at every point: ``extent_m`` wide, without the waves of
    the scene's patch's side or shorter (which the scene holds), its floor map the whole patch (the
    window's extent and centre set aside); None for ``extent_m`` = 0. A patch no larger than the
    scene's own, or a scene the patch cannot be built from (e.g. a height field), is an error naming
    --long-waves and its way out, --long-waves 0."""
    from warpcaustics.scene import load_scene

    if not (_is_number(extent_m) and math.isfinite(extent_m) and extent_m >= 0.0):
        raise ConfigError(f"--long-waves = {extent_m!r} must be a side in metres (e.g. 128), or 0 for the "
                          "scene's waves alone")
    if extent_m == 0.0:
        return None
    if extent_m <= config.water.extent_m:
        raise ConfigError(f"--long-waves = {extent_m:g} m must exceed water.extent_m = "
                          f"{config.water.extent_m:g} m (the scene's own patch), or be 0 for its waves alone")
    grid = {"water.resolution": 64, "caustics.map_resolution": 64} if quick else {
        **LONG_WAVES_OVERRIDES, "sky.directions": min(config.sky.directions, LONG_WAVES_SKY_DIRECTIONS)}
    long = {**fixed, **grid, "water.extent_m": extent_m, "water.shortest_wave_m": config.water.extent_m,
            "caustics.map_extent_m": 0.0, "caustics.map_center_m": [0.0, 0.0]}  # the whole patch
    try:
        load_scene(scene_path, long)
    except ConfigError as exc:
        raise ConfigError(f"--long-waves = {extent_m:g} m cannot take this scene ({exc}); "
                          "give --long-waves 0 to compare the scene's own waves alone") from None
    return long


def band_statistics(sweep, out: str | Path, point: dict, wavelengths_nm) -> list[list[dict]]:
    """Per band of ``wavelengths_nm``, the statistics of every frame rendered at ``point``."""
    stats = frame_statistics_of(sweep, out, point)
    return [[s["bands"][f"{nm:g}nm_w_m2_nm"] for s in stats] for nm in wavelengths_nm]


def sea_cv(window: list[tuple[float, float]], windows: list[tuple[float, float]] | None,
           longer: list[tuple[float, float]] | None) -> tuple[float, float, float | None]:
    """One field's CV over the whole sea from its frames' (mean, CV): of the ``window``, of the
    means of the patch's ``windows`` (None: none, :func:`patch_variance`) and of the ``longer``
    waves' patch (None: not rendered), nested (:func:`nested_cv`). Returns (that CV, the scene's
    patch's relative variance, the longer waves' own CV or None)."""
    patch = patch_variance(window, windows)
    if longer is None:
        return math.sqrt(patch), patch, None
    cv_long = pooled_statistics(longer)[1]
    return nested_cv(patch, cv_long**2), patch, cv_long


def band_row(band: list[dict], measured: float | None, longer: list[dict] | None = None) -> dict:
    """One band's frames pooled, beside the measured CV (None: not measured there): the columns every
    Darecki row shares. The model's CV is the whole patch's (within the window and between the
    patch's windows, :func:`~warpcaustics.batch.field.common.patch_variance`) where every frame has
    ``patch_windows``, nested with that of the waves longer than the patch (``longer``: their
    frames' statistics, or None); ``model_cv_window`` is the window's frames pooled alone,
    ``model_cv_patch`` the scene's patch and ``model_cv_long_waves`` the long waves' alone."""
    window = [(b["mean"], b["cv"]) for b in band]
    windows = [(b["patch_windows"]["mean"], b["patch_windows"]["cv"]) for b in band if "patch_windows" in b]
    _, cv_window = pooled_statistics(window)
    cv, patch, cv_long = sea_cv(window, windows if len(windows) == len(band) else None,
                                None if longer is None else [(b["mean"], b["cv"]) for b in longer])
    return {
        "model_cv": round(cv, 4),
        "model_cv_window": round(cv_window, 4),
        "model_cv_patch": round(math.sqrt(patch), 4),
        "model_cv_long_waves": None if cv_long is None else round(cv_long, 4),
        "model_cv_frame_sd": round(float(np.std([b["cv"] for b in band])), 4),
        "model_over_measured": None if measured is None else round(cv / measured, 3),
        "model_cv_continuous_sky": continuous_sky(band),
        "frames": len(band),
    }


def select_measured(have_values: np.ndarray, wanted: tuple[float, ...] | None, flag: str,
                    what: str, *, unmeasured: bool = False) -> list[float]:
    """The record's values (depths, winds) at ``wanted`` (None: all); one the record lacks is an
    error naming ``flag``, unless ``unmeasured``: then ``wanted`` as asked, in increasing order
    (positive; a duplicate once)."""
    have = [float(d) for d in have_values]
    wanted = numbers_of(flag, wanted)
    if wanted is None:
        return have
    if unmeasured:
        bad = [d for d in wanted if not (math.isfinite(d) and d > 0.0)]
        if bad:
            raise ConfigError(f"{flag}: {bad[0]:g} must be a {what} above 0, e.g. {flag} 0.5,1,2")
        return sorted(set(float(d) for d in wanted))
    for d in wanted:
        if not any(abs(d - h) < 1e-6 for h in have):
            raise ConfigError(f"{flag}: {d:g} is not a measured {what}; the record holds "
                              + ", ".join(f"{h:g}" for h in have))
    return [h for h in have if any(abs(d - h) < 1e-6 for d in wanted)]
