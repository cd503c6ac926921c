"""The error budget of the field comparison (issue 27): ``python -m benchmarks.field_budget``.

Each row is ``warpcaustics field gernez2009 configs/field/gernez2009.toml`` at three of the paper's
sun zeniths (20°, 50°, 80°) and three of its wind classes (√U = 1.2, 2.4, 3.6, at a 40° sun), with
one change (``--set``) to the set-up before issue 27 (``BEFORE``: a JONSWAP sea, a uniform sky), so
that each row's change to the model's CV against the baseline's is that change's share of the gap;
the last row, ``configured``, is the config as it is now. The command each row runs is printed and
written to the CSV. Rows are resumable sweeps under ``--out`` (default ``out/field_budget``);
``--rows`` picks some. The table goes to ``benchmarks/results/field_budget.csv`` and is printed as
markdown (docs/validation.md holds the figures). No parameter here is fitted to a CV: each row is
a source's value or a resolution, named beside it.

Every row's CV is the one the budget was made with: the 1 m window's texels pooled over the frames
(the CSV's ``model_cv_window``; ``model_cv`` in a table written before 2026-12-06, when it was the
comparison's only CV), each row run with ``--long-waves 0``. The whole sea's CV (the patch's
windows and the longer waves, the comparison's ``model_cv`` since 2026-12-06) is a row of its own in
docs/validation.md, from the comparison's columns.

``--quick``: the field command's ``--quick`` (a 64² surface) on two rows, to keep the script
running; its CVs are not a budget.
"""

from __future__ import annotations

import argparse
import csv
import math
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
SCENE = ROOT / "configs/field/gernez2009.toml"
ZENITHS = (20.0, 50.0, 80.0)
SQRT_WINDS = (1.2, 2.4, 3.6)

BEFORE = {"water.spectrum": "jonswap", "sky.model": "uniform", "sky.sampling": "stratified",
          "sky.directions": 16, "optics.beam_spread": "wells", "water.extent_m": 32.0,
          "water.resolution": 1024, "water.wind_direction_deg": 0.0, "sun.disk_samples": 16}
"""The set-up the budget starts from: configs/field/gernez2009.toml as it was before issue 27 (a
JONSWAP sea, a uniform sky of 16 point directions, Wells's spread, 1024² cells over 32 m, the wind
along the sun's azimuth, 16 directions over the sun's disk); every row but the last changes one
thing on top of it."""

SKY_16_CONES = {"sky.directions": 16, "sky.surface_resolution": 0}
"""The config's sky until 2026-12-06 (late): 16 cones refracted through the whole 2048² sea, as the
figures of the benchmarks that take it (cones_attenuation, long_waves, field_bands) were measured;
the config now has 64 cones on its waves cut to 1024²."""

QUICK_LIGHT = {"optics.beam_spread_photons": 16384, "sky.directions": 4, "sun.disk_samples": 2}
"""The light of the field benchmarks' ``--quick`` (long_waves, field_bands, small_angle): four sky
directions, two of the sun's disk and walks of the beam spread a sixteenth as long. Each light
direction's walks and multipliers had taken most of their quick runs' 2–5 minutes, and the quick
mode only keeps them running."""

WINDOW_CV = "model_cv_window"
"""The column every row's CV is read from (the window alone); a table written before it existed has
the same figure in ``model_cv``."""

