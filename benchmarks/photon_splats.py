"""Photon footprint splats vs texel deposits at equal photon count and time, same run.

``configs/ocean.toml`` (a point sun, rgb, no absorption) with photons deposited per texel and
spread over their footprints, at several photons per surface cell: the photon stage's time (emit,
trace, deposit; median after a warm-up frame, device synchronised) and the floor map's relative L1
against the converged photon map (footprints at ``CONVERGED`` photons per cell: the photon method's
own limit, so the figure is its noise) and against the beams' exact map (the triangle surface model
instead of the photons' bilinear patches). Printed with photons per texel; the ratio is the time
footprints need for the texel deposit's error at the default 4×4 per cell.

The same with a sphere in the water (radius 1 m, 7,936 faces, centre 2.5 m down): the photon
stage's time and the relative L1 of the flux on the sphere's faces against the converged photons'
and the beams', for photons deposited on the face they hit and spread over the faces their cells
cover.
``python -m benchmarks.photon_splats --help``.
"""

from __future__ import annotations

import sys

from benchmarks.run import ROOT, device_record, median_time, point_sun_scene

FULL = {"n": 256, "m": 256, "subdivisions": (1, 2, 4, 8), "converged": 16}
QUICK = {"n": 32, "m": 32, "subdivisions": (1, 2, 4), "converged": 8}
SPHERE = {"receivers": [{"mesh": "sphere", "scale": 2.0, "translate_m": [0.0, 0.0, -2.5]}]}
"""The sphere's case: a 1 m ball whose top is 1.5 m under the surface."""
SPHERE_ID = 2
"""The sphere's receiver id (the floor's 0, the walls' 1)."""


def _scene(n: int, m: int, overrides: dict):
    return point_sun_scene(ROOT / "configs" / "ocean.toml", {
        "water.resolution": n, "caustics.map_resolution": m, "optics.wavelengths": "rgb",
        "optics.water_type": "none", **overrides})


def measure(size: dict, device: str, repeats: int, sphere: bool = False) -> list[dict]:
    """Rows for the floor map or, with ``sphere``, for the flux on the sphere's faces."""
    import warpcaustics as wc
    from warpcaustics.reference import relative_l1

    n, m = size["n"], size["m"]
    extra = SPHERE if sphere else {}

    def quantity(result):
        if sphere:
            return result.face_flux_w_nm[result.face_receiver == SPHERE_ID]
        return result.floor_irradiance

    beams = quantity(wc.render(_scene(n, m, {"caustics.method": "beams", **extra}), device=device))
    converged = quantity(wc.render(_scene(n, m, {
        "caustics.method": "photons", "caustics.photon_splat": "footprint",
        "caustics.photon_subdivisions": size["converged"], **extra}), device=device))
    rows = []
    for splat in ("texel", "footprint"):
        for s in size["subdivisions"]:
            scene = _scene(n, m, {"caustics.method": "photons", "caustics.photon_splat": splat,
                                  "caustics.photon_subdivisions": s, **extra})
            renderer = wc.Renderer(scene, device)
            result = renderer.render(0.0)  # warm-up
            stage = renderer.method.caustics[0]
            surface = renderer.water.at(0.0)

            def trace(stage=stage, surface=surface, renderer=renderer, scene=scene):
                stage.trace(surface, renderer.visible, scene.sun_direction, renderer.light.sun_irradiance)

            rows.append({"receiver": "sphere" if sphere else "floor", "splat": splat, "subdivisions": s,
                         "water_n": n, "map_m": m, "photons_per_texel": (n * s) ** 2 / m**2,
                         "stage_s": median_time(trace, repeats, device),
                         "l1_vs_converged": relative_l1(converged, quantity(result)),
                         "l1_vs_beams": relative_l1(beams, quantity(result))})
    return rows


def equal_error_ratio(rows: list[dict]) -> float:
    """Texel time at the default 4×4 per cell over the time of the cheapest footprint setting whose
    L1 against the converged map is no larger (a lower bound of the time ratio at equal error;
    nan if none is)."""
    texel = next(r for r in rows if r["splat"] == "texel" and r["subdivisions"] == 4)
    good = [r["stage_s"] for r in rows if r["splat"] == "footprint" and r["receiver"] == texel["receiver"]
            and r["l1_vs_converged"] <= texel["l1_vs_converged"]]
    return float(texel["stage_s"] / min(good)) if good else float("nan")


def run(quick: bool, device: str) -> dict:
    import warp as wp

    from benchmarks.run import _cpu_name

    size = QUICK if quick else FULL
    repeats = 2 if quick else 5
    record = device_record(device)
    print(f"photon splat warp {wp.__version__} [{device}: {record['device_name']}] | cpu {_cpu_name()}",
          flush=True)
    out = {"benchmark": "photon_splats", **record, "repeats": repeats,
           "converged_subdivisions": size["converged"],
           "timing": "median of the photon stage's trace() after a warm-up frame, device synchronised"}
    for receiver in ("floor", "sphere"):
        rows = measure(size, device, repeats, sphere=receiver == "sphere")
        what = "floor map" if receiver == "floor" else "sphere's faces"
        for r in rows:
            s = r["subdivisions"]
            print(f"photon splat {receiver:6s} {r['splat']:9s} {s:2d}x{s:<2d} per cell "
                  f"{r['photons_per_texel']:6.1f} per texel | {r['stage_s'] * 1e3:8.1f} ms | L1 vs converged "
                  f"{r['l1_vs_converged']:.4f} | vs beams {r['l1_vs_beams']:.4f}", flush=True)
        ratio = equal_error_ratio(rows)
        print(f"photon splat {what}: texel 4x4 per cell vs the cheapest footprint setting at least as "
              f"accurate: "
              f"ratio {ratio:.2f}x (time at equal L1, a lower bound)", flush=True)
        key = "" if receiver == "floor" else "sphere_"
        out[f"{key}results"] = rows
        out[f"{key}texel_4x4_time_over_footprint_time_at_equal_l1"] = ratio
    return out


def main(argv: list[str] | None = None) -> int:
    from benchmarks.run import module_main

    return module_main(argv, "photon_splats", run, __doc__)


if __name__ == "__main__":
    sys.exit(main())
