"""Print the validation figures quoted in docs/validation.md: ``python -m benchmarks.validate``.

The same scenes as the tests, reporting the measured error instead of a pass/fail.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))


def main() -> int:
    import warpcaustics as wc
    from warpcaustics import reference, water

    from conftest import fresnel_t_angles
    from test_floor_physics import _flat_scene, _rough_ocean, _transmitted_flux_float64
    from test_lens import APEX_M, FOCAL_M, N

    print("## Flat water vs E_sun cosθ T(θ) exp(-c D / cosθ_t)  (pure water, 8 bins, max over bins, texels)")
    for el in (15.0, 40.0, 65.0, 90.0):
        for depth in (0.5, 5.0, 30.0):
            r = wc.render(_flat_scene(el, depth), device="cpu")
            th = np.radians(90 - el)
            ct = np.sqrt(1 - (np.sin(th) / 1.333) ** 2)
            e = r.sun_irradiance * np.cos(th) * fresnel_t_angles(np.array([th]), 1, 1.333)[0] * np.exp(
                -r.attenuation_per_m * depth / ct)
            err = np.abs(r.floor_irradiance / e[:, None, None] - 1).max()
            print(f"elevation {el:5.1f}°  depth {depth:5.1f} m   max relative error {err:.2e}")

    print("\n## Energy, rough FFT ocean, water_type = none (64² surface, 96² map)")
    r = wc.render(_rough_ocean(), device="cpu")
    t = _transmitted_flux_float64(r)
    print(f"floor flux / transmitted flux - 1: max over bins {np.abs(r.floor_flux_w_nm / t - 1).max():.2e}")

    print("\n## Warp (float32) vs numpy float64 implementation, same scene with pure water")
    r = wc.render(_rough_ocean(**{"optics.water_type": "pure"}), device="cpu")
    f64, _ = reference.floor_caustics(r.surface_positions, r.surface_normals, r.scene.sun_direction,
                                      1.333, 6.0, r.sun_irradiance, r.attenuation_per_m, 8.0, 96)
    print(f"relative L1 {np.abs(r.floor_irradiance - f64).sum() / np.abs(f64).sum():.2e}")

    print(f"\n## Paraboloid lens: f = nR/(n-1) = {FOCAL_M:.4f} m, apex {APEX_M:.4f} m")
    with tempfile.TemporaryDirectory() as tmp:
        from test_lens import APERTURE_M, EXTENT_M, RADIUS_OF_CURVATURE_M

        x = (np.arange(N) + 0.5) * EXTENT_M / N - EXTENT_M / 2
        xx, yy = np.meshgrid(x, x)
        r2 = xx**2 + yy**2
        h = np.where(r2 < APERTURE_M**2, (APERTURE_M**2 - r2) / (2 * RADIUS_OF_CURVATURE_M), 0.0)
        np.save(Path(tmp) / "lens.npy", h)
        from test_lens import _central_gain

        for d in (0.5, 1.0, 1.5):
            g = _central_gain(Path(tmp) / "lens.npy", d, "cpu")
            e = 1 / (1 - (d + APEX_M) / FOCAL_M) ** 2
            print(f"depth {d:.1f} m: central gain {g:.3f}, paraxial {e:.3f}, error {g / e - 1:+.2%}")
        depths = np.arange(1.0, 3.01, 0.1)
        gains = [_central_gain(Path(tmp) / "lens.npy", d, "cpu") for d in depths]
        print(f"brightest depth {depths[int(np.argmax(gains))]:.2f} m (predicted {FOCAL_M - APEX_M:.3f} m), "
              f"peak gain {max(gains):.0f}")

    print("\n## Warp FFT vs numpy.fft (norm-relative)")
    rng = np.random.default_rng(0)
    for n in (64, 256, 1024):
        x = rng.standard_normal((n, n)) + 1j * rng.standard_normal((n, n))
        a = water.to_vec2(x, "cpu")
        water.ifft2(a)
        ref = np.fft.ifft2(x) * n * n
        print(f"{n}²: {np.linalg.norm(water.from_vec2(a) - ref) / np.linalg.norm(ref):.2e}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
