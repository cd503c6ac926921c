"""Before/after check of a restructuring: every scene in ``configs/`` (and a variant per caustics
method, sky and scattering mode) rendered at a small size through the public API only
(``load_scene``, ``Renderer``, ``RenderResult``), so the same script runs on the old tree and the new.

    python -m benchmarks.layout_check --save /tmp/before.npz     # on the old commit
    python -m benchmarks.layout_check --compare /tmp/before.npz  # on the new one

``--compare`` prints, per scene and array, whether it is bit-identical or its largest relative
difference, and exits 1 if any array differs by more than ``--rtol`` (default 0: bits).

The one meaning that changed on purpose (CHANGELOG): a flux-ratio render's ``transmitted_flux_w_nm``
was the flux delivered to the floor after attenuation and is now the flux entering the water, the
same as for every other method; the old value is ``delivered_flux_w_nm``. An old
``transmitted_flux_w_nm`` that differs is therefore compared with the new ``delivered_flux_w_nm``
of the same result and reported as "moved" when those bits agree.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]

SMALL = {"water.resolution": 32, "caustics.map_resolution": 48, "optics.wavelengths.bins": 4,
         "sun.disk_samples": 4, "caustics.eikonal_resolution": 24, "caustics.wave3d_resolution": 48,
         "camera.width": 32, "camera.height": 24}
"""Overrides that make every scene small (a key a scene does not use is harmless)."""

VARIANTS: dict[str, tuple[str, dict]] = {
    "ocean_beams_camera": ("ocean.toml", {"caustics.method": "beams", "camera.enabled": True,
                                          "camera.position_m": [0.0, -5.0, -1.5],
                                          "camera.look_at_m": [0.0, 0.0, -3.5]}),
    "ocean_photons_newton": ("ocean.toml", {"caustics.method": "photons", "caustics.intersection": "newton"}),
    "ocean_both_camera": ("ocean.toml", {"caustics.method": "both", "camera.enabled": True,
                                         "camera.position_m": [0.0, -5.0, -1.5],
                                         "camera.look_at_m": [0.0, 0.0, -3.5]}),
    "ocean_sky": ("ocean.toml", {"sky.model": "uniform", "sky.diffuse_fraction": 0.2, "sky.directions": 3}),
    "ocean_photons_sky": ("ocean.toml", {"caustics.method": "photons", "sky.model": "uniform",
                                         "sky.diffuse_fraction": 0.2, "sky.directions": 2}),
    "ocean_multiple": ("ocean.toml", {"optics.scattering": "multiple", "optics.water_type": "coastal_ocean",
                                      "optics.mc_samples": 1}),
    "ocean_multiple_sky": ("ocean.toml", {"optics.scattering": "multiple", "optics.mc_samples": 1,
                                          "sky.model": "uniform", "sky.diffuse_fraction": 0.2,
                                          "sky.directions": 2}),
    "ocean_window": ("ocean.toml", {"caustics.map_extent_m": 4.0, "caustics.map_center_m": [1.0, -2.0]}),
    "ocean_dispersion": ("ocean.toml", {"optics.dispersion": True}),
    "procedural_sunmap": ("procedural.toml", {"caustics.method": "sunmap"}),
    "pool_wave3d": ("wavepool.toml", {"caustics.method": "wave3d"}),
    "pool_eikonal_sky": ("wavepool.toml", {"caustics.method": "eikonal", "sky.model": "uniform",
                                           "sky.diffuse_fraction": 0.2, "sky.directions": 2}),
    "pool_beams_smooth": ("pool.toml", {"caustics.method": "beams", "caustics.beam_interpolation": "smooth"}),
    "pool_photons_newton": ("pool.toml", {"caustics.method": "photons", "caustics.intersection": "newton",
                                          "sun.elevation_deg": 50.0}),
}

TIMES_S = (0.0, 0.1)
"""Two frames from one Renderer: the pools are stateful, frame 2 comes from stepping frame 1."""

FIELDS = ("floor_irradiance", "transmitted_flux_w_nm", "sky_floor_irradiance", "camera_radiance",
          "face_flux_w_nm", "surface_positions", "surface_normals", "delivered_flux_w_nm")
MOVED = {"transmitted_flux_w_nm": "delivered_flux_w_nm"}
"""An old array's meaning that moved to another name (see the module docstring)."""


