"""The Elfouhaily et al. (1997) spectrum against JONSWAP: the ocean's set-up and its frames.

``python -m benchmarks.spectra`` (part of ``python -m benchmarks.run``; ``--quick``: 256²): the field
set-up's 1024² sea over 32 m (``configs/field/gernez2009.toml``'s water on the grid it had until
2026-12-05, pinned here) built with ``water.spectrum =
"jonswap"`` (the baseline) and ``"elfouhaily"``: the time to build the ocean (the spectrum on the
grid in float64 numpy and h̃0: once per render) and one surface step (h̃(t), the inverse FFTs and the
assembly: every frame), median of ``repeats`` rounds timed in turn, one core. The step is the same
code for any spectrum; the spectrum's own cost is in the build. Also prints the slope variance each
draws on the grid, and two tables of docs/validation.md (issue 27 item 1), computed from the spectra
alone: Elfouhaily's mean square slope of a fully developed sea against Cox & Munk (1954)'s
clean-surface fits at six winds, and the slope variance each spectrum puts on the field set-up's
1024² grid as its cells shrink (the grid's k-box summed, Σ k² P Δk²), and what the same cells
would hold as a window of an unbounded ocean (all waves down to the cell's Nyquist): does it converge?
And where each spectrum puts its slope: by band of wavelengths, with its share along the wind.
"""

from __future__ import annotations

import itertools
import sys

import numpy as np

from benchmarks.run import ROOT, device_record

COX_MUNK_WINDS = (1.0, 3.0, 5.0, 7.0, 10.0, 14.0)
CELLS_CM = (3.125, 1.5625, 0.78125, 0.390625)


def cox_munk_table() -> list[dict]:
    """Elfouhaily's slope variances of a fully developed sea (∫B d ln k; up- and cross-wind with the
    spreading, ∫B (½ ± Δ/4) d ln k) beside Cox & Munk (1954)'s clean-surface fits at W, the wind at
    12.5 m (as tests/test_elfouhaily.py)."""
    from warpcaustics.water import elfouhaily as elf

    k = np.logspace(-5, 5, 400001)
    ln_k, rows = np.log(k), []
    for u10 in COX_MUNK_WINDS:
        bl, bh, delta = elf.curvature_spectra(k, u10, 1e12)
        b = bl + bh
        k0 = elf.GRAVITY_M_S2 / u10**2 * 0.84**2
        ustar = elf.friction_velocity(u10, u10 / float(elf.phase_speed(np.array(k0))))
        z0 = 10.0 / np.exp(elf.KARMAN * u10 / ustar)
        w = u10 * np.log(12.5 / z0) / np.log(10.0 / z0)
        rows.append({"u10": u10, "w12_5": float(w), "mss": float(np.trapezoid(b, ln_k)),
                     "up": float(np.trapezoid(b * (0.5 + delta / 4.0), ln_k)),
                     "cross": float(np.trapezoid(b * (0.5 - delta / 4.0), ln_k)),
                     "cm_mss": 0.003 + 5.12e-3 * w, "cm_up": 3.16e-3 * w, "cm_cross": 0.003 + 1.92e-3 * w})
    return rows


