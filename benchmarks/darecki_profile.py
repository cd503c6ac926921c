"""CV(z) of downwelling irradiance under Darecki et al. (2011)'s conditions.

``python -m benchmarks.darecki_profile``.

Darecki, Stramski & Sokolski (2011), Fig. 13a (the ``jerlov`` package's
``darecki2011_irradiance_cv``): the CV of Ed at 443, 532 and 670 nm at six depths, 0.86–9.58 m,
in the Santa Barbara Channel, sun 30–33° from the zenith, wind 4.1–6.4 m/s, c(555) = 0.68 m⁻¹,
a 2.5 mm collector. The model: the field set-up (``configs/field/gernez2009.toml``: 1024² over 32 m,
JONSWAP) with the record's mid wind and sun, a bio-optical water whose chlorophyll is solved for
the record's c(555), 18 % diffuse sky (issue 32's set-up), a black sensor plane (``floor.albedo =
0``), a 0.4 m window at 1 mm texels seen through the 2.5 mm collector; for each depth the CV per
band as rendered with ``optics.scattering = "single"`` and ``"small_angle"`` (the scattered light
with its structure, its mean from the walk), pooled over ``--frames`` frames 0.5 s apart.
``--quick``: 256² over 8 m, two depths, one frame (keeps the script runnable; not the figures).
The figures are in docs/validation.md with the command that made them.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

from benchmarks.field_budget import BEFORE  # the field set-up as these figures were measured

ROOT = Path(__file__).resolve().parents[1]


def chlorophyll_for(c555: float) -> float:
    """The bio-optical water's chlorophyll [mg m⁻³] whose c(555) is ``c555`` (bisection on the
    package's own IOPs)."""
    import warpcaustics as wc
    from warpcaustics.optics.spectra import bins_for, water_optics

    def c_at(chl: float) -> float:
        cfg = wc.load_scene(None, {"optics.water_type": "bio_optical", "optics.chlorophyll_mg_m3": chl,
                                   "optics.wavelengths": [555.0]}).config
        o = water_optics(cfg.optics, bins_for(cfg.optics))
        return float(o.absorption_per_m[0] + o.scattering_per_m[0])

    lo, hi = 1e-3, 100.0
    for _ in range(60):
        mid = math.sqrt(lo * hi)
        lo, hi = (mid, hi) if c_at(mid) < c555 else (lo, mid)
    return math.sqrt(lo * hi)


def profile(quick: bool, frames: int, modes: tuple[str, ...], extra: dict | None = None,
            only_depths: list[float] | None = None) -> list[dict]:
    import jerlov

    import warpcaustics as wc
    from warpcaustics.batch.stats import collector_average

    record = jerlov.darecki2011_irradiance_cv()
    chl = chlorophyll_for(record.beam_attenuation_555)
    zenith = float(np.mean(record.sun_zenith_deg))
    base = {
        "water.wind_speed_m_s": float(np.mean(record.wind_m_s)),
        "sun.elevation_deg": 90.0 - zenith,
        "sky.diffuse_fraction": 0.18,
        "optics.water_type": "bio_optical",
        "optics.chlorophyll_mg_m3": chl,
        "optics.wavelengths": [float(w) for w in record.wavelengths_nm],
        "floor.albedo": 0.0,
        "caustics.map_extent_m": 0.4,
        "caustics.map_resolution": 400,
        "optics.mc_samples": 1,
        **(extra or {}),
    }
    depths = list(record.depth_m)
    if quick:
        base.update({"water.resolution": 256, "water.extent_m": 8.0, "caustics.map_resolution": 100})
        depths = depths[::3]
    if only_depths:
        depths = [d for d in record.depth_m if any(abs(d - o) < 1e-6 for o in only_depths)]
    texel = base["caustics.map_extent_m"] / base["caustics.map_resolution"]
    rows = []
    for d_index, depth in enumerate(record.depth_m):
        if depth not in depths:
            continue
        row = {"depth_m": float(depth), "measured": record.cv[d_index].tolist()}
        for mode in modes:
            scene = wc.load_scene(ROOT / "configs/field/gernez2009.toml",
                                  {**BEFORE, **base, "floor.depth_m": float(depth),
                                   "optics.scattering": mode})
            renderer = wc.Renderer(scene, device="cpu")
            sums = np.zeros((3, 2))
            start = time.perf_counter()
            for f in range(frames):
                r = renderer.render(0.5 * f)
                for band in range(3):
                    e = collector_average(r.floor_irradiance[band], texel, record.collector_mm * 1e-3,
                                          periodic=False)
                    sums[band] += (e.mean(), (e**2).mean())
            mean = sums[:, 0] / frames
            cv = np.sqrt(np.maximum(sums[:, 1] / frames - mean**2, 0.0)) / mean
            row[mode] = cv.tolist()
            row[f"{mode}_s"] = (time.perf_counter() - start) / frames
            print(f"{depth:5.2f} m  {mode:12s} CV {np.round(cv, 3).tolist()}  measured "
                  f"{np.round(record.cv[d_index], 3).tolist()}  ({row[f'{mode}_s']:.0f} s/frame)", flush=True)
        rows.append(row)
    return rows


def plot(rows: list[dict], path: Path) -> None:
    """CV(z) per band: the measured profile (Darecki et al. 2011, Fig. 13a, from ``jerlov``) and
    each mode's, one panel per wavelength."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    modes = list(dict.fromkeys(k for r in rows for k in r if k not in ("depth_m", "measured")
                               and not k.endswith("_s")))
    fig, axes = plt.subplots(1, 3, figsize=(11, 4), sharey=True)
    for band, (ax, nm) in enumerate(zip(axes, (443, 532, 670))):
        ax.plot([r["measured"][band] for r in rows], [r["depth_m"] for r in rows], "ko-",
                label="measured (Darecki et al. 2011)")
        for mode, style in zip(modes, ("s--", "d-", "^-", "v-")):
            have = [r for r in rows if mode in r]
            ax.plot([r[mode][band] for r in have], [r["depth_m"] for r in have], style,
                    label=f"model, {mode}")
        ax.set_xscale("log")
        ax.set_title(f"{nm} nm")
        ax.set_xlabel("CV of Ed")
    axes[0].invert_yaxis()
    axes[0].set_ylabel("depth [m]")
    axes[0].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a small surface, two depths, one frame")
    parser.add_argument("--frames", type=int, default=3, help="frames pooled per depth (default 3)")
    parser.add_argument("--modes", default="single,small_angle",
                        help="optics.scattering modes, comma-separated")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="a further config override (repeatable), e.g. optics.phase_function=petzold")
    parser.add_argument("--depths", help="only these of the record's depths [m], comma-separated")
    parser.add_argument("--out", help="write the rows to this JSON file")
    parser.add_argument("--plot", help="draw CV(z) per band to this PNG (matplotlib)")
    args = parser.parse_args(argv)
    extra = {}
    for item in args.set:
        key, _, value = item.partition("=")
        try:
            extra[key] = float(value)
        except ValueError:
            extra[key] = value
    only = [float(d) for d in args.depths.split(",")] if args.depths else None
    rows = profile(args.quick, 1 if args.quick else args.frames, tuple(args.modes.split(",")), extra, only)
    if args.out:
        record = {"overrides": extra, "frames": args.frames, "rows": rows}
        Path(args.out).write_text(json.dumps(record, indent=1))
    if args.plot:
        plot(rows, Path(args.plot))
    return 0


if __name__ == "__main__":
    sys.exit(main())
