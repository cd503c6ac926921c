"""Device memory of large scenes: ``python -m benchmarks.memory``.

Prints the tables of docs/benchmarks.md ("Memory of large scenes") from ``pipeline.scene_bytes``,
the estimate a render checks against the device's free memory before it allocates anything. Nothing
is allocated here, so it runs in a second on any machine.
"""

from __future__ import annotations

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

FLUX_RATIO = [(256, 512, 16), (512, 1024, 16), (1024, 2048, 16), (2048, 4096, 16), (2048, 8192, 32)]
"""(water N, map M, spectral bins K) of ocean.toml with the flux-ratio map."""

def _large(n: int, m: int) -> dict:
    return {"water.resolution": n, "caustics.map_resolution": m}


SCENES = {
    "beams": [
        ("`ocean.toml` with beams (256², 512² map, 16 bands)", "ocean.toml", {}),
        ("the same with `optics.dispersion = true`", "ocean.toml", {"optics.dispersion": True}),
        ("1024² water, 2048² map, beams", "ocean.toml", _large(1024, 2048)),
        ("2048² water, 4096² map, beams", "ocean.toml", _large(2048, 4096)),
        ("`ocean_floor.toml` with beams (rippled floor, camera 480×320)", "ocean_floor.toml", {}),
        ("`ocean_floor.toml` with `both`", "ocean_floor.toml", {"caustics.method": "both"}),
        ("`pool_pots.toml` with beams", "pool_pots.toml", {}),
        ("`two_sided.toml` with beams (a glass ball: bounced beams, camera 480×320)", "two_sided.toml", {}),
    ],
    "photons": [
        ("`ocean.toml` with photons (256², s = 4, 512² map, 16 bands)", "ocean.toml", {}),
        ("the same with `optics.dispersion = true` (16 index groups)", "ocean.toml",
         {"optics.dispersion": True}),
        ("1024² water, 2048² map, photons", "ocean.toml", _large(1024, 2048)),
        ("2048² water, 4096² map, photons", "ocean.toml", _large(2048, 4096)),
        ("`ocean_floor.toml` (rippled floor mesh 512² + margin, camera 480×320)", "ocean_floor.toml", {}),
        ("`pool_pots.toml`", "pool_pots.toml", {}),
        ("`buried_in_sand.toml`", "buried_in_sand.toml", {}),
        ("`two_sided.toml` (a glass ball, 2 bounces)", "two_sided.toml", {}),
        ("`above_water.toml` with photons (the camera above, shafts from slices)", "above_water.toml", {}),
    ],
}
"""Per caustic method: (row label, config, overrides); ``caustics.method`` is set to the method
unless the overrides name another."""


def human(n_bytes: int) -> str:
    mib = n_bytes / 2**20
    return f"{mib / 1024:.1f} GiB" if mib >= 1024 else f"{mib:.0f} MiB"


def run() -> dict:
    import warpcaustics as wc
    from warpcaustics.pipeline import scene_bytes

    record: dict = {"benchmark": "memory", "flux_ratio": [], "beams": [], "photons": []}
    print("| water N | map M | K | device memory |\n|---|---|---|---|")
    for n, m, k in FLUX_RATIO:
        bins = {"min_nm": 400.0, "max_nm": 700.0, "bins": k}
        scene = wc.load_scene(ROOT / "configs" / "ocean.toml", {**_large(n, m), "optics.wavelengths": bins})
        b = scene_bytes(scene)
        record["flux_ratio"].append({"water_n": n, "map_m": m, "bins": k, "bytes": b})
        print(f"| {n} | {m} | {k} | {human(b)} |")
    for method, rows in SCENES.items():
        print(f"\n{method}:\n\n| scene | device memory |\n|---|---|")
        for label, config, overrides in rows:
            scene = wc.load_scene(ROOT / "configs" / config, {"caustics.method": method, **overrides})
            b = scene_bytes(scene)
            record[method].append({"scene": label, "config": config, "overrides": overrides, "bytes": b})
            print(f"| {label} | {human(b)} |")
    return record


def main() -> int:
    run()
    return 0


if __name__ == "__main__":
    sys.exit(main())