ROWS: dict[str, tuple[dict | None, str]] = {
    "baseline": ({}, "the set-up before issue 27: JONSWAP, uniform sky, small-angle scattering (Petzold)"),
    "single_scattering": ({"optics.scattering": "single"}, "scattered light dropped (c = a + b)"),
    "cells_1.6cm": ({"water.extent_m": 16.0}, "1024² over 16 m: 1.6 cm cells (waves > 16 m dropped)"),
    "cells_0.8cm": ({"water.extent_m": 8.0}, "1024² over 8 m: 7.8 mm cells (waves > 8 m dropped)"),
    "damped_10cm": ({"water.small_wave_m": 0.1}, "waves under ~10 cm damped (Tessendorf's l = 0.1 m)"),
    "elfouhaily": ({"water.spectrum": "elfouhaily"}, "Elfouhaily et al. 1997 spectrum and spreading"),
    "elfouhaily_0.8cm": ({"water.spectrum": "elfouhaily", "water.extent_m": 8.0},
                         "Elfouhaily et al. 1997 on 7.8 mm cells"),
    "elfouhaily_0.4cm": ({"water.spectrum": "elfouhaily", "water.extent_m": 8.0, "water.resolution": 2048},
                         "Elfouhaily et al. 1997 on 3.9 mm cells over the same 8 m (does 7.8 mm converge?)"),
    "elfouhaily_0.2cm": ({"water.spectrum": "elfouhaily", "water.extent_m": 8.0, "water.resolution": 4096},
                         "Elfouhaily et al. 1997 on 1.95 mm cells over the same 8 m (does 3.9 mm converge?)"),
    "cie_clear": ({"sky.model": "cie_clear"}, "CIE clear sky (type 12) at the paper's diffuse share"),
    "point_sun": ({"sun.angular_diameter_deg": 0.0}, "a point sun instead of the 0.53° disk"),
    "choppy": ({"water.choppiness": 1.0}, "Lagrangian (choppy) displacement, λ = 1"),
    "spreading_s2": ({"water.spreading_s": 2.0}, "broad cos-2s spreading, s = 2 (default 10)"),
    "fetch_200km": ({"water.fetch_m": 200000.0}, "fetch 200 km (near fully developed; default 20 km)"),
    "elfouhaily_cie_clear": ({"water.spectrum": "elfouhaily", "sky.model": "cie_clear"},
                             "Elfouhaily's sea and the CIE clear sky together, on 3.1 cm cells (the config "
                             "until 2026-12-05)"),
    "baseline_2026_12_06": ({}, "the baseline again, with each window's scattered light from the sea around "
                            "it (since 2026-12-05 late): the rows below compare with it"),
    "walked_spread": ({"optics.beam_spread": "walk"}, "the small-angle transfer measured by a pencil beam's "
                      "walk instead of Wells's closed form (2026-12-06)"),
    "sky_cones": ({"sky.sampling": "cones"}, "each sky direction spread over its cell of the sky: the sky's "
                  "continuum instead of 16 point directions (2026-12-06)"),
    "configured": (None, "configs/field/gernez2009.toml as it is now: Elfouhaily's sea, the CIE clear sky "
                         "in cones, the walked spread, 3.9 mm cells (2048² over 8 m)"),
}
"""name → (overrides on top of ``BEFORE``, or None: the config as it is; what it changes). The field
command sets the sun, the sky's share and the wind at each point."""

ZENITH_ONLY = {"cells_0.8cm"}
"""Rows run at the three sun zeniths only: 7.8 mm cells put 16× the triangles over the window, about
150 s of CPU a frame with the clipped deposit (the rows that ran before 2026-12-05). Since the deposit
by the footprints' edges, a frame on 3.9 mm cells (2048² over 8 m, ``elfouhaily_0.4cm``) takes about a
minute and on 1.95 mm cells (4096², ``elfouhaily_0.2cm``) 5–8 minutes, most of it the crest shading
from the sky's low directions (docs/benchmarks.md)."""


def command(name: str, out: Path, workers: int, quick: bool) -> list[str]:
    """The ``warpcaustics field`` arguments of one row."""
    args = ["field", "gernez2009", str(SCENE.relative_to(ROOT)), "--out", str(out / name),
            "--zeniths", ",".join(f"{z:g}" for z in ZENITHS)]
    if name in ZENITH_ONLY:
        args += ["--series", "zenith"]
    else:
        args += ["--sqrt-winds", ",".join(f"{w:g}" for w in SQRT_WINDS)]
    args += ["--long-waves", "0", "--workers", str(workers), "--quiet"]
    changes = ROWS[name][0]
    for key, value in ({} if changes is None else {**BEFORE, **changes}).items():
        args += ["--set", f"{key}={value!r}" if isinstance(value, str) else f"{key}={value}"]
    return args + (["--quick"] if quick else [])


def run_row(name: str, out: Path, workers: int, quick: bool) -> list[dict]:
    from warpcaustics.cli import main

    args = command(name, out, workers, quick)
    print("warpcaustics " + " ".join(args), flush=True)
    start = time.perf_counter()
    if main(args) != 0:
        raise SystemExit(f"row {name!r} failed")
    seconds = time.perf_counter() - start
    with (out / name / "gernez2009.csv").open() as fh:
        rows = list(csv.DictReader(fh))
    return [{"row": name, "seconds": round(seconds, 1), **r, "command": "warpcaustics " + " ".join(args)}
            for r in rows]