def resolution_table(n: int) -> list[dict]:
    """The slope variance the field set-up's n² grid holds as its extent shrinks (cells 3.1 cm down
    to 3.9 mm at n = 1024), for each spectrum: Σ k² P(k) Δk² over the grid's wavenumbers."""
    import warpcaustics as wc
    from warpcaustics.water import ocean_spectrum
    from warpcaustics.water.ocean import wavenumbers

    field = ROOT / "configs/field/gernez2009.toml"
    rows = []
    for cell_cm in CELLS_CM:
        extent = cell_cm / 100.0 * 1024
        row = {"cell_cm": cell_cm * 1024 / n, "extent_m": extent}
        for spectrum in ("jonswap", "elfouhaily"):
            cfg = wc.load_scene(field, {"water.spectrum": spectrum, "water.extent_m": extent,
                                        "water.resolution": 1024}).config
            k = wavenumbers(n, extent)
            kx, ky = np.meshgrid(k, k)
            dk = 2.0 * np.pi / extent
            row[spectrum] = float(np.sum((kx**2 + ky**2) * ocean_spectrum(cfg, kx, ky)) * dk * dk)
            row[f"{spectrum}_window"] = window_slope_variance(cfg, np.pi * n / extent)
        rows.append(row)
    # the limit: waves down to 1 mm (k = 2π/1 mm), far into the capillary range
    row = {"cell_cm": 0.05, "extent_m": None, "jonswap": None, "elfouhaily": None}
    for spectrum in ("jonswap", "elfouhaily"):
        cfg = wc.load_scene(field, {"water.spectrum": spectrum}).config
        row[f"{spectrum}_window"] = window_slope_variance(cfg, 2.0 * np.pi / 1e-3)
    return rows + [row]


def window_slope_variance(cfg, k_max: float) -> float:
    """The slope variance of the whole ocean's waves down to k_max [rad/m] (∫∫ k² P k dφ dk on a
    polar grid from 10⁻³ rad/m): what a window of cells π/k_max cut from a larger ocean holds."""
    from warpcaustics.water import ocean_spectrum

    k = np.logspace(-3.0, np.log10(k_max), 3000)
    phi = np.linspace(-np.pi, np.pi, 721)[:-1]
    kk, pp = np.meshgrid(k, phi)
    p = ocean_spectrum(cfg, kk * np.cos(pp), kk * np.sin(pp))
    per_ln_k = np.sum(kk**4 * p, axis=0) * (phi[1] - phi[0])
    return float(np.trapezoid(per_ln_k, np.log(k)))


BANDS_M = ((0.0625, 0.2), (0.2, 1.0), (1.0, 5.0), (5.0, 32.0))
BAND_WINDS = (1.44, 5.0, 12.96)


def band_table() -> list[dict]:
    """Where each spectrum puts its slope (the field set-up, 20 km fetch): the slope variance of the
    waves in each band of wavelengths (``BANDS_M``, the grid's 6 cm to its 32 m) and the share of it
    along the wind (1/2 for an isotropic sea, 1 for long-crested waves), at three of the field
    comparison's winds."""
    import warpcaustics as wc
    from warpcaustics.water import ocean_spectrum

    field = ROOT / "configs/field/gernez2009.toml"
    phi = np.linspace(-np.pi, np.pi, 721)[:-1]
    rows = []
    for wind in BAND_WINDS:
        for spectrum in ("jonswap", "elfouhaily"):
            cfg = wc.load_scene(field, {"water.spectrum": spectrum, "water.wind_speed_m_s": wind}).config
            row = {"wind_m_s": wind, "spectrum": spectrum}
            for shortest, longest in BANDS_M:
                k = np.geomspace(2.0 * np.pi / longest, 2.0 * np.pi / shortest, 2000)
                kk, pp = np.meshgrid(k, phi)
                slope = kk**4 * ocean_spectrum(cfg, kk * np.cos(pp), kk * np.sin(pp))
                total = np.trapezoid(slope.sum(axis=0), np.log(k))
                along = np.trapezoid((slope * np.cos(pp) ** 2).sum(axis=0), np.log(k))
                row[f"{shortest:g}-{longest:g}m"] = (float(total * (phi[1] - phi[0])), float(along / total))
            rows.append(row)
    return rows


