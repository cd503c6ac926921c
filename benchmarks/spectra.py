"""The Elfouhaily et al. (1997) spectrum against JONSWAP: the ocean's set-up and its frames.

``python -m benchmarks.spectra`` (part of ``python -m benchmarks.run``; ``--quick``: 256²): the field
set-up's 1024² sea over 32 m (``configs/field/gernez2009.toml``'s water) built with ``water.spectrum =
"jonswap"`` (the baseline) and ``"elfouhaily"``: the time to build the ocean (the spectrum on the
grid in float64 numpy and h̃0: once per render) and one surface step (h̃(t), the inverse FFTs and the
assembly: every frame), median of ``repeats`` rounds timed in turn, one core. The step is the same
code for any spectrum; the spectrum's own cost is in the build. Also prints the slope variance each
draws on the grid.
"""

from __future__ import annotations

import itertools
import sys

import numpy as np

from benchmarks.run import ROOT, device_record


def run(quick: bool, device: str) -> dict:
    import warpcaustics as wc
    from warpcaustics.water import FFTOcean

    n = 256 if quick else 1024
    repeats = 3 if quick else 5
    from benchmarks.run import interleaved_times

    field = ROOT / "configs/field/gernez2009.toml"
    scenes = {s: wc.load_scene(field, {"water.spectrum": s, "water.resolution": n})
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
    return {"benchmark": "wave_spectra", **device_record(device), "repeats": repeats, "results": rows}


def main(argv: list[str] | None = None) -> int:
    from benchmarks.run import module_main

    return module_main(argv, "spectra", run, __doc__)


if __name__ == "__main__":
    sys.exit(main())
