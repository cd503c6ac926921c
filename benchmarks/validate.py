"""Print the validation figures quoted in docs/validation.md: ``python -m benchmarks.validate``.

The same scenes as the tests, reporting the measured error instead of a pass/fail.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import numpy as np

from benchmarks.run import point_sun_scene

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))


def main() -> int:
    _floor_physics()
    _lens()
    _crests()
    _fft_ocean()
    _colour_and_fft()
    _photons()
    _beams()
    _approximate_methods()
    _sunmap_variants()
    _wave_depths()
    _multiple_scattering()
    return 0


def _floor_physics() -> None:
    """The flux-ratio floor on flat water, its energy on a rough sea and the float64 reference."""
    import warpcaustics as wc
    from warpcaustics import reference

    from helpers import flat_floor_irradiance
    from test_floor_physics import _flat_scene, _rough_ocean, _transmitted_flux_float64

    print("## Flat water vs E_sun cosθ T(θ) exp(-c D / cosθ_t)  (pure water, 8 bins, max over bins, texels)")
    for el in (15.0, 40.0, 65.0, 90.0):
        for depth in (0.5, 5.0, 30.0):
            r = wc.render(_flat_scene(el, depth), device="cpu")
            e = flat_floor_irradiance(r, el, depth)
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


def _lens() -> None:
    """The paraboloid lens's focus, under an overhead and an oblique sun."""
    import warpcaustics as wc

    from test_lens import APEX_M, FOCAL_M, N

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

    print("\n## Oblique sun on the lens (elevation 45°, azimuth 30°, floor 1.0 m)")
    with tempfile.TemporaryDirectory() as tmp:
        np.save(Path(tmp) / "lens.npy", h)
        scene = point_sun_scene(None, {
            "water.model": "heightfield", "water.file": str(Path(tmp) / "lens.npy"),
            "water.extent_m": EXTENT_M, "floor.depth_m": 1.0, "sun.elevation_deg": 45.0,
            "sun.azimuth_deg": 30.0, "optics.water_type": "none", "optics.wavelengths.bins": 1,
            "caustics.map_resolution": N})
        f = wc.render(scene, device="cpu").floor_irradiance[0].astype(np.float64)
    spot = np.where(f > 2 * np.median(f), f, 0.0)
    cx, cy = (spot.sum(0) * x).sum() / spot.sum(), (spot.sum(1) * x).sum() / spot.sum()
    shift = (1.0 + APEX_M) * np.tan(np.arcsin(np.sin(np.radians(45.0)) / 1.333))
    ex, ey = -shift * np.cos(np.radians(30.0)), -shift * np.sin(np.radians(30.0))
    print(f"spot centroid ({cx:.4f}, {cy:.4f}) m, chief ray ({ex:.4f}, {ey:.4f}) m, "
          f"distance {np.hypot(cx - ex, cy - ey) * 1000:.1f} mm (texel {EXTENT_M / N * 1000:.1f} mm)")


def _crests() -> None:
    """The crests' shading of a low sun against the float64 sweep."""
    import warpcaustics as wc
    from warpcaustics import reference

    print("\n## Shading by crests: steep sea, sun 10° high (64², water_type none)")
    scene = point_sun_scene(None, {"water.model": "fft", "water.resolution": 64, "water.extent_m": 8.0,
                                 "water.wind_speed_m_s": 5.0, "water.phillips_amplitude": 0.05,
                                 "floor.depth_m": 20.0, "caustics.map_resolution": 64,
                                 "sun.elevation_deg": 10.0, "optics.water_type": "none",
                                 "optics.wavelengths.bins": 1, "water.seed": 1})
    renderer = wc.Renderer(scene, "cpu")
    r = renderer.render(0.0)
    s_dir = scene.sun_direction
    idx, shift_m = reference.triangles(64, 8.0)
    tri = r.surface_positions.astype(np.float64).reshape(-1, 3)[idx]
    tri[..., :2] += shift_m
    a_perp = 0.5 * np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]) @ s_dir
    beam = r.sun_irradiance[0] * 64.0 * s_dir[2]
    vis64 = reference.sun_visibility(r.surface_positions.astype(np.float64), s_dir, 8.0)
    print(f"shaded vertices {1 - renderer.visible.numpy().mean():.1%} (the float64 sweep disagrees on "
          f"{np.mean(renderer.visible.numpy() != vis64):.2%}); sun-facing area / beam section "
          f"{np.maximum(a_perp, 0).sum() / (64.0 * s_dir[2]):.3f}; floor flux / beam flux "
          f"{r.floor_flux_w_nm[0] / beam:.3f}")


