"""The flux-ratio deposit by the footprints' edges against clipping every texel, same run:
``python -m benchmarks.deposit [--quick] [--device cpu]``.

Each surface triangle's flux is spread over its floor footprint by exact overlap with the texels.
Clipping the footprint against every texel of its box (the deposit before, kept here as
``clipped_deposit``; ``fluxratio.spread_triangle``, which the photons still use) costs its area in
texels; the deposit now accumulates the same overlaps along the footprint's edges
(``kernels/caustics/coverage.py``) at the cost of its perimeter. On the field comparisons' fine
grids the footprints are large — rays from millimetre waves cross many times above a 3.2 m sensor
— and the sky's low directions stretch them further. Rows: the field set-up's sea
(``configs/field/gernez2009.toml``: Elfouhaily, 5 m/s) on 8 m at N², refracted towards a 1 m window
of 512² texels at 3.2 m, light from several zeniths; and ``configs/ocean.toml``'s whole periodic map
(small footprints), where the edges must not cost more. Both sides start from the same refracted
hits and triangle fluxes; each is timed with its band images. A third side is the edges' deposit
without the culling of blocks whose footprints cannot reach the window (``coverage.block_reach``):
the same map to the bit (``same``). The maps' relative L1 difference to the clipped one is printed
beside (float32 geometry on both sides).
"""

from __future__ import annotations

import sys

import numpy as np
import warp as wp

from warpcaustics.kernels.caustics.fluxratio import (
    FloorMap,
    TriangleDeposit,
    carries_flux,
    footprint,
    spread_triangle,
    texels_to_bands,
)

from benchmarks.run import CONFIGS, device_record, interleaved_times

FULL = ((512, 1024, 2048), (20.0, 50.0, 80.0))
QUICK = ((256,), (20.0, 80.0))
OCEAN_FULL = (256, 512)
OCEAN_QUICK = (128,)


@wp.kernel
def clipped_deposit(hit_xy: wp.array3d[wp.vec2], flux_w_nm: wp.array4d[wp.float32],
                    wavelengths_per_group: int, extent_m: float, periodic: int, floor_map: FloorMap,
                    floor_texels: wp.array3d[wp.float32], coarse_count: wp.array[wp.int32]):
    """The deposit before the edges: each footprint clipped against every texel of its box."""
    g, iy, ix, half = wp.tid()
    m = floor_texels.shape[0]
    k_begin = g * wavelengths_per_group
    if carries_flux(flux_w_nm, iy, ix, half, k_begin, wavelengths_per_group) == 0:
        return
    dep = TriangleDeposit()
    dep.floor_texels = floor_texels
    dep.flux_w_nm = flux_w_nm
    dep.k_begin = k_begin
    dep.k_count = wavelengths_per_group
    dep.iy = iy
    dep.ix = ix
    dep.half = half
    q0, e1, e2 = footprint(hit_xy, g, iy, ix, half, extent_m, periodic, floor_map, m)
    scale = floor_map.scale
    spread_triangle(dep, q0, e1, e2, m, floor_map.wrap, floor_map.max_clipped, scale * scale, coarse_count)


def direction(zenith_deg: float, azimuth_deg: float = 30.0) -> np.ndarray:
    z, a = np.radians(zenith_deg), np.radians(azimuth_deg)
    return np.array([np.sin(z) * np.cos(a), np.sin(z) * np.sin(a), np.cos(z)])