def scenes() -> dict[str, tuple[Path, dict]]:
    """Every render scene in configs/ (study, sweep and field files are not scenes) and the variants."""
    out = {}
    for path in sorted((ROOT / "configs").glob("*.toml")):
        if path.stem != "study":
            out[path.stem] = (path, {})
    for name, (file, extra) in VARIANTS.items():
        out[name] = (ROOT / "configs" / file, extra)
    return out


def _overrides(scene_path: Path, extra: dict) -> dict:
    import warpcaustics as wc

    base = wc.load_scene(scene_path, overrides=extra).config
    small = dict(SMALL)
    if base.water.file:  # a height-field file keeps its own size
        small.pop("water.resolution")
    if not base.camera.enabled:
        small.pop("camera.width"), small.pop("camera.height")
    return {**small, **extra}


def render_all(names: list[str] | None) -> dict[str, np.ndarray]:
    import warpcaustics as wc

    arrays = {}
    for name, (path, extra) in scenes().items():
        if names and name not in names:
            continue
        scene = wc.load_scene(path, overrides=_overrides(path, extra))
        renderer = wc.Renderer(scene, device="cpu")
        for t in TIMES_S:
            result = renderer.render(t)
            for res, tag in ((result, ""), (result.comparison, "comparison.")):
                if res is None:
                    continue
                for f in FIELDS:
                    value = getattr(res, f, None)
                    if value is not None:
                        arrays[f"{name}/t{t:g}/{tag}{f}"] = np.asarray(value)
        print(f"rendered {name}", file=sys.stderr, flush=True)
    return arrays


def compare(before: dict[str, np.ndarray], after: dict[str, np.ndarray], rtol: float) -> int:
    bad = 0
    new_only = {k for k in set(after) - set(before) if k.endswith(tuple(MOVED.values()))}
    for key in sorted(set(before) | set(after) - new_only):
        if key not in after or key not in before:
            print(f"MISSING {'after' if key not in after else 'before'}: {key}")
            bad += 1
            continue
        a, b = before[key], after[key]
        if a.shape != b.shape:
            print(f"SHAPE {key}: {a.shape} vs {b.shape}")
            bad += 1
        elif np.array_equal(a, b, equal_nan=True):
            print(f"same bits  {key}")
        elif _moved(key, a, after):
            print(f"moved      {key} -> {_moved(key, a, after)} (same bits)")
        else:
            a64, b64 = a.astype(np.float64), b.astype(np.float64)
            rel = float(np.max(np.abs(a64 - b64)) / max(np.max(np.abs(a64)), 1e-300))
            ok = rel <= rtol
            bad += not ok
            print(f"{'within' if ok else 'DIFFERS'} {rel:.3e}  {key}")
    print(f"{len(set(before) | set(after)) - bad} agree, {bad} differ")
    return 1 if bad else 0


def _moved(key: str, before: np.ndarray, after: dict[str, np.ndarray]) -> str | None:
    """The new name under which ``before``'s bits are found, if its meaning moved (MOVED)."""
    for old, new in MOVED.items():
        if key.endswith(old):  # the same result's, or (an approximate method) its flux-ratio comparison's
            for new_key in (key[: -len(old)] + new, key[: -len(old)] + "comparison." + new):
                if new_key in after and np.array_equal(after[new_key], before):
                    return new_key
    return None


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    g = p.add_mutually_exclusive_group(required=True)
    g.add_argument("--save", metavar="FILE.npz")
    g.add_argument("--compare", metavar="FILE.npz")
    p.add_argument("--only", nargs="*", help="scene names to render (default all)")
    p.add_argument("--rtol", type=float, default=0.0)
    args = p.parse_args(argv)
    arrays = render_all(args.only)
    if args.save:
        np.savez_compressed(args.save, **arrays)
        print(f"wrote {len(arrays)} arrays to {args.save}")
        return 0
    with np.load(args.compare) as data:
        before = {k: data[k] for k in data.files if not args.only or k.split("/")[0] in args.only}
    return compare(before, arrays, args.rtol)


if __name__ == "__main__":
    sys.exit(main())