def _fft_ocean() -> None:
    """The FFT ocean's height variance, dynamics and choppiness, and JONSWAP's variance."""
    from test_water import _phillips_h0

    from warpcaustics import water

    print("\n## Ocean height variance vs the spectrum (24 seeds, 512² over 200 m, A = 3e-3)")
    for wind in (4.0, 8.0):
        params = {"amplitude": 3e-3, "wind_speed_m_s": wind, "wind_direction_deg": 40.0, "small_wave_m": 0.0}
        var = np.array([np.var(water.FFTOcean(_phillips_h0(512, 200.0, sd, **params), 200.0, 1000.0, "cpu")
                               .at(1.3).positions.numpy()[..., 2].astype(np.float64)) for sd in range(24)])
        k = water.wavenumbers(512, 200.0)
        p = water.phillips_spectrum(*np.meshgrid(k, k), **params)
        p[256, :] = 0.0
        p[:, 256] = 0.0
        drawn = p.sum() * (2 * np.pi / 200.0) ** 2
        cont = 3e-3 * np.pi * (wind**2 / 9.81) ** 2 / 2
        sig = var.std(ddof=1) / np.sqrt(24)
        print(f"wind {wind} m/s: mean variance {var.mean():.5f} m², drawn ΣPΔk² {drawn:.5f} "
              f"({(var.mean() / drawn - 1):+.2%}, σ of the mean {sig / drawn:.1%}), continuous "
              f"{cont:.5f} ({drawn / cont - 1:+.2%}); Hs {4 * np.sqrt(var.mean()):.3f} m")

    print("\n## FFT ocean dynamics and choppiness")
    from test_water import _ocean, _single_mode

    from warpcaustics.config import config_from_dict

    for depth in (1000.0, 1.0):
        ocean = water.FFTOcean(_single_mode(64, 32.0, 4), 32.0, depth, "cpu")
        kw = 2 * np.pi * 4 / 32.0
        ph = [np.angle(np.fft.fft(ocean.at(t).positions.numpy()[0, :, 2].astype(np.float64))[4])
              for t in (0.0, 0.05)]
        c = -np.angle(np.exp(1j * (ph[1] - ph[0]))) / (kw * 0.05)
        c0 = np.sqrt(9.81 * kw * np.tanh(kw * depth)) / kw
        print(f"single mode, depth {depth:6.1f} m: phase speed {c:.4f} m/s, ω/k {c0:.4f} ({c / c0 - 1:+.2%})")
    surface = _ocean(256, "cpu", extent=10.0, small_wave_m=0.25).at(0.7)
    hh = surface.positions.numpy()[..., 2].astype(np.float64)
    cell = 10.0 / 256
    fd = np.stack([-(np.roll(hh, -1, 1) - np.roll(hh, 1, 1)) / (2 * cell),
                   -(np.roll(hh, -1, 0) - np.roll(hh, 1, 0)) / (2 * cell), np.ones_like(hh)], -1)
    fd /= np.linalg.norm(fd, axis=-1, keepdims=True)
    print(f"spectral normals vs central differences (256², band-limited): max |Δn| "
          f"{np.abs(surface.normals.numpy() - fd).max():.1e}")
    for lam in (0.0, 0.5, 1.5, 3.0):
        jac = _ocean(128, "cpu", extent=20.0, choppiness=lam, amplitude=5e-2, small_wave_m=0.5).at(
            1.0).jacobian.numpy()
        print(f"choppiness {lam}: folded fraction {np.mean(jac <= 0):.3%}, mean |J - 1| "
              f"{np.abs(jac - 1).mean():.3f}")
    cfg = config_from_dict({}, {"water.spectrum": "jonswap", "water.wind_speed_m_s": 6.0,
                                "water.fetch_m": 20000.0, "water.extent_m": 300.0,
                                "water.resolution": 512, "floor.depth_m": 30.0})
    kk = water.wavenumbers(512, 300.0)
    drawn = water.ocean_spectrum(cfg, *np.meshgrid(kk, kk)).sum() * (2 * np.pi / 300.0) ** 2
    g, u, f = 9.81, 6.0, 20000.0
    al, wpk = 0.076 * (u * u / (f * g)) ** 0.22, 22.0 * (g * g / (u * f)) ** (1 / 3)
    om = np.linspace(0.2 * wpk, 12 * wpk, 200001)
    sg = np.where(om <= wpk, 0.07, 0.09)
    so = (al * g * g / om**5 * np.exp(-1.25 * (wpk / om) ** 4)
          * 3.3 ** np.exp(-((om - wpk) ** 2) / (2 * sg**2 * wpk**2)))
    print(f"JONSWAP (6 m/s, 20 km fetch): Σ P Δk² {drawn:.5f} m², ∫ S dω {np.trapezoid(so, om):.5f} m² "
          f"({drawn / np.trapezoid(so, om) - 1:+.2%})")