def window_cv(row: dict) -> float:
    """The row's CV of the window alone (:data:`WINDOW_CV`, or ``model_cv`` where a table predates it)."""
    return float(row.get(WINDOW_CV) or row["model_cv"])


def table(results: list[dict]) -> str:
    """Markdown: one line per row, the window's CV (:func:`window_cv`) at each point with its change
    against the baseline, and the geometric mean of its ratios to the measured medians (over the
    points it has: a row of ``ZENITH_ONLY`` shows – at the winds)."""
    points = [(r["series"], r["sun_zenith_deg"], r["sqrt_wind"]) for r in results
              if r["row"] == results[0]["row"]]
    head = [f"{z}°" if s == "zenith" else f"√U {w}" for s, z, w in points]
    lines = ["| row | " + " | ".join(head) + " | mean ratio to measured |",
             "|---|" + "---|" * (len(head) + 1)]
    measured = {p: float(r["measured_cv"]) for r in results
                for p in [(r["series"], r["sun_zenith_deg"], r["sqrt_wind"])]}
    base = {(r["series"], r["sun_zenith_deg"], r["sqrt_wind"]): window_cv(r)
            for r in results if r["row"] == "baseline"}
    for name in dict.fromkeys(r["row"] for r in results):
        cells, ratios = [], []
        for p in points:
            cv = next((window_cv(r) for r in results if r["row"] == name
                       and (r["series"], r["sun_zenith_deg"], r["sqrt_wind"]) == p), None)
            if cv is None:
                cells.append("–")
                continue
            change = f" ({cv / base[p] - 1.0:+.0%})" if p in base and name != "baseline" else ""
            cells.append(f"{cv:.3f}{change}")
            ratios.append(cv / measured[p])
        geometric = math.exp(sum(map(math.log, ratios)) / len(ratios))
        lines.append(f"| {name} | " + " | ".join(cells) + f" | {geometric:.2f} |")
    lines.append("| measured | " + " | ".join(f"{measured[p]:.3f}" for p in points) + " | 1 |")
    return "\n".join(lines)


def merged(path: Path, results: list[dict]) -> list[dict]:
    """The table at ``path`` with the rows just run put in place of their earlier results (a row not
    run keeps its figures and its command; a new row goes after the rest, in ``ROWS``' order)."""
    if not path.exists():
        return results
    with path.open() as fh:
        old = list(csv.DictReader(fh))
    ran = {r["row"] for r in results}
    names = list(dict.fromkeys([r["row"] for r in old] + [r["row"] for r in results]))
    order = {name: i for i, name in enumerate(ROWS)}
    names.sort(key=lambda name: order.get(name, len(order)))
    return [r for name in names for r in (results if name in ran else old) if r["row"] == name]


def write_table(path: Path, results: list[dict]) -> None:
    """The CSV of ``results``, its columns those of every row (a column newer than a row's run is
    left empty there)."""
    columns = list(dict.fromkeys(key for r in results for key in r))
    with path.open("w", newline="") as fh:
        writer = csv.DictWriter(fh, fieldnames=columns, restval="", lineterminator="\n")
        writer.writeheader()
        writer.writerows(results)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rows", default=",".join(ROWS), help=f"comma-separated, of: {', '.join(ROWS)}")
    parser.add_argument("--out", default=str(ROOT / "out/field_budget"), help="folder of the rows' sweeps")
    parser.add_argument("--workers", type=int, default=1, help="worker processes per row (default 1)")
    parser.add_argument("--quick", action="store_true", help="two coarse rows (checks the script)")
    parser.add_argument("--csv", default=str(ROOT / "benchmarks/results/field_budget.csv"),
                        help="where the table goes")
    args = parser.parse_args(argv)
    names = ["baseline", "choppy"] if args.quick else args.rows.split(",")
    unknown = [n for n in names if n not in ROWS]
    if unknown:
        parser.error(f"unknown row {unknown[0]!r}; rows: {', '.join(ROWS)}")
    out = Path(args.out) / ("quick" if args.quick else "")
    results = [r for name in names for r in run_row(name, out, args.workers, args.quick)]
    if not args.quick:
        write_table(Path(args.csv), merged(Path(args.csv), results))
    print(table(results) if any(r["row"] == "baseline" for r in results)
          else "\n".join(map(str, results)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
