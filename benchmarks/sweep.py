"""Sweep throughput: the local executor with 1 and 2 workers vs the same tasks in a plain loop.

``python -m benchmarks.sweep [--quick]``: a sweep of ocean tasks (full: 24 tasks of 256² water,
512² map, 16 bands, the default scene's size; quick: 8 tasks of 64², 64², 3 bands) run three ways
in one run:

- loop: one process renders every task after another (``Renderer`` + ``save_frame``), the
  baseline a user would write by hand;
- ``run_sweep`` with 1 worker and with 2 workers (spawned processes, manifest, atomic folders).

Prints tasks/min and the ratios; the difference between the loop and 1 worker is the executor's
per-task overhead (process start, Warp import and kernel load per worker, manifest writes).
"""

from __future__ import annotations

import argparse
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

SWEEP = """
base = "{base}"
[set]
"water.resolution" = {n}
"caustics.map_resolution" = {m}
"sun.angular_diameter_deg" = 0.0
"optics.wavelengths" = {{ min_nm = 400.0, max_nm = 700.0, bins = {k} }}
[grid]
"floor.depth_m" = {depths}
"optics.water_type" = ["pure", "clear_ocean"]
[zip]
"sun.elevation_deg" = [40.0, 80.0]
"sun.azimuth_deg" = [0.0, 45.0]
"""


def run(quick: bool, device: str = "cpu") -> dict:
    from warpcaustics.batch.sweep import load_sweep, run_sweep
    from warpcaustics.io.frame import save_frame
    from warpcaustics.io.run_json import write_run_json
    from warpcaustics.pipeline import Renderer
    from warpcaustics.scene import load_scene

    depths = [2.0, 4.0] if quick else [2.0, 4.0, 6.0, 8.0, 10.0, 12.0]
    n, m, k = (64, 64, 3) if quick else (256, 512, 16)
    tmp = Path(tempfile.mkdtemp(prefix="wc-sweep-bench-"))
    try:
        path = tmp / "sweep.toml"
        base = (ROOT / "configs" / "ocean.toml").as_posix()
        path.write_text(SWEEP.format(base=base, depths=depths, n=n, m=m, k=k))
        sweep = load_sweep(path)
        count = len(sweep.tasks)
        t0 = time.perf_counter()
        for task in sweep.tasks:  # the hand-written loop
            result = Renderer(load_scene(sweep.base, task.overrides), device).render(task.times_s[0])
            out = tmp / "loop" / task.id
            save_frame(result, out)
            write_run_json(out, [result])
        loop_s = time.perf_counter() - t0
        times = {}
        for workers in (1, 2):
            t0 = time.perf_counter()
            report = run_sweep(sweep, tmp / f"w{workers}", workers=workers, device=device, quiet=True)
            times[workers] = time.perf_counter() - t0
            assert report.done == count, report
        try:
            import ray  # noqa: F401
        except ImportError:
            ray_s = None
        else:  # a local Ray instance of 2 CPUs, started and stopped inside the timed region
            t0 = time.perf_counter()
            report = run_sweep(sweep, tmp / "ray", workers=2, device=device, quiet=True, executor="ray")
            ray_s = time.perf_counter() - t0
            assert report.done == count, report
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    row = {
        "tasks": count,
        "water_n": n,
        "map_m": m,
        "bands": k,
        "loop_s": loop_s,
        "workers_1_s": times[1],
        "workers_2_s": times[2],
        "ray_2_cpus_s": ray_s,
        "cpus": os.cpu_count(),
    }
    rate = {name: 60.0 * count / sec for name, sec in (("loop", loop_s), ("1", times[1]), ("2", times[2]))}
    print(
        f"sweep        {count} tasks ({n}² ocean, {m}² map, {k} bands) | tasks/min: "
        f"loop {rate['loop']:.1f}, 1 worker {rate['1']:.1f}, 2 workers {rate['2']:.1f} | "
        f"2 workers / loop {loop_s / times[2]:.2f}x | "
        f"1 worker - loop per task {(times[1] - loop_s) / count * 1000:+.0f} ms"
    )
    if ray_s is not None:
        print(
            f"sweep        Ray (local, 2 CPUs, start and stop included): "
            f"{60.0 * count / ray_s:.1f} tasks/min | "
            f"Ray - 2 local workers per task {(ray_s - times[2]) / count * 1000:+.0f} ms"
        )
    return row


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true")
    p.add_argument("--device", default="cpu")
    args = p.parse_args(argv)
    run(args.quick, args.device)
    return 0


if __name__ == "__main__":
    sys.exit(main())
