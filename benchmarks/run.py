"""Benchmark runner: ``python -m benchmarks.run [--quick] [--device cpu] [--out FILE]``.

Prints a table and writes JSON (device, sizes, Warp version, timings, baselines measured in the
same run, peak memory). Nothing here asserts a time: the quick mode only keeps the suite alive in CI.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing as mp
import platform
import sys
import time
from importlib import metadata
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
CONFIGS = ROOT / "configs"  # paths from this file, so that nothing depends on the working directory

# (water N, floor map M, spectral bins); numpy runs only where it finishes in reasonable time.
FULL = [(256, 512, 16, True), (512, 1024, 16, True), (1024, 2048, 16, False)]
QUICK = [(128, 256, 8, True)]
# Cost vs spectral bins K: (water N, map M, bins list) full / quick.
BINS_FULL = (256, 512, [3, 8, 16, 32])
BINS_QUICK = (128, 256, [3, 8])
# Step benchmarks: (module, label, sizes N full, sizes N quick)
STEPS = [("ocean_step", "FFT ocean step, choppy (4 complex 2-D FFTs)", [64, 128, 256, 512, 1024], [64, 128]),
         ("pool_step", "shallow-water pool substep", [64, 128, 256, 512, 1024], [64, 128]),
         ("procedural_step", "procedural octave waves (GPU Gems ch. 2), heights + analytic normals",
          [64, 128, 256, 512, 1024], [64, 128])]
CUDA_STEP_SIZES = {"ocean_step": [2048], "pool_step": [2048]}
"""Sizes the full run adds on a CUDA device (issue 3: the FFT ocean to 2048² on CUDA; the pool too).
On one CPU core a 2048² ocean step takes about 2.6 s, so the CPU run stops at 1024²."""


def step_sizes(module: str, quick: bool, device: str) -> list[int]:
    """The sizes N of step benchmark ``module`` for this run."""
    (full, short), = [(f, q) for name, _, f, q in STEPS if name == module]
    if quick:
        return short
    return full + (CUDA_STEP_SIZES.get(module, []) if device.startswith("cuda") else [])


def point_sun_scene(path, overrides: dict | None = None):
    """``warpcaustics.load_scene`` with a point sun (``sun.angular_diameter_deg = 0``) unless the
    overrides set a disk: the numpy twins and the figures recorded in docs/ are a point sun's,
    while the default sun is the 0.53° disk."""
    import warpcaustics as wc

    return wc.load_scene(path, {"sun.angular_diameter_deg": 0.0, **(overrides or {})})


def device_record(device: str) -> dict:
    """The device fields every benchmark record starts with: the device asked for, its name, Warp's
    version."""
    import warp as wp

    return {"device": device, "device_name": str(wp.get_device(device).name), "warp_version": wp.__version__}


def median_time(func, repeats: int, device: str | None = None) -> float:
    """Median wall time [s] of ``repeats`` calls of ``func``; with ``device``, each call ends by
    synchronising it (Warp launches are asynchronous on CUDA)."""
    return float(np.median(interleaved_times({"func": (func, 1)}, repeats, device)["func"]))


def _in_child(func_name: str, *args, module: str = "frame"):
    """Run benchmarks.<module>.<func_name>(*args) in a fresh spawned process (own peak memory)."""
    ctx = mp.get_context("spawn")
    with ctx.Pool(1) as pool:
        return pool.apply(_call, (module, func_name, args))


def _call(module, func_name, args):
    import importlib
    import os

    os.chdir(ROOT)
    sys.path.insert(0, str(ROOT))
    from warpcaustics.device import _warp

    _warp()
    return getattr(importlib.import_module(f"benchmarks.{module}"), func_name)(*args)


def interleaved_times(sides: dict, rounds: int, device: str | None = None) -> dict[str, list[float]]:
    """Wall time [s] per call of each side, timed in turn: ``sides`` maps a name to (func, calls);
    every round times each side once (``calls`` calls, averaged), in the given order and in the
    reverse order by turns, so all sides see the same machine (a shared or virtual machine's speed
    drifts over seconds, and timing one side after the other moved ratios by up to 2x here) and
    sides given next to each other stay next to each other. With ``device``, each timing ends by
    synchronising it. Returns the ``rounds`` times of each side."""
    def timed(func, calls: int) -> float:
        t0 = time.perf_counter()
        for _ in range(calls):
            func()
        if device is not None:
            import warp as wp

            wp.synchronize_device(device)
        return (time.perf_counter() - t0) / calls

    names = list(sides)
    times: dict[str, list[float]] = {name: [] for name in names}
    for r in range(rounds):
        for name in names if r % 2 == 0 else names[::-1]:
            times[name].append(timed(*sides[name]))
    return times


def calls_per_round(warp_repeats: int, numpy_repeats: int) -> int:
    """Warp calls per round of :func:`interleaved_times`, so that the Warp side is timed about
    ``warp_repeats`` times over the ``numpy_repeats`` rounds a slow numpy twin sets."""
    return max(1, round(warp_repeats / numpy_repeats))


def measure_interleaved(module: str, n: int, device: str, repeats: int) -> dict:
    """One size of step benchmark ``module`` in this process: its Warp step and its numpy twin
    (``warp_stepper`` and ``numpy_stepper`` of benchmarks/<module>.py), each warmed up once, then
    timed in turn for ``repeats`` rounds (:func:`interleaved_times`). Medians per step [s], and the
    module's agreement check."""
    import importlib

    bench = importlib.import_module(f"benchmarks.{module}")
    warp_step, calls = bench.warp_stepper(n, device)
    numpy_step, check = bench.numpy_stepper(n, device)
    # Warm-up (module loads and first launches excluded), then the rounds.
    interleaved_times({"warp": (warp_step, 1), "numpy": (numpy_step, 1)}, 1, device)
    times = interleaved_times({"warp": (warp_step, calls), "numpy": (numpy_step, 1)}, repeats, device)
    return {"warp_step_s": float(np.median(times["warp"])), "numpy_step_s": float(np.median(times["numpy"])),
            **check()}


