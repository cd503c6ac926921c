"""The radiometer's integration time as a row of the error budget (issue 27 item 2):
``python -m benchmarks.sensor_integration``.

Gernez & Antoine (2009) sampled at 6 Hz and did not publish their integration time; a sensor that
integrates over T reads the running mean of E(t) over T, and the brightest flashes are the
briefest, so integration lowers the CV. This measures by how much, on the field set-up
(``configs/field/gernez2009.toml`` before issue 27, ``BEFORE``: 3.1 cm cells, 510 nm, small-angle
scattering, a 1 m window through the 8 mm collector) on a 256² × 8 m window of that sea (the same
cells; the 32 m patch only adds longer waves, which focus below 3 m), at the paper's diffuse share
for each sun zenith: the spatial CV of the instantaneous map against that of the map averaged over
the last T = 1/6 s (the 6 Hz sampling interval, the longest an integrating sensor at 6 Hz can have)
and 1/12 s. The
average is the trapezoid rule over maps ``dt`` apart (``stats.integrate_series``'s piecewise-linear
series); ``dt`` = 1/120 s, checked against 1/240 s at 20°. Frames ``--frames`` 0.5 s apart, pooled.
``--quick``: 64² surface, one zenith, one frame, T = 1/6 s at dt = 1/24 s (keeps the script running).
``--configured`` starts from the config as it is instead of ``BEFORE``, ``--set KEY=VALUE`` changes
it further (converged cells: ``--set water.extent_m=8.0 --set water.resolution=2048``).

``--series SECONDS`` (``--configured`` and ``--set`` as above): the buoy's own statistic instead —
E(t) sampled at 6 Hz for SECONDS at 8 × 8 points of the window, its CV per point (median, 10th and
90th percentiles, and all samples pooled) beside the spatial CV of the same maps: when do the two
agree? Also the period of the strongest fluctuation (the points' mean periodogram's peak; the
paper's T_max, in the `jerlov` record) and the CV and that period left after running means of 1/3,
1/2, 1 and 2 s of the samples (what a slow sensor would read). ``--save NPZ`` keeps the samples;
``--nest A.npz B.npz`` gives the same statistics of records of independent scales multiplied at each
point (the scene's patch and the waves longer than it, as the field comparison nests them).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from benchmarks.field_budget import BEFORE  # the field set-up as these figures were measured

ROOT = Path(__file__).resolve().parents[1]


def maps_over(renderer, t_end: float, window_s: float, dt_s: float, texel: float, collector: float):
    """The collector-averaged maps at times ``t_end − window_s … t_end``, about ``dt_s`` apart."""
    steps = max(1, round(window_s / dt_s))
    times = t_end - window_s + np.arange(steps + 1) * (window_s / steps)
    return [collector_map(renderer, float(t), texel, collector) for t in times]


def trapezoid_mean(maps: list[np.ndarray]) -> np.ndarray:
    """The time mean of equally spaced maps of a piecewise-linear E(t) (trapezoid rule)."""
    weights = np.full(len(maps), 1.0)
    weights[0] = weights[-1] = 0.5
    return sum(w * m for w, m in zip(weights, maps)) / weights.sum()


def field_window(zenith: float, quick: bool, start: dict | None = None, extra: dict | None = None):
    """The renderer of the field set-up's 256² × 8 m window (``start``: the set-up, ``BEFORE`` if
    None; ``extra``: overrides on top of the window) at a sun zenith with the paper's diffuse share,
    its config, its texel and its collector [m]."""
    import warpcaustics as wc
    from warpcaustics.batch.field import diffuse_fraction

    overrides = {"water.resolution": 64 if quick else 256, "water.extent_m": 2.0 if quick else 8.0,
                 "sun.elevation_deg": 90.0 - zenith, "sky.diffuse_fraction": diffuse_fraction(zenith)}
    if quick:
        overrides.update({"caustics.map_resolution": 64, "sun.disk_samples": 2, "sky.directions": 2})
    start = BEFORE if start is None else start
    scene = wc.load_scene(ROOT / "configs/field/gernez2009.toml", {**start, **overrides, **(extra or {})})
    cfg = scene.config
    texel = (cfg.caustics.map_extent_m or cfg.water.extent_m) / cfg.caustics.map_resolution  # 0: the patch
    return wc.Renderer(scene, device="cpu"), cfg, texel, cfg.stats.collector_mm * 1e-3


def measure(zeniths, windows, dt_s: float, frames: int, quick: bool, start: dict | None = None,
            extra: dict | None = None) -> list[dict]:
    rows = []
    for zenith in zeniths:
        renderer, cfg, texel, collector = field_window(zenith, quick, start, extra)
        began = time.perf_counter()
        inst, integ = [], {w: [] for w in windows}
        for f in range(frames):
            t_end = 1.0 + 0.5 * f
            longest = max(windows)
            maps = maps_over(renderer, t_end, longest, dt_s, texel, collector)
            inst.append(maps[-1])
            per = len(maps) - 1
            for w in windows:  # shorter windows from the same maps: the last w/longest of them
                integ[w].append(trapezoid_mean(maps[per - round(per * w / longest):]))
        inst = np.array(inst)
        row = {"sun_zenith_deg": zenith, "dt_s": dt_s, "frames": frames,
               "cv_instant": float(inst.std() / inst.mean())}
        for w in windows:
            a = np.array(integ[w])
            row[f"cv_integrated_{w:.4f}s"] = float(a.std() / a.mean())
        row["seconds"] = time.perf_counter() - began
        rows.append(row)
        _print(row)
    return rows


def time_series(zenith: float, seconds: float, rate_hz: float, probes: int, quick: bool,
                start: dict | None = None, extra: dict | None = None, save: Path | None = None) -> dict:
    """The buoy's statistic beside the model's: the CV of E(t) at ``probes``² points of the window
    (the collector-averaged map sampled at ``rate_hz`` for ``seconds``; the median over points and
    the CV of all samples pooled) against the spatial CV of the same maps pooled — equal for a
    stationary, homogeneous sea once the record is long against the pattern's correlation time.
    ``start`` and ``extra``: as :func:`field_window`'s; ``save``: an .npz for the samples."""
    renderer, cfg, texel, collector = field_window(zenith, quick, start, extra)
    m = cfg.caustics.map_resolution
    at = ((np.arange(probes) + 0.5) * m / probes).astype(int)  # probes spread evenly over the window
    start = time.perf_counter()
    samples, spatial = [], []
    for k in range(max(2, round(seconds * rate_hz))):
        e = collector_map(renderer, 1.0 + k / rate_hz, texel, collector)
        samples.append(e[np.ix_(at, at)].ravel())
        spatial.append((e.mean(), e.std() / e.mean()))
    from warpcaustics.batch.field.common import pooled_statistics

    series = np.array(samples)  # (time, point)
    row = {"sun_zenith_deg": zenith, "seconds": seconds, "rate_hz": rate_hz, "points": probes**2,
           **series_statistics(series, rate_hz), "cv_spatial": float(pooled_statistics(spatial)[1])}
    row["wall_s"] = time.perf_counter() - start
    _print(row)
    if save is not None:
        np.savez(save, series=series, rate_hz=rate_hz, sun_zenith_deg=zenith, overrides=repr(extra))
    return row