def _colour_and_fft() -> None:
    """D65 through the colour pipeline and Warp's FFT against numpy's."""
    from warpcaustics import water

    print("\n## Colour: D65 → linear sRGB / Y")
    from warpcaustics.optics import colour as colour_out
    from warpcaustics.optics.spectra import SpectralBins

    d65 = colour_out.colour_science().SDS_ILLUMINANTS["D65"]
    for width in (1.0, 5.0, 18.75):
        bins = SpectralBins.uniform(380.0, 780.0, int(round(400 / width)))
        xyz = colour_out.spectral_to_xyz(bins.average(d65.wavelengths, d65.values, "D65")[:, None, None],
                                         bins)[0, 0]
        rgb = colour_out.xyz_to_linear_srgb(xyz) / xyz[1]
        print(f"{width:5.2f} nm bins: max |rgb/Y - 1| = {np.abs(rgb - 1).max():.1e}")

    print("\n## Warp FFT vs numpy.fft (norm-relative)")
    rng = np.random.default_rng(0)
    for n in (64, 256, 1024):
        x = rng.standard_normal((n, n)) + 1j * rng.standard_normal((n, n))
        a = water.to_vec2(x, "cpu")
        water.ifft2(a)
        ref = np.fft.ifft2(x) * n * n
        print(f"{n}²: {np.linalg.norm(water.from_vec2(a) - ref) / np.linalg.norm(ref):.2e}")


def _wave_depths() -> None:
    """The wave texture on still water at depth under a low sun: docs/physics.md's figures."""
    import warpcaustics as wc

    print("\n## Wave texture on still water, 15° sun, 48 nodes across 4 m: floor / flux-ratio floor")
    for depth in (1.5, 6.0, 12.0):
        r = wc.render(point_sun_scene(None, {
            "caustics.method": "wave3d", "water.model": "flat", "water.extent_m": 4.0, "water.resolution": 64,
            "caustics.map_resolution": 64, "caustics.wave3d_resolution": 48, "sun.elevation_deg": 15.0,
            "sun.azimuth_deg": 25.0, "floor.depth_m": depth,
            "optics.wavelengths": {"min_nm": 450.0, "max_nm": 650.0, "bins": 2}}), device="cpu")
        ratio = r.floor_irradiance.mean(axis=(1, 2)) / r.comparison.floor_irradiance.mean(axis=(1, 2))
        print(f"{depth:4.1f} m: {np.round(ratio.astype(np.float64), 3).tolist()}")


def _multiple_scattering() -> None:
    """Caustic contrast against depth, single vs multiple scattering: docs/physics.md's table."""
    from test_multiple import contrast_without_noise

    print("\n## Multiple vs single scattering, configs/ocean.toml in coastal water (64² surface, 32² map, "
          "rgb; walk noise removed with two seeds)")
    for depth in (1.0, 3.0, 6.0):
        cv_single, cv_multi, gain = contrast_without_noise({
            "water.resolution": 64, "caustics.map_resolution": 32, "optics.wavelengths": "rgb",
            "optics.water_type": "coastal_ocean", "floor.depth_m": depth, "optics.scattering": "multiple",
            "optics.mc_samples": 4})
        print(f"{depth:.0f} m: CV single {np.round(cv_single, 3).tolist()}, CV multiple "
              f"{np.round(cv_multi, 3).tolist()}, floor mean multiple / single {np.round(gain, 2).tolist()}")


APPROXIMATE = ("sunmap", "eikonal", "wave3d")
"""The approximate floor methods (issue 8), compared with the flux-ratio map."""