def _steps(module: str, sizes: list[int], device: str, repeats: int) -> list[dict]:
    rows = []
    for n in sizes:
        row = {"water_n": n, **_in_child("measure_interleaved", module, n, device, repeats, module="run")}
        row["speedup_warp_vs_numpy"] = row["numpy_step_s"] / row["warp_step_s"]
        rows.append(row)
        print(f"{module:11s}  N={n:5d} | warp[{device}] {row['warp_step_s'] * 1e3:9.3f} ms | "
              f"numpy {row['numpy_step_s'] * 1e3:9.3f} ms | ratio {row['speedup_warp_vs_numpy']:6.1f}x",
              flush=True)
    if len(rows) >= 2:
        n = np.log([r["water_n"] for r in rows])
        for key in ("warp_step_s", "numpy_step_s"):
            slope = np.polyfit(n, np.log([r[key] for r in rows]), 1)[0]
            print(f"  log-log slope of {key} vs N: {slope:.2f}")
            for r in rows:
                r[f"{key}_loglog_slope"] = float(slope)
    return rows


def _step_rows(module: str, quick: bool, device: str, repeats: int) -> list[dict]:
    """Step benchmark ``module`` at each of its sizes, Warp and numpy timed in turn in one process
    per size, with the log-log slopes and, in the full run, the plot in docs/images/."""
    title, = [t for name, t, _, _ in STEPS if name == module]
    rows = _steps(module, step_sizes(module, quick, device), device, repeats)
    if not quick:
        image = ROOT / "docs" / "images" / f"{module}_scaling_{device.replace(':', '')}.png"
        _plot_steps(rows, f"{title}, {device}", image)
    return rows


def run_steps(module: str, benchmark: str, quick: bool, device: str) -> dict:
    """The record of step benchmark ``module`` run alone (``python -m benchmarks.<module>``)."""
    rows = _step_rows(module, quick, device, 2 if quick else 5)
    return {"benchmark": benchmark, **device_record(device), "results": rows}


def _bins(n: int, m: int, bins_list: list[int], device: str, repeats: int) -> list[dict]:
    """Frame cost vs the number of spectral bins K, Warp and numpy, with a linear fit t = t0 + s·K."""
    rows = []
    for k in bins_list:
        w = _in_child("measure_warp", n, m, k, device, repeats)
        npy = _in_child("measure_numpy", n, m, k, 2)
        rows.append({"water_n": n, "map_m": m, "bins": k, "warp_stages_s": w["stages_s"],
                     "numpy_stages_s": npy["stages_s"],
                     "speedup_warp_vs_numpy": npy["stages_s"] / w["stages_s"]})
        print(f"bins         N={n:5d} M={m:5d} K={k:3d} | warp[{device}] {w['stages_s'] * 1e3:8.1f} ms | "
              f"numpy {npy['stages_s'] * 1e3:8.1f} ms | ratio {rows[-1]['speedup_warp_vs_numpy']:6.1f}x",
              flush=True)
    ks = [r["bins"] for r in rows]
    for key in ("warp_stages_s", "numpy_stages_s"):
        slope, intercept = np.polyfit(ks, [r[key] for r in rows], 1)
        print(f"  {key}: {intercept * 1e3:.1f} ms + {slope * 1e3:.2f} ms per bin")
        for r in rows:
            r[f"{key}_per_bin"] = float(slope)
            r[f"{key}_fixed"] = float(intercept)
    return rows