def series_statistics(series: np.ndarray, rate_hz: float) -> dict:
    """The statistics of (time, point) samples: each point's CV (median, 10th and 90th percentiles,
    and all samples pooled), the period of the strongest fluctuation, and both after running means of
    1/3, 1/2, 1 and 2 s of the samples (what a slow sensor would read)."""
    per_point = series.std(axis=0) / series.mean(axis=0)
    p10, p50, p90 = np.percentile(per_point, [10, 50, 90])
    row = {"cv_time_median": float(p50), "cv_time_p10": float(p10), "cv_time_p90": float(p90),
           "cv_time_pooled": float(series.std() / series.mean()),
           "peak_period_s": peak_period(series, rate_hz)}
    # the CV left after a running mean of the 6 Hz samples over n of them (a sensor's response of
    # n/rate seconds, sampled as the buoy sampled: a coarse stand-in for a continuous average), and
    # the period of its strongest fluctuation
    for n in (2, 3, 6, 12):
        if series.shape[0] < n + 2:  # too short a record to smooth over n (--quick)
            continue
        kernel = np.ones(n) / n
        smooth = np.apply_along_axis(lambda x, k=kernel: np.convolve(x, k, mode="valid"), 0, series)
        row[f"cv_time_mean_{n / rate_hz:.3g}s"] = float(np.median(smooth.std(axis=0) / smooth.mean(axis=0)))
        row[f"peak_period_mean_{n / rate_hz:.3g}s"] = peak_period(smooth, rate_hz)
    return row


