"""Our floor maps against Mitsuba 3's particle tracer, as a user would check us (issue 30).

The same height field (``configs/ocean.toml``'s FFT ocean on a 4 m patch, a flat floor 2 m down,
no absorption, one band, n = 1.333, a point sun) rendered by Mitsuba 3's ``ptracer``: a directional
sun, the displaced surface as a dielectric triangle mesh (its periodic images around it, cropped 1 m
beyond the patch so that light entering near the edges still lands), a white diffuse floor, and a
pinhole straight above the floor's centre, under the water, whose film maps the floor one-to-one
(a plane parallel to the film; irradiance E = π L on a white Lambertian floor); ``max_depth = 3``
keeps only sun → water → floor paths (with 4 the white floor's own light, sent back down by the
surface's underside, adds ~20 %). A reference is converged once (``--reference-spp``, in passes with their own
seeds); then, for each of our methods, its relative L1 against that reference, its time (best of 3
warm renders, one CPU core), Mitsuba's time for the same L1 on its own L1-against-time curve (its
renders at increasing samples, other seeds; log-log interpolation, or extrapolated as t ∝ L1⁻²
past its last point, and said so), and the ratio. Photons per texel are printed beside every L1.

Mitsuba is an optional extra (``pip install -e '.[compare]'``); its LLVM variants need libLLVM
(e.g. Debian's ``libllvm19``), else the ``scalar_mono`` variant runs, slower. Without Mitsuba the
benchmark says so in one line and exits 0. ``python -m benchmarks.vs_mitsuba --help``.
"""

from __future__ import annotations

import argparse
import math
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from benchmarks.run import ROOT, point_sun_scene

CASES = {"overhead sun": (90.0, 0.0), "sun 60° high, azimuth 20°": (60.0, 20.0)}
EXTENT_M, DEPTH_M = 4.0, 2.0
OURS = [("fluxratio", {"caustics.method": "fluxratio"}),
        ("beams", {"caustics.method": "beams"}),
        ("photons 4×4, footprint (default)", {"caustics.method": "photons"}),
        ("photons 4×4, texel", {"caustics.method": "photons", "caustics.photon_splat": "texel"}),
        ("photons 8×8, footprint", {"caustics.method": "photons", "caustics.photon_subdivisions": 8}),
        ("photons 16×16, texel", {"caustics.method": "photons", "caustics.photon_splat": "texel",
                                  "caustics.photon_subdivisions": 16})]
CURVE_SPP = (16, 64, 256, 1024, 4096)


def our_scene(n: int, m: int, elevation: float, azimuth: float, overrides: dict):
    return point_sun_scene(ROOT / "configs" / "ocean.toml", {
        "water.extent_m": EXTENT_M, "water.resolution": n, "caustics.map_resolution": m,
        "floor.depth_m": DEPTH_M, "optics.water_type": "none", "optics.ior": 1.333,
        "optics.wavelengths": {"min_nm": 550.0, "max_nm": 560.0, "bins": 1},
        "sun.elevation_deg": elevation, "sun.azimuth_deg": azimuth, **overrides})


def surface_ply(mi, positions: np.ndarray, path: Path, margin_m: float = 2.0) -> None:
    """The periodic surface (N, N, 3) as a triangle mesh with its images, cropped ``margin_m``
    beyond the patch, written as PLY (normals up: the dielectric's inside is below). Light that
passes beyond the crop falls unrefracted, so the margin must exceed depth × tan(zenith) in the air
(1.15 m for a 60° sun 2 m down; a 1 m margin let 2.6 % too much light onto the patch's edge)."""
    n = positions.shape[0]
    side = n + 1
    idx = np.arange(side) % n
    grid = positions[idx][:, idx].astype(np.float64)
    grid[:, n, 0] += EXTENT_M
    grid[n, :, 1] += EXTENT_M
    j, i = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    a = (j * side + i).ravel()
    cells = np.stack([a, a + 1, a + side + 1, a, a + side + 1, a + side], axis=1).reshape(-1, 3)
    points, faces = [], []
    for ky in (-1, 0, 1):
        for kx in (-1, 0, 1):
            p = grid.reshape(-1, 3) + np.array([kx * EXTENT_M, ky * EXTENT_M, 0.0])
            keep = np.all(np.abs(p[cells][..., :2]) <= 0.5 * EXTENT_M + margin_m, axis=(1, 2))
            faces.append(cells[keep] + sum(len(q) for q in points))
            points.append(p)
    v, f = np.concatenate(points), np.concatenate(faces)
    mesh = mi.Mesh("water", vertex_count=len(v), face_count=len(f), has_vertex_normals=False)
    params = mi.traverse(mesh)
    params["vertex_positions"] = mi.Float(v.astype(np.float32).ravel())
    params["faces"] = mi.UInt(f.astype(np.uint32).ravel())
    params.update()
    mesh.write_ply(str(path))