def _plot_steps(rows: list[dict], title: str, path: Path) -> None:
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib not installed (pip install -e '.[bench]'): no plot written")
        return
    n = [r["water_n"] for r in rows]
    fig, ax = plt.subplots(figsize=(5, 3.6), dpi=120)
    for key, label in (("warp_step_s", "Warp"), ("numpy_step_s", "numpy")):
        ax.loglog(n, [r[key] * 1e3 for r in rows], "o-",
                  label=f"{label} (slope {rows[0][f'{key}_loglog_slope']:.2f})")
    ax.set_xlabel("water resolution N (N×N)")
    ax.set_ylabel("one step [ms]")
    ax.set_title(title, fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
    fig.tight_layout()
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path)
    print(f"wrote {path}")


def _cpu_name() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown"


CHILD_MODULES = (
    "photons",        # photon splatting against its numpy twin
    "beams",          # the beam rasteriser against its numpy twins
    "sunmap",         # sun-map caustics against the flux-ratio map of the same frame
    "above_water",    # the camera above the water against the camera under it
    "photon_splats",  # photon footprint splats against texel deposits
    "bounces",        # photons and beams through a glass receiver against the same receiver opaque
    "eikonal",        # the eikonal texture at Mercier's sizes
    "sun_disk",       # the sun's disk against a point sun
    "shading",        # the crest-shading march over height blocks against the step-by-step one
    "deposit",        # the flux-ratio deposit by the footprints' edges against clipping every texel
    "multiple",       # the multiple-scattering random walk's photon rate
    "small_angle",    # the small-angle scattering mode against single scattering
    "long_waves",     # the field comparison's long waves against its scene's frame
    "field_bands",    # the Gernez comparison's six bands against its one
    "spectra",        # the Elfouhaily spectrum against JONSWAP: the ocean's build and step
    "radiance",       # a radiance sensor at every texel against the irradiance map; its sky against numpy
    "radiance_scattered",  # the caustics along the sensor's lines of sight: its planes against its frame
)
"""The benchmark modules (``benchmarks/<name>.py``) whose ``run(quick, device)`` main runs in a child
process each, in this order; their records go into the run's record under their names."""


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m benchmarks.run", description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="small sizes, one repeat (CI keeps it alive)")
    p.add_argument("--device", default="cpu", help="Warp device for the Warp side (default cpu)")
    p.add_argument("--repeats", type=int, default=None, help="timed repeats (default 5, quick 2)")
    p.add_argument("--out", type=Path, default=None, help="JSON file (default benchmarks/results/...)")
    args = p.parse_args(argv)
    cases = QUICK if args.quick else FULL
    repeats = args.repeats or (2 if args.quick else 5)

    rows = []
    for n, m, bins, with_numpy in cases:
        warp_res = _in_child("measure_warp", n, m, bins, args.device, repeats)
        numpy_res = _in_child("measure_numpy", n, m, bins, max(1, repeats // 2)) if with_numpy else None
        row = {"water_n": n, "map_m": m, "bins": bins, "warp": warp_res, "numpy": numpy_res}
        if numpy_res:
            row["speedup_warp_vs_numpy"] = numpy_res["stages_s"] / warp_res["stages_s"]
        rows.append(row)
        speed = f"{row['speedup_warp_vs_numpy']:8.1f}x" if numpy_res else "       -"
        np_time = f"{numpy_res['stages_s']:9.3f}" if numpy_res else "        -"
        print(f"ocean frame  N={n:5d} M={m:5d} K={bins:3d} | warp[{args.device}] stages "
              f"{warp_res['stages_s']:8.3f} s frame {warp_res['frame_s']:8.3f} s "
              f"peak {warp_res['peak_rss_mib']:7.0f} MiB | numpy {np_time} s | ratio {speed}",
              flush=True)

    bins_rows = _bins(*(BINS_QUICK if args.quick else BINS_FULL), args.device, repeats)

    steps = {module: _step_rows(module, args.quick, args.device, repeats) for module, _, _, _ in STEPS}

    # Each capability's benchmark against its baseline, each in a child process of its own, with the
    # wall time each takes (where a quick run's minutes go; nothing asserts it).
    children, wall_s = {}, {}
    for module in CHILD_MODULES:
        t0 = time.perf_counter()
        children[module] = _in_child("run", args.quick, args.device, module=module)
        wall_s[module] = round(time.perf_counter() - t0, 1)
        print(f"{module:12s} took {wall_s[module]:.0f} s (its child process, start to end)", flush=True)

    # The sky's cones on the sea's waves cut to a coarser grid (benchmarks/sky_surface.py), in this
    # process: it runs each case in a child of its own (a pool's worker may not start one).
    from benchmarks import sky_surface as sky_surface_bench

    sky_surface = sky_surface_bench.run(args.quick, args.device)

    # Sweep throughput (benchmarks/sweep.py) in this process: it starts its own worker pool.
    from benchmarks import sweep as sweep_bench

    sweeps = sweep_bench.run(args.quick, args.device)

    # Device memory of large scenes, from the estimate renders check (benchmarks/memory.py).
    from benchmarks import memory as memory_bench

    memory = memory_bench.run()

    record = {
        "benchmark": "ocean_frame_floor_caustics",
        "command": "python -m benchmarks.run" + (" --quick" if args.quick else "")
                   + f" --device {args.device}",
        "date": time.strftime("%Y-%m-%dT%H:%M:%S%z"),
        "machine": {"platform": platform.platform(), "processor": _cpu_name(),
                    "python": platform.python_version()},
        "versions": {d: metadata.version(d) for d in ("warp-lang", "numpy")},
        "repeats": repeats,
        "timing": "median wall time; Warp after one warm-up frame, device synchronised; the step, photon "
                  "and beam benchmarks time Warp and numpy in turn, round by round (interleaved_times)",
        "results": rows,
        "steps": steps,
        "bins": bins_rows,
        **children,
        "children_wall_s": wall_s,
        "sky_surface": sky_surface,
        "sweep": sweeps,
        "memory": memory,
    }
    save_record(record, args.out, "ocean_frame", args.quick, args.device)
    return 0


def module_main(argv: list[str] | None, name: str, run, doc: str) -> int:
    """The command line of one benchmark module (``python -m benchmarks.<name>``): ``--quick``,
    ``--device``, ``--out``; runs ``run(quick, device)`` and saves its record with the command,
    date, machine and versions."""
    p = argparse.ArgumentParser(prog=f"python -m benchmarks.{name}", description=doc.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="small sizes, fewer repeats")
    p.add_argument("--device", default="cpu", help="Warp device for the Warp side (default cpu)")
    p.add_argument("--out", type=Path, default=None, help="JSON file (default benchmarks/results/...)")
    args = p.parse_args(argv)
    record = run(args.quick, args.device)
    record.update(command=f"python -m benchmarks.{name}" + (" --quick" if args.quick else "")
                  + f" --device {args.device}", date=time.strftime("%Y-%m-%dT%H:%M:%S%z"),
                  machine={"platform": platform.platform(), "processor": _cpu_name(),
                           "python": platform.python_version()},
                  versions={d: metadata.version(d) for d in ("warp-lang", "numpy")})
    save_record(record, args.out, name, args.quick, args.device)
    return 0


def _jsonable(value):
    """numpy arrays and scalars in a record (a frame's per-band tallies) as plain lists and numbers."""
    if hasattr(value, "tolist"):
        return value.tolist()
    raise TypeError(f"{type(value).__name__} is not JSON serializable")


def save_record(record: dict, out: Path | None, name: str, quick: bool, device: str) -> Path:
    """Write a benchmark's JSON record to ``out`` or benchmarks/results/<name>[_quick]_<device>.json."""
    tag = f"{name}{'_quick' if quick else ''}_{device.replace(':', '')}"
    out = out or ROOT / "benchmarks" / "results" / f"{tag}.json"
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(record, indent=2, default=_jsonable) + "\n")
    print(f"wrote {out}")
    return out


if __name__ == "__main__":
    sys.exit(main())