def _approximate_methods() -> None:
    """The approximate methods against the flux-ratio map: docs/validation.md's method table."""
    from warpcaustics.batch.compare import compare_methods

    print("\n## Approximate methods vs the flux-ratio map (band-summed maps normalised by their means)")
    scenes = {"configs/ocean.toml": ({}, 0.0, APPROXIMATE),
              "configs/ocean.toml, eikonal 256": ({"caustics.eikonal_resolution": 256}, 0.0, ("eikonal",)),
              "configs/ocean.toml, eikonal 256, 1 m": (
                  {"caustics.eikonal_resolution": 256, "floor.depth_m": 1.0}, 0.0, ("eikonal",)),
              "configs/procedural.toml": ({}, 0.0, APPROXIMATE),
              "configs/lens.toml": ({"caustics.map_resolution": 128}, 0.0, APPROXIMATE),
              "configs/mercier_pool.toml": ({}, 0.3, APPROXIMATE)}
    for label, (overrides, time_s, methods) in scenes.items():
        config = label.split(",")[0]
        rows = compare_methods(ROOT / config, {"sun.angular_diameter_deg": 0.0, **overrides}, time_s, "cpu",
                               methods)["rows"]
        reference = rows[0]["contrast"]
        for r in rows[1:]:
            print(f"{label:37s} {r['method']:8s} correlation {r['correlation']:6.3f}  relative L1 "
                  f"{r['relative_l1']:.3f}  contrast {r['contrast']:.3f} (flux ratio {reference:.3f})")


SUNMAP_SCENES = {"configs/ocean.toml": 0.0, "configs/pool.toml": 1.0, "configs/procedural.toml": 0.0}
"""Scenes (and times) of the sun map's two variants against the flux-ratio map (issue 26)."""


def sunmap_variant_rows(device: str = "cpu", overrides: dict | None = None) -> list[dict]:
    """GPU Gems ch. 2's per-vertex (§2.3–2.4) and per-pixel (§2.5) sun maps against the
    flux-ratio map of the same frame, under a point sun: one row per scene and variant."""
    from warpcaustics.batch.compare import compare_methods

    rows = []
    for config, time_s in SUNMAP_SCENES.items():
        for variant in ("per_vertex", "per_pixel"):
            cmp = compare_methods(ROOT / config, {"sun.angular_diameter_deg": 0.0,
                                                  "caustics.sunmap_variant": variant, **(overrides or {})},
                                  time_s, device, ("sunmap",))["rows"]
            rows.append({"config": config, "time_s": time_s, "variant": variant,
                         "reference_contrast": cmp[0]["contrast"], **cmp[1]})
    return rows


def _sunmap_variants() -> None:
    print("\n## Sun map per vertex (§2.3-2.4) and per pixel (§2.5) vs the flux-ratio map (point sun)")
    for sun, overrides in (("the config's sun", {}), ("sun at 30°", {"sun.elevation_deg": 30.0})):
        for r in sunmap_variant_rows(overrides=overrides):
            print(f"{r['config']:24s} {sun:16s} t={r['time_s']:.1f} s {r['variant']:10s} correlation "
                  f"{r['correlation']:6.3f}  relative L1 {r['relative_l1']:.3f}  contrast "
                  f"{r['contrast']:.3f} "
                  f"(flux ratio {r['reference_contrast']:.3f})")