def nested_series(paths: list[Path]) -> dict:
    """The statistics of the light under seas of independent scales (the scene's patch, the waves
    longer than it: ``--long-waves``), each saved by ``--series --save``: at a point E(t) is their
    product, each over its own mean, as the field comparison nests their CVs (1 + CV² multiplies).
    The records are paired point by point (any pairing of independent points will do) and must be
    alike in rate and points; longer ones are cut to the shortest (each starts at t = 1 s, so that is
    the record a shorter run gives). Like the comparison's nesting, this takes the scales as
    independent: at a low sun the long waves' tilt also changes the short waves' contrast, which it
    leaves out."""
    records = []
    for path in paths:
        with np.load(path) as data:
            records.append((np.asarray(data["series"], np.float64), float(data["rate_hz"])))
    if len({rate for _, rate in records}) != 1 or len({series.shape[1] for series, _ in records}) != 1:
        raise SystemExit("--nest: the records differ in rate or points "
                         f"({[(series.shape, rate) for series, rate in records]}); record them alike")
    length = min(series.shape[0] for series, _ in records)
    if any(series.shape[0] != length for series, _ in records):  # every record starts at t = 1 s
        print(f"# the records cut to the shortest, {length} samples: as if all were recorded that long")
        records = [(series[:length], rate) for series, rate in records]
    if any(np.any(series.mean(axis=0) <= 0.0) for series, _ in records):
        raise SystemExit("--nest: a point of a record has no light on average")
    rate = records[0][1]
    product = np.ones_like(records[0][0])
    for series, _ in records:
        product *= series / series.mean(axis=0)
    row = {"records": " + ".join(str(p) for p in paths), "seconds": product.shape[0] / rate,
           **series_statistics(product, rate)}
    for path, (series, _) in zip(paths, records):
        row[f"cv_time_median_{Path(path).stem}"] = float(np.median(series.std(axis=0) / series.mean(axis=0)))
    _print(row)
    return row


def peak_period(series: np.ndarray, rate_hz: float) -> float:
    """The period [s] of the strongest fluctuation of (time, point) samples: the peak of the points'
    mean periodogram, each point's mean removed (Gernez & Antoine's T_max)."""
    power = np.mean(np.abs(np.fft.rfft(series - series.mean(axis=0), axis=0)) ** 2, axis=1)
    freq = np.fft.rfftfreq(series.shape[0], 1.0 / rate_hz)
    return float(1.0 / freq[1 + np.argmax(power[1:])])


def _print(row: dict) -> None:
    text = (f"{k} {v:.4g}" if isinstance(v, float) else f"{k} {v}" for k, v in row.items())
    print("  ".join(text), flush=True)


def collector_map(renderer, t: float, texel: float, collector: float) -> np.ndarray:
    from warpcaustics.batch.stats import collector_average

    return collector_average(renderer.render(float(t)).floor_irradiance[0], texel, collector, periodic=False)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a tiny surface, one zenith, one frame")
    parser.add_argument("--frames", type=int, default=2, help="frames 0.5 s apart, pooled (default 2)")
    parser.add_argument("--zeniths", default="20,50,80", help="sun zeniths [deg], comma-separated")
    parser.add_argument("--dt", type=float, default=1.0 / 120.0, help="spacing of the averaged maps [s]")
    parser.add_argument("--series", type=float, default=0.0, metavar="SECONDS",
                        help="instead: point time series at 6 Hz over SECONDS against the spatial CV")
    parser.add_argument("--configured", action="store_true",
                        help="the config as it is (not the set-up before issue 27, BEFORE)")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="a config override on top (repeatable), e.g. water.resolution=2048")
    parser.add_argument("--save", type=Path, metavar="NPZ",
                        help="with --series: keep the samples (one zenith)")
    parser.add_argument("--nest", nargs="+", type=Path, metavar="NPZ",
                        help="instead: the statistics of records saved by --save, multiplied (nested seas)")
    args = parser.parse_args(argv)
    if args.nest:
        nested_series(args.nest)
        return 0
    if args.save is not None:  # found wanting before the run, not after it
        if args.series <= 0.0 or args.quick:
            raise SystemExit("--save keeps the samples of --series (not with --quick)")
        args.save.parent.mkdir(parents=True, exist_ok=True)
    from warpcaustics.config import parse_override

    start = {} if args.configured else BEFORE
    extra = dict(parse_override(text) for text in args.set)
    if args.quick:
        measure([20.0], [1.0 / 6.0], 1.0 / 24.0, 1, True)
        time_series(20.0, 1.0, 6.0, 4, True)
        return 0
    if args.series > 0.0:
        zeniths = args.zeniths.split(",")
        if args.save is not None and len(zeniths) > 1:
            raise SystemExit("--save keeps one zenith's samples: give one in --zeniths")
        for zenith in zeniths:
            time_series(float(zenith), args.series, 6.0, 8, False, start, extra, args.save)
        return 0
    measure([float(z) for z in args.zeniths.split(",")], [1.0 / 12.0, 1.0 / 6.0], args.dt, args.frames, False,
            start, extra)
    return 0


if __name__ == "__main__":
    sys.exit(main())