def mitsuba_scene(mi, ply: Path, sun: np.ndarray, m: int, spp: int, seed: int):
    height = 0.5  # the pinhole above the floor, under the lowest trough
    fov = 2.0 * math.degrees(math.atan(0.5 * EXTENT_M / height))
    return mi.load_dict({
        "type": "scene",
        "integrator": {"type": "ptracer", "max_depth": 3, "hide_emitters": True},
        "sun": {"type": "directional", "direction": (-sun).tolist(),
                "irradiance": {"type": "spectrum", "value": 1.0}},
        "water": {"type": "ply", "filename": str(ply),
                  "bsdf": {"type": "dielectric", "int_ior": 1.333, "ext_ior": 1.0}},
        "floor": {"type": "rectangle",
                  "bsdf": {"type": "diffuse", "reflectance": {"type": "spectrum", "value": 1.0}},
                  "to_world": mi.ScalarTransform4f().translate([0.0, 0.0, -DEPTH_M]).scale(
                      [0.5 * EXTENT_M + 1.0, 0.5 * EXTENT_M + 1.0, 1.0])},
        "sensor": {"type": "perspective", "fov": fov, "fov_axis": "x",
                   "to_world": mi.ScalarTransform4f().look_at(
                       origin=[0.0, 0.0, -DEPTH_M + height], target=[0.0, 0.0, -DEPTH_M], up=[0.0, 1.0, 0.0]),
                   "film": {"type": "hdrfilm", "width": m, "height": m, "rfilter": {"type": "box"},
                            "pixel_format": "luminance"},
                   "sampler": {"type": "independent", "sample_count": spp, "seed": seed}},
    })


def mitsuba_map(mi, scene) -> tuple[np.ndarray, float]:
    """(M, M) floor irradiance per unit solar irradiance, rows along +y as our maps; seconds."""
    t0 = time.perf_counter()
    image = np.array(mi.render(scene), dtype=np.float64).reshape(scene.sensors()[0].film().size()[::-1])
    return math.pi * image[::-1], time.perf_counter() - t0  # the film's top row is +y


def equal_error_time(curve: list[tuple[float, float]], l1: float) -> tuple[float, bool]:
    """Mitsuba's time for ``l1`` on its (time, L1) curve: log-log interpolation, or extrapolated as
    t ∝ L1⁻² beyond it (True)."""
    times = np.log([t for t, _ in curve])
    errors = np.log([e for _, e in curve])
    order = np.argsort(errors)
    if errors.min() <= math.log(l1) <= errors.max():
        return float(np.exp(np.interp(math.log(l1), errors[order], times[order]))), False
    t, e = curve[-1] if l1 < min(e for _, e in curve) else curve[0]
    return t * (e / l1) ** 2, True