def run(quick: bool, device: str) -> dict:
    import warpcaustics as wc
    from warpcaustics.water import FFTOcean

    n = 256 if quick else 1024
    repeats = 3 if quick else 5
    from benchmarks.run import interleaved_times

    field = ROOT / "configs/field/gernez2009.toml"
    scenes = {s: wc.load_scene(field, {"water.spectrum": s, "water.resolution": n, "water.extent_m": 32.0})
              for s in ("jonswap", "elfouhaily")}
    oceans = {s: FFTOcean.from_config(scene.config, device) for s, scene in scenes.items()}
    clock = itertools.count(1)
    for ocean in oceans.values():
        ocean.at(0.0)  # warm-up
    # timed in turn, round by round, so that both see the same machine (benchmarks/run.py)
    builds = interleaved_times({s: ((lambda c=scene.config: FFTOcean.from_config(c, device)), 1)
                                for s, scene in scenes.items()}, repeats, device)
    steps = interleaved_times({s: ((lambda o=o: o.at(0.1 * next(clock))), 1) for s, o in oceans.items()},
                              repeats, device)
    rows = []
    for spectrum, ocean in oceans.items():
        normals = ocean.at(0.0).normals.numpy().astype(np.float64)
        mss = float(np.mean((normals[..., 0] ** 2 + normals[..., 1] ** 2) / normals[..., 2] ** 2))
        rows.append({"spectrum": spectrum, "water_n": n, "build_s": float(np.median(builds[spectrum])),
                     "step_s": float(np.median(steps[spectrum])), "mss": mss})
    base, elf = rows
    for r in rows:
        r["build_ratio"] = r["build_s"] / base["build_s"]
        r["step_ratio"] = r["step_s"] / base["step_s"]
    print(f"spectra  N={n} | build: jonswap {base['build_s']:.3f} s, elfouhaily {elf['build_s']:.3f} s "
          f"(×{elf['build_ratio']:.2f}) | step: {base['step_s']:.3f} s, {elf['step_s']:.3f} s "
          f"(×{elf['step_ratio']:.2f}) | mss on the grid {base['mss']:.4f}, {elf['mss']:.4f}", flush=True)
    cox_munk = cox_munk_table()
    print("Elfouhaily (fully developed) vs Cox & Munk clean surface: U10 [m/s], W12.5 | mss, up, cross "
          "| Cox & Munk's fits")
    for r in cox_munk:
        print(f"  {r['u10']:4.1f} {r['w12_5']:5.2f} | {r['mss']:.4f} {r['up']:.4f} {r['cross']:.4f} | "
              f"{r['cm_mss']:.4f} {r['cm_up']:.4f} {r['cm_cross']:.4f}")
    resolution = resolution_table(n)
    print(f"slope variance (5 m/s, 20 km): cell [cm], extent of the {n}² grid [m] | jonswap, elfouhaily "
          "on the grid | the same cells as a window of an unbounded ocean")
    for r in resolution[:-1]:
        print(f"  {r['cell_cm']:6.3f} {r['extent_m']:6.2f} | {r['jonswap']:.4f} {r['elfouhaily']:.4f} | "
              f"{r['jonswap_window']:.4f} {r['elfouhaily_window']:.4f}")
    r = resolution[-1]
    print(f"  waves down to 1 mm, unbounded ocean: {r['jonswap_window']:.4f} {r['elfouhaily_window']:.4f}")
    bands = band_table()
    print("slope variance by wavelength [m] (its share along the wind), 20 km fetch: "
          + ", ".join(f"{a:g}-{b:g}" for a, b in BANDS_M))
    for r in bands:
        cells = (f"{v[0]:.4f} ({v[1]:.2f})" for v in r.values() if isinstance(v, tuple))
        print(f"  {r['wind_m_s']:5.2f} m/s {r['spectrum']:10s} " + "  ".join(cells))
    return {"benchmark": "wave_spectra", **device_record(device), "repeats": repeats, "results": rows,
            "cox_munk": cox_munk, "resolution": resolution, "bands": bands}


def main(argv: list[str] | None = None) -> int:
    from benchmarks.run import module_main

    return module_main(argv, "spectra", run, __doc__)


if __name__ == "__main__":
    sys.exit(main())