def _photons() -> None:
    """Photon caustics: the figures of docs/validation.md's photon section."""
    from test_newton import SLOPE, SPHERE, newton_errors
    from test_photons import PHOTONS, _flat

    import warpcaustics as wc

    from helpers import flat_floor_irradiance

    print("\n## Photons on flat water vs E_sun cosθ T(θ) exp(-c D / cosθ_t)  (pure water, 8 bins, 3 m)")
    for mode in ("exact", "newton"):
        worst = 0.0
        for el in (20.0, 55.0, 90.0):
            r = wc.render(_flat(el, 3.0, **{"caustics.intersection": mode}), device="cpu")
            e = flat_floor_irradiance(r, el, 3.0)
            worst = max(worst, float(np.abs(r.floor_irradiance / e[:, None, None] - 1).max()))
        print(f"{mode:6s}: max relative error over elevations 20°, 55°, 90° and all texels {worst:.1e}")

    print("\n## Photon flux conservation (water_type = none)")
    r = wc.render(point_sun_scene(ROOT / "configs" / "ocean.toml", {
        **PHOTONS, "water.resolution": 64, "water.wind_speed_m_s": 9.0, "water.choppiness": 0.8,
        "caustics.map_resolution": 48, "optics.water_type": "none", "optics.wavelengths": "rgb"}),
        device="cpu")
    print(f"rough choppy ocean: floor / transmitted - 1 = "
          f"{np.abs(r.floor_flux_w_nm / r.transmitted_flux_w_nm - 1).max():.1e}")
    r = wc.Renderer(point_sun_scene(ROOT / "configs" / "pool.toml", {
        **PHOTONS, "water.resolution": 48, "caustics.map_resolution": 48, "optics.water_type": "none",
        "optics.wavelengths": "rgb", "sun.elevation_deg": 40.0,
        "receivers": [{"mesh": "sphere", "scale": 0.8, "translate_m": [0.3, -0.2, -1.0]}]}),
        "cpu").render(0.6)
    total = r.floor_flux_w_nm + r.face_flux_w_nm.sum(axis=0, dtype=np.float64)
    print(f"pool with a sphere (floor + walls + sphere) / transmitted - 1 = "
          f"{np.abs(total / r.transmitted_flux_w_nm - 1).max():.1e}")

    print("\n## Shah's Newton–Raphson vs exact BVH hits (64² surface, 2×2 photons per cell, 1024² buffer)")
    oblique = {**SLOPE, "sun.elevation_deg": 80.0}
    for name, scene, receiver in (("15° slope in the pool, sun at the zenith", SLOPE, 0),
                                  ("15° slope in the pool, sun 80° high", oblique, 0),
                                  ("sphere r = 1.5 m in the ocean", SPHERE, 2)):
        ks = [0, 1, 2, 3, 4, 5]
        errors, texel = newton_errors(scene, ks, receiver=receiver)
        print(f"{name} (light-view texel {texel * 1000:.1f} mm): k, mean, median, p95 [mm], "
              "share within a texel")
        for k, e in zip(ks, errors):
            print(f"  k={k}: {e['mean'] * 1000:10.4f} {e['median'] * 1000:10.4f} {e['p95'] * 1000:10.4f}  "
                  f"{e['within_texel']:.1%}")

    print("\n## Newton vs exact hits: where a walled pool's light lands (0.6 s, no absorption)")
    from test_newton import pool_flux_by_intersection

    for config, el in (("pool", 20.0), ("pool", 40.0), ("pool", 70.0), ("wavepool", 30.0)):
        f = pool_flux_by_intersection(el, ROOT / "configs" / f"{config}.toml")
        share = {mode: {part: f[mode][part] / f["transmitted"] for part in ("floor", "walls")}
                 for mode in ("exact", "newton")}
        print(f"{config}.toml, sun {el:2.0f}°: floor {share['exact']['floor']:.2%} exact, "
              f"{share['newton']['floor']:.2%} Newton; walls {share['exact']['walls']:.2%} exact, "
              f"{share['newton']['walls']:.2%} Newton "
              "(of the transmitted flux)")

    print("\n## Photons vs the flux-ratio map, configs/ocean.toml (256² surface, rgb)")
    for m in (64, 128):
        base = {"caustics.map_resolution": m, "optics.wavelengths": "rgb"}
        ref = wc.render(point_sun_scene(ROOT / "configs" / "ocean.toml", base), device="cpu").floor_irradiance
        for s in (1, 2, 4):
            f = wc.render(point_sun_scene(ROOT / "configs" / "ocean.toml", {
                **base, **PHOTONS, "caustics.photon_subdivisions": s}), device="cpu").floor_irradiance
            per_texel = 256 * 256 * s * s / m / m
            print(f"map {m}², {s * s:2d} photons per cell ({per_texel:5.0f} per texel): relative L1 "
                  f"{np.abs(f - ref).sum() / np.abs(ref).sum():.2%}")

    print("\n## Light shafts vs single scattering, sun at the zenith over a still pool (clear_ocean)")
    from test_photons import shaft_block

    for n in (64, 128, 256):
        for pitch, sees, view in ((0.0, 1, "level, to the far wall"), (35.0, -1, "35° up, to the surface"),
                                  (-35.0, 0, "35° down, to the floor (+ the lit floor)")):
            measured, expected = shaft_block(pitch, sees, n)
            print(f"{n}² surface (one line per cell), {view}: block mean / analytic per band: "
                  + ", ".join(f"{x:.3f}" for x in measured / expected))
    _camera_floor()