def run_case(mi, name: str, elevation: float, azimuth: float, n: int, m: int, reference_spp: int,
             passes: int) -> list[dict]:
    import warpcaustics as wc
    from warpcaustics.reference import relative_l1

    base = our_scene(n, m, elevation, azimuth, {})
    surface = wc.Renderer(base, "cpu").render(0.0).surface_positions
    sun = base.sun_direction
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        ply = Path(tmp) / "water.ply"
        surface_ply(mi, surface, ply)
        reference = np.zeros((m, m))
        ref_s = 0.0
        for k in range(passes):
            image, seconds = mitsuba_map(mi, mitsuba_scene(mi, ply, sun, m, reference_spp, seed=1000 + k))
            reference += image / passes
            ref_s += seconds
        curve = []
        for spp in CURVE_SPP:
            image, seconds = mitsuba_map(mi, mitsuba_scene(mi, ply, sun, m, spp, seed=spp))
            curve.append((seconds, relative_l1(image, reference)))
            print(f"vs mitsuba   {name}: Mitsuba {spp:6d} spp {seconds:8.2f} s  L1 {curve[-1][1]:.4f}",
                  flush=True)
    print(f"vs mitsuba   {name}: reference {passes} × {reference_spp} spp in {ref_s:.0f} s, mean "
          f"{reference.mean():.4f} (flat water: {math.sin(math.radians(elevation)):.4f} × T)", flush=True)
    for label, overrides in OURS:
        scene = our_scene(n, m, elevation, azimuth, overrides)
        renderer = wc.Renderer(scene, "cpu")
        renderer.render(0.0)
        best, result = math.inf, None
        for _ in range(3):
            t0 = time.perf_counter()
            result = renderer.render(0.0)
            best = min(best, time.perf_counter() - t0)
        ours = result.floor_irradiance[0].astype(np.float64) / float(result.sun_irradiance[0])
        l1 = relative_l1(ours, reference)
        mitsuba_s, extrapolated = equal_error_time(curve, l1)
        s = scene.config.caustics.photon_subdivisions
        per_texel = (n * s) ** 2 / m**2 if "photons" in label else None
        rows.append({"case": name, "method": label, "photons_per_texel": per_texel, "l1": l1,
                     "ours_s": best,
                     "mitsuba_s_at_equal_l1": mitsuba_s, "extrapolated": extrapolated,
                     "ratio": mitsuba_s / best, "mean_ratio": float(ours.mean() / reference.mean())})
        r = rows[-1]
        texels = f"{per_texel:6.0f} photons/texel" if per_texel else " " * 20
        print(f"vs mitsuba   {name}: {label:34s} {texels} L1 {l1 * 100:6.2f} %  ours {best:7.3f} s  Mitsuba "
              f"{mitsuba_s:9.1f} s{' (extrapolated)' if extrapolated else ''}  ratio {r['ratio']:9.0f}x  "
              f"mean ours/Mitsuba {r['mean_ratio']:.4f}", flush=True)
    return rows


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m benchmarks.vs_mitsuba",
                                description=__doc__.splitlines()[0])
    p.add_argument("--quick", action="store_true", help="64² heights and map, a 2 × 4096 spp reference")
    p.add_argument("--reference-spp", type=int, default=65536, help="samples per pixel per reference pass")
    p.add_argument("--passes", type=int, default=2, help="reference passes (seeds) averaged")
    p.add_argument("--variant", default="llvm_ad_mono", help="Mitsuba variant (scalar_mono without libLLVM)")
    p.add_argument("--out", type=Path, default=None, help="JSON file (default benchmarks/results/...)")
    args = p.parse_args(argv)
    try:
        import mitsuba as mi
    except ImportError:
        print("vs mitsuba   skipped: Mitsuba 3 is not installed (pip install -e '.[compare]')")
        return 0
    mi.set_variant(args.variant)
    n, m = (64, 64) if args.quick else (128, 128)
    spp = 4096 if args.quick else args.reference_spp
    rows = []
    for name, (elevation, azimuth) in CASES.items():
        rows += run_case(mi, name, elevation, azimuth, n, m, spp, args.passes)
    from benchmarks.run import save_record

    save_record({"benchmark": "vs_mitsuba", "mitsuba": mi.__version__, "variant": args.variant,
                 "reference_spp": spp, "reference_passes": args.passes, "water_n": n, "map_m": m,
                 "rows": rows}, args.out, "vs_mitsuba", args.quick, "cpu")
    return 0


if __name__ == "__main__":
    sys.exit(main())