class Pass:
    """One light direction's refracted surface and triangle fluxes, and the two deposits of it."""

    def __init__(self, scene, light_dir: np.ndarray, device: str):
        from warpcaustics.optics.refraction import height_range, refract_to_floor, sun_visibility
        from warpcaustics.pipeline import Renderer

        renderer = Renderer(scene, device)
        surface = renderer.water.at(0.0)
        _, highest = height_range(surface, device)
        visible = sun_visibility(surface, light_dir, highest, device)
        floor = renderer.method.floor
        refracted = refract_to_floor(surface, visible, renderer.light.group_ior, light_dir,
                                     -scene.config.floor.depth_m, device)
        self.floor, self.surface, self.refracted, self.light_dir = floor, surface, refracted, light_dir
        self.device = device
        m, k = floor.irradiance.shape[1], floor.irradiance.shape[0]
        self.texels = wp.zeros((m, m, k), dtype=wp.float32, device=device)
        self.clipped = wp.zeros((k, m, m), dtype=wp.float32, device=device)
        self.coarse = wp.zeros(1, dtype=wp.int32, device=device)
        self.edges()  # the triangle fluxes, once

    def edges(self) -> np.ndarray:
        return self.floor.run(self.surface, self.refracted, self.light_dir)

    def clip(self) -> wp.array3d:
        floor, surface = self.floor, self.surface
        quads = floor.flux.shape[0]
        m = self.texels.shape[0]
        self.texels.zero_()
        self.coarse.zero_()
        groups = self.refracted.hit_xy.shape[0]
        wp.launch(clipped_deposit, dim=(groups, quads, quads, 2),
                  inputs=[self.refracted.hit_xy, floor.flux, floor.flux.shape[3] // groups,
                          float(surface.extent_m), int(surface.periodic),
                          floor.floor_map(float(surface.extent_m))],
                  outputs=[self.texels, self.coarse], device=self.device)
        wp.launch(texels_to_bands, dim=(m, m), inputs=[self.texels], outputs=[self.clipped],
                  device=self.device)
        return self.clipped

    def deposit_only(self) -> None:
        """The deposit and its band images without the triangle fluxes (as :meth:`clip`)."""
        self.floor.deposit(self.surface, self.refracted)

    def unculled(self) -> None:
        """:meth:`deposit_only` without the blocks' culling: every triangle's footprint looked at."""
        cells, self.floor.reach_cells = self.floor.reach_cells, 0
        try:
            self.floor.deposit(self.surface, self.refracted)
        finally:
            self.floor.reach_cells = cells


def measure(scene, label: str, zenith: float, device: str, repeats: int) -> dict:
    one = Pass(scene, direction(zenith), device)
    one.deposit_only()
    edges = one.floor.irradiance.numpy().astype(np.float64)
    clipped = one.clip().numpy().astype(np.float64)
    l1 = float(np.abs(edges - clipped).sum() / max(np.abs(clipped).sum(), 1e-300))
    one.unculled()
    same = bool(np.array_equal(one.floor.irradiance.numpy(), edges.astype(np.float32)))
    sides = {"edges": (one.deposit_only, 1), "unculled": (one.unculled, 1), "clipped": (one.clip, 1)}
    times = {k: float(np.median(v)) for k, v in interleaved_times(sides, repeats, device).items()}
    return {"scene": label, "water_n": scene.water_resolution, "map_m": int(edges.shape[-1]),
            "light_zenith_deg": zenith, "edges_s": times["edges"], "unculled_s": times["unculled"],
            "clipped_s": times["clipped"], "speedup": times["clipped"] / times["edges"],
            "culling_speedup": times["unculled"] / times["edges"], "culling_same": same,
            "relative_l1": l1}


def run(quick: bool, device: str) -> dict:
    import warpcaustics as wc

    sizes, zeniths = QUICK if quick else FULL
    repeats = 3
    results = []
    cases = [("field sea over 8 m, 1 m window at 3.2 m", wc.load_scene(
        CONFIGS / "field/gernez2009.toml", {"water.resolution": n, "water.extent_m": 8.0}), zenith)
        for n in sizes for zenith in zeniths]
    cases += [("ocean.toml, whole periodic map", wc.load_scene(
        CONFIGS / "ocean.toml", {"water.resolution": n, "caustics.map_resolution": 2 * n}), 30.0)
        for n in (OCEAN_QUICK if quick else OCEAN_FULL)]
    for label, scene, zenith in cases:
        row = measure(scene, label, zenith, device, repeats)
        results.append(row)
        print(f"deposit      {label:38s} N={row['water_n']:5d} M={row['map_m']:5d} | light {zenith:4.0f}° "
              f"from the zenith | clipped {row['clipped_s'] * 1e3:9.1f} ms | edges, every block "
              f"{row['unculled_s'] * 1e3:8.1f} ms | edges {row['edges_s'] * 1e3:8.1f} ms | speed-up "
              f"{row['speedup']:5.1f}x (the culling {row['culling_speedup']:4.1f}x, same: "
              f"{row['culling_same']}) | L1 {row['relative_l1']:.1e}", flush=True)
    return {"benchmark": "deposit_edges_vs_clipped", **device_record(device), "repeats": repeats,
            "timing": "median wall time of one deposit and its band images (triangle fluxes excluded), "
                      "device synchronised, the sides timed in turn; edges: with the blocks' culling",
            "results": results}


def main(argv: list[str] | None = None) -> int:
    from benchmarks.run import module_main

    return module_main(argv, "deposit", run, __doc__)


if __name__ == "__main__":
    sys.exit(main())