def _camera_floor() -> None:
    from test_photons import _flat

    import warpcaustics as wc

    from helpers import fresnel_t_angles

    print("\n## Camera: uniformly lit grey floor seen obliquely (flat water, water_type none)")
    r = wc.render(_flat(60.0, 3.0, "none", **{
        "water.resolution": 128, "caustics.photon_subdivisions": 4, "floor.albedo": 0.5,
        "camera.enabled": True,
        "camera.position_m": [-1.0, -2.0, -1.0], "camera.look_at_m": [0.5, 0.5, -3.0], "camera.width": 96,
        "camera.height": 64, "camera.fov_deg": 60.0}), device="cpu")
    th = np.radians(30.0)
    e = r.sun_irradiance * np.cos(th) * fresnel_t_angles(np.array([th]), 1.0, 1.333)[0]
    g = r.camera_gbuffer
    seen = (g["receiver"] == 0) & np.all(np.abs(g["position"][..., :2]) < 3.5, axis=-1)
    seen[:6], seen[-6:], seen[:, :6], seen[:, -6:] = False, False, False, False
    err = np.abs(r.camera_radiance[:, seen] * np.pi / 0.5 / e[:, None] - 1).max()
    print(f"max |L π / (albedo E) - 1| over {seen.sum()} pixels: {err:.1e}")



def _beams() -> None:
    """Beam caustics: the figures of docs/validation.md's beam section."""
    from test_beam_chords import (
        NEAR_AXIS_BEAMS,
        PRISM_BASE,
        PRISM_DIRECTION,
        PRISM_ENDS,
        _prism_chord,
        _straight_prism_chords,
        near_axis_chord_errors,
    )
    from test_beams import BEAMS, _flat, _sphere_bins
    from test_photons import shaft_block

    import warpcaustics as wc

    from helpers import flat_floor_irradiance

    print("\n## Beams on flat water vs E_sun cosθ T(θ) exp(-c D / cosθ_t)  (pure water, 8 bins, 3 m)")
    worst = 0.0
    for el in (5.0, 20.0, 55.0, 90.0):
        r = wc.render(_flat(el, 3.0), device="cpu")
        e = flat_floor_irradiance(r, el, 3.0)
        worst = max(worst, float(np.abs(r.floor_irradiance / e[:, None, None] - 1).max()))
    print(f"max relative error over elevations 5°, 20°, 55°, 90° and all texels {worst:.1e}")

    print("\n## Beam floor map, configs/ocean.toml (128² surface, 64² map, rgb)")
    base = {"water.resolution": 128, "caustics.map_resolution": 64, "optics.wavelengths": "rgb"}
    ocean = ROOT / "configs" / "ocean.toml"
    ref = wc.render(point_sun_scene(ocean, base), device="cpu").floor_irradiance
    for interp in ("flat", "smooth"):
        b = wc.render(point_sun_scene(ocean, {**base, **BEAMS, "caustics.beam_interpolation": interp,
                                            "optics.water_type": "none"}), device="cpu")
        flux = np.abs(b.floor_flux_w_nm / b.transmitted_flux_w_nm - 1).max()
        f = wc.render(point_sun_scene(ocean, {**base, **BEAMS, "caustics.beam_interpolation": interp}),
                      device="cpu").floor_irradiance
        print(f"{interp:6s}: flux (water_type none) floor / transmitted - 1 = {flux:.1e}; pure water, "
              f"relative L1 vs the flux-ratio map {np.abs(f - ref).sum() / np.abs(ref).sum():.1e}")

    print("\n## Beams vs exact photons (16 per cell, 256 per texel), ocean.toml + sphere r = 1 m at z = -2.5")
    centre = [0.0, 0.0, -2.5]
    base = {"water.resolution": 128, "caustics.map_resolution": 32, "optics.wavelengths": "rgb",
            "optics.water_type": "none",
            "receivers": [{"mesh": "sphere", "scale": 2.0, "translate_m": centre}]}
    ph = wc.render(point_sun_scene(ocean, {**base, "caustics.method": "photons",
                                         "caustics.photon_subdivisions": 4}), device="cpu")
    bm = wc.render(point_sun_scene(ocean, {**base, **BEAMS}), device="cpu")
    floor_l1 = np.abs(bm.floor_irradiance - ph.floor_irradiance).sum() / np.abs(ph.floor_irradiance).sum()
    sb, sp = _sphere_bins(bm, 2, centre), _sphere_bins(ph, 2, centre)
    total = bm.floor_flux_w_nm + bm.face_flux_w_nm.sum(axis=0)
    print(f"floor relative L1 {floor_l1:.2%}; sphere (8×8 elevation-azimuth cells) relative L1 "
          f"{np.abs(sb - sp).sum() / np.abs(sp).sum():.2%}; (floor + sphere) / transmitted - 1 = "
          f"{np.abs(total / bm.transmitted_flux_w_nm - 1).max():.1e}")

    print("\n## Beams on rippled sand under ocean.toml (64² surface, 64² map, water_type none)")
    rip = {"water.resolution": 64, "caustics.map_resolution": 64, "optics.water_type": "none",
           "optics.wavelengths": "rgb", "floor.shape": "ripples", "floor.ripple_amplitude_m": 0.1,
           "floor.ripple_wavelength_m": 16.0 / np.hypot(7, 26),
           "floor.ripple_direction_deg": np.degrees(np.arctan2(26, 7))}
    bm = wc.render(point_sun_scene(ocean, {**rip, **BEAMS}), device="cpu")
    for s in (8, 16):
        ph = wc.render(point_sun_scene(ocean, {**rip, "caustics.method": "photons",
                                             "caustics.photon_subdivisions": s}), device="cpu")
        l1 = np.abs(bm.floor_irradiance - ph.floor_irradiance).sum() / ph.floor_irradiance.sum()
        print(f"vs exact photons at {s * s} per cell: relative L1 {l1:.2%}; beams floor / transmitted - 1 = "
              f"{(bm.floor_flux_w_nm / bm.transmitted_flux_w_nm - 1).max():.1e}")
    for el in (20.0, 5.0):
        low = wc.render(point_sun_scene(ocean, {**rip, **BEAMS, "sun.elevation_deg": el}), device="cpu")
        print(f"sun {el:g}° high: beams floor / transmitted - 1 = "
              f"{(low.floor_flux_w_nm / low.transmitted_flux_w_nm - 1).max():.1e}")

    print("\n## Scan-plane chord of a straight prism vs the exact float64 ray-prism chord")
    rng = np.random.default_rng(5)
    v, ends, d = PRISM_BASE, PRISM_ENDS, PRISM_DIRECTION
    n = 4000
    origins = rng.uniform(-3.0, 3.0, (n, 3)) + np.array([0.0, 0.0, -1.0])
    targets = v.mean(axis=0) + rng.uniform(-0.5, 0.5, (n, 3)) + d * rng.uniform(0.0, 2.0, (n, 1))
    rays = (targets - origins) / np.linalg.norm(targets - origins, axis=1, keepdims=True)
    got = _straight_prism_chords(v, d, ends, origins, rays)
    errs = []
    for i in range(n):
        lo, hi = _prism_chord(v, d, ends, origins[i], rays[i])
        if hi - lo > 1e-4:
            errs.append(max(abs(got[i, 0] - lo), abs(got[i, 1] - hi)))
    print(f"{len(errs)} rays crossing the prism: max |Δs_a|, |Δs_b| = {max(errs) * 1e6:.2f} µm, "
          f"mean {np.mean(errs) * 1e6:.2f} µm")
    for beam, direction in NEAR_AXIS_BEAMS.items():
        across = near_axis_chord_errors(direction)
        print(f"beam {beam}: {len(across)} rays 1°-10° off its axis crossing it: max error across the face "
              f"that sets a chord end = {across.max() * 1e6:.2f} µm")

    print("\n## Beam light shafts vs single scattering, sun at the zenith over a still pool (clear_ocean)")
    for n in (32, 64):
        for pitch, sees, view in ((0.0, 1, "level"), (35.0, -1, "35° up"), (-35.0, 0, "35° down")):
            measured, expected = shaft_block(pitch, sees, n, method="beams")
            print(f"{n}² surface, {view}: block mean / analytic - 1 per band: "
                  + ", ".join(f"{x - 1:+.1e}" for x in measured / expected))


if __name__ == "__main__":
    sys.exit(main())
