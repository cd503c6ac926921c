"""optics.scattering = "small_angle": the water column's small-angle transfer (issue 32 item 2)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import erf

import warpcaustics as wc
from warpcaustics.errors import ConfigError
from warpcaustics.optics.phase import solid_angle_weights
from warpcaustics.optics.small_angle import phase_hankel, spread_from_phase

from helpers import CONFIGS


def test_the_spread_of_a_gaussian_phase_function_is_its_closed_form():
    """A narrow Gaussian phase function, p ∝ exp(−θ²/θ0²) with θ0 = 2°, has in the small-angle
    approximation the Hankel transform p̃(ν) = exp(−ν²θ0²/4) and so
    G(x) = (1/x)∫₀^x p̃ = √π erf(θ0 x/2)/(θ0 x): both from the code's quadrature within 1e-4 (the
    sin θ ≈ θ of the closed form costs ~θ0²/6 = 2e-4 at most, relative to 1)."""
    theta0 = math.radians(2.0)
    theta = np.concatenate([np.linspace(0.0, 1e-4, 201)[:-1], np.geomspace(1e-4, np.pi, 60000)])
    p = np.exp(-((theta / theta0) ** 2))
    p /= 2 * np.pi * np.trapezoid(p * np.sin(theta), theta)
    nu = np.array([0.0, 10.0, 50.0, 100.0, 200.0])
    weight = solid_angle_weights(theta, p)
    np.testing.assert_allclose(phase_hankel(theta, weight, nu), np.exp(-(nu**2) * theta0**2 / 4), atol=2e-4)
    x, g = spread_from_phase(theta, weight)
    pick = (x > 0.01) & (x < 1e4)
    expected = math.sqrt(math.pi) * erf(theta0 * x[pick] / 2) / (theta0 * x[pick])
    np.testing.assert_allclose(g[pick], expected, atol=2e-4)
    assert g[0] == 1.0


SCENE = {"water.resolution": 128, "caustics.map_resolution": 128, "optics.wavelengths": "rgb",
         "optics.water_type": "coastal_ocean", "floor.albedo": 0.0, "sun.angular_diameter_deg": 0.0,
         "optics.mc_samples": 8}

BANDS = [0.0, 1 / 64, 1 / 32, 1 / 16, 1 / 8, 1 / 4, 1.0]
"""Radial bands of spatial frequency [cycles per texel] for the power spectra."""


def band_power(spectrum: np.ndarray, m: int) -> np.ndarray:
    """(K, bands) the power of a (K, M, M) spectrum summed over each radial band (k = 0 left out)."""
    k = np.fft.fftfreq(m)
    kr = np.hypot(*np.meshgrid(k, k))
    bands = zip(BANDS[:-1], BANDS[1:])
    return np.stack([spectrum[:, (kr > lo) & (kr <= hi)].sum(axis=1) for lo, hi in bands], axis=1)


def fluctuations(a: np.ndarray) -> np.ndarray:
    a = np.asarray(a, np.float64)
    return np.fft.fft2(a - a.mean(axis=(1, 2), keepdims=True), axes=(1, 2))


@pytest.mark.parametrize("depth_m, phase", [(3.0, "henyey_greenstein"), (6.0, "petzold")])
def test_small_angle_map_has_the_walks_spatial_spectrum(depth_m, phase):
    """configs/ocean.toml (128² over 16 m, 128² map) in coastal water, black floor: the map's power
    in each radial band of spatial frequency (6 bands, 2 cycles per patch to the Nyquist limit)
    against the random walk's — the walk's own photon noise taken out by the cross-spectrum of two
    seeds — in every rgb band. Wells's closed form (``optics.beam_spread = "wells"``) within 20 %
    everywhere (measured 0.92–1.17). The walked spread (``"walk"``, with its derivative by the local
    path) within 8 % above the two lowest bands (measured 0.93–1.02, the highest band carrying the two
    methods' different surfaces, flat facets against bilinear normals, 0.93–0.97 without any
    scattering) and within 25 % in the two lowest, scales of 4–16 m carried by a handful of Fourier
    modes where one pair of seeds scatters by 5–15 % in the 650 nm band (measured 0.97–1.18).
    ``python -m benchmarks.small_angle_vs_walk`` measures each spread's own error beyond the walk's
    noise with eight seeds (walked: 0.97–1.03 over the surfaces' factor, 1.10 in the 650 nm band's
    lowest at 6 m; Wells's: 0.92–1.09). Where the spreads differ most — the strongly absorbed 650 nm
    band at 6 m, 0.5–4 m scales (radial bands 3–5) — Wells's keeps too little (measured 0.92) and the
    walked one is within 4 % (measured 0.98–1.00). The single-scattering map scaled to the walk's
    mean misses by more than 2× at the lowest or highest band (measured 2.3–3.1× at 3 m), so the test
    tells them apart. The map's mean over the patch is the walk's, by construction (1e-5)."""
    overrides = {**SCENE, "floor.depth_m": depth_m, "optics.phase_function": phase}
    walks = [wc.render(wc.load_scene(CONFIGS / "ocean.toml", {**overrides, "optics.scattering": "multiple",
                                                              "optics.mc_seed": seed}), device="cpu")
             for seed in (1, 2)]
    m = SCENE["caustics.map_resolution"]
    cross = (fluctuations(walks[0].floor_irradiance) * np.conj(fluctuations(walks[1].floor_irradiance))).real
    reference = band_power(cross, m)
    ratios = {}
    for spread in ("wells", "walk"):
        r = wc.render(wc.load_scene(CONFIGS / "ocean.toml", {**overrides, "optics.scattering": "small_angle",
                                                             "optics.beam_spread": spread}), device="cpu")
        small = r.floor_irradiance.astype(np.float64)
        single = r.comparison.floor_irradiance.astype(np.float64)
        walk_mean = np.asarray(r.multiple_scattering_stats["floor"]) / 16.0**2
        np.testing.assert_allclose(small.mean(axis=(1, 2)), walk_mean, rtol=1e-5)
        ratios[spread] = band_power(np.abs(fluctuations(small)) ** 2, m) / reference
        assert small.min() >= 0.0
    assert np.all(np.abs(ratios["wells"] - 1.0) < 0.2), ratios
    assert np.all(np.abs(ratios["walk"][:, 2:] - 1.0) < 0.08), ratios
    assert np.all(np.abs(ratios["walk"][:, :2] - 1.0) < 0.25), ratios
    if depth_m == 6.0:
        red_mid = slice(2, 5)
        assert np.all(np.abs(ratios["walk"][2, red_mid] - 1.0) < 0.04), ratios
        assert np.all(ratios["wells"][2, red_mid] < 0.96), ratios
    scaled = single * (walk_mean / single.mean(axis=(1, 2)))[:, None, None]
    single_ratio = band_power(np.abs(fluctuations(scaled)) ** 2, m) / reference
    assert np.all(np.maximum(single_ratio.max(axis=1), 1 / single_ratio.min(axis=1)) > 2.0), single_ratio


@pytest.mark.parametrize("model", ["fft", "flat"])
def test_the_coarse_map_of_the_patch_keeps_every_pass_flux(model):
    """The whole patch's coarse map beside a window (``kernels/caustics/coarse.py``): every quad's
    flux lands on it, so its sum is the pass's triangle fluxes summed in float64 (1e-9), and under
    still water, where the floor hits are the surface's lattice shifted, a whole number of cells per
    coarse texel makes it uniform to the float32 hits' rounding (a bilinear weight from a texel
    coordinate up to 64 carries ~4e-6; measured 3.8e-6)."""
    overrides = {"water.model": model, "optics.scattering": "small_angle", "optics.mc_samples": 1,
                 "caustics.map_extent_m": 2.0, "caustics.map_resolution": 32}
    scene = wc.load_scene(CONFIGS / "ocean.toml", {**SCENE, **overrides})
    renderer = wc.Renderer(scene, device="cpu")
    renderer.render(0.5)
    floor = renderer.method.floor
    coarse = floor.coarse.numpy()
    assert coarse.shape == (64, 64, 3)  # 16 m / (2 m / 8) texels, 2 cells each
    flux = floor.flux.numpy().astype(np.float64).sum(axis=(0, 1, 2))
    np.testing.assert_allclose(coarse.sum(axis=(0, 1)), flux, rtol=1e-9)
    if model == "flat":
        np.testing.assert_allclose(coarse / coarse.mean(axis=(0, 1)), 1.0, atol=1e-5)


def test_small_angle_errors_are_one_line():
    """The small-angle mode takes its mean from the random walk, so it runs where the walk runs."""
    with pytest.raises(ConfigError, match="small_angle"):
        wc.load_scene(None, {"optics.scattering": "small_angle", "caustics.method": "beams"})
    with pytest.raises(ConfigError, match="periodic sea"):
        wc.load_scene(CONFIGS / "pool.toml", {"optics.scattering": "small_angle"})
    with pytest.raises(ConfigError, match="optics.beam_spread = \"walk\" is how"):
        wc.load_scene(None, {"optics.beam_spread": "walk"})


def test_a_window_agrees_with_the_whole_map():
    """A 4 m window of the 16 m sea (texels as the whole map's): its scattered light takes the
    scales above two coarse texels (4 m / 8) from the whole patch, the rest from the window taken as
    periodic. Against the same texels of the whole map: relative L1 within 1 % (measured 0.5 %;
    1.6 % when the whole window was taken as periodic) and CV within 1 % (measured 0.4–0.6 %)."""
    base = {**SCENE, "optics.mc_samples": 4, "floor.depth_m": 3.0, "optics.scattering": "small_angle"}
    whole = wc.render(wc.load_scene(CONFIGS / "ocean.toml", base), device="cpu").floor_irradiance
    window = wc.render(wc.load_scene(CONFIGS / "ocean.toml", {**base, "caustics.map_resolution": 32,
                                                            "caustics.map_extent_m": 4.0,
                                                            "caustics.map_center_m": [4.0, -2.0]}),
                       device="cpu").floor_irradiance.astype(np.float64)
    part = whole[:, 32:64, 80:112].astype(np.float64)  # rows from y = −4 m, columns from x = 2 m
    assert np.abs(window - part).sum() / np.abs(part).sum() < 0.01
    cv = window.std(axis=(1, 2)) / window.mean(axis=(1, 2))
    np.testing.assert_allclose(cv, part.std(axis=(1, 2)) / part.mean(axis=(1, 2)), rtol=0.01)


DEEP = {"floor.depth_m": 9.58, "water.resolution": 256, "stats.collector_mm": 0.0, "sky.model": "none",
        "sky.diffuse_fraction": 0.0, "sun.angular_diameter_deg": 0.0, "optics.wavelengths": [532.0]}
"""Darecki et al. (2011)'s water at 9.58 m under a point sun, its 32 m sea on 256² cells (t = 10 s)."""


@pytest.fixture(scope="module")
def deep_sea():
    """(the whole patch's map, its single-scattering map) of :data:`DEEP` on 128² texels of 25 cm."""
    whole = wc.render(wc.load_scene(CONFIGS / "field" / "darecki2011.toml",
                                    {**DEEP, "caustics.map_extent_m": 0.0, "caustics.map_resolution": 128}),
                      time_s=10.0, device="cpu")
    return (whole.floor_irradiance[0].astype(np.float64),
            whole.comparison.floor_irradiance[0].astype(np.float64))


def deep_window(side_m: float, cx: float, cy: float) -> tuple[np.ndarray, tuple[slice, slice]]:
    """(the map of a window of :data:`DEEP` on texels of the whole map's 25 cm, (rows, columns) of the
    same ground on the whole map)."""
    where = {"caustics.map_extent_m": side_m, "caustics.map_resolution": round(side_m * 4),
             "caustics.map_center_m": [float(cx), float(cy)]}
    window = wc.render(wc.load_scene(CONFIGS / "field" / "darecki2011.toml", {**DEEP, **where}), time_s=10.0,
                       device="cpu").floor_irradiance[0].astype(np.float64)
    ground = tuple(slice(round((c - side_m / 2 + 16) * 4), round((c + side_m / 2 + 16) * 4))
                   for c in (cy, cx))  # 25 cm texels from −16 m
    return window, ground


def test_a_deep_window_takes_its_large_scales_from_the_whole_patch(deep_sea):
    """Darecki et al. (2011)'s water at 9.58 m (b z ≈ 5.7: almost all the light scattered, spread over
    metres): 2 m windows of the 32 m sea (256² cells) at four places against the same texels of the
    whole patch's map (25 cm texels). The window's light must come from the sea around it: the
    single-scattering light of these windows is 0.68–1.20× the patch's mean, the whole map's
    0.89–1.08×, and the window taken as periodic (before 2026-12-05) kept the window's own swing,
    0.77–1.15× the whole map's with 12–23 % L1. Now each window is within 2.5 % of the whole map
    in the mean (measured 0.4–1.6 %) and 3 % in L1 (0.4–1.6 %)."""
    full, single = deep_sea
    swings = []
    for cx, cy in ((0, 0), (7, -5), (-9, 11), (13, 3)):
        window, ground = deep_window(2.0, cx, cy)
        part = full[ground]
        assert abs(window.mean() / part.mean() - 1.0) < 0.025, (cx, cy)
        assert np.abs(window - part).sum() / part.sum() < 0.03, (cx, cy)
        swings.append(single[ground].mean() / single.mean())
    assert max(abs(s - 1.0) for s in swings) > 0.2  # the windows' own light swings: the test can tell


def test_a_window_two_coarse_texels_wide_keeps_the_whole_maps_mean(deep_sea):
    """The same water and sea with 0.5 m windows (two 25 cm texels), whose coarse texels (two
    cells, 25 cm) are half the window: the coarse map read bilinearly misses the window's own light
    by 5–19 %, and the window's detail taken as periodic would spread that miss by the transfer's
    whole weight (its k = 0 value, about 440 here): 0.91–1.00× the whole map's mean over the same
    ground (up to 9 % L1) when it did. With the detail's mean left out of its transfer each window
    is within 1 % of the whole map (measured 0.998–1.004, L1 ≤ 0.5 %)."""
    full, _ = deep_sea
    for cx, cy in ((7.25, -4.75), (-8.75, 11.25), (-3.75, -9.75), (5.25, 5.25)):
        window, ground = deep_window(0.5, cx, cy)
        part = full[ground]
        assert abs(window.mean() / part.mean() - 1.0) < 0.01, (cx, cy, window.mean() / part.mean())
        assert np.abs(window - part).sum() / part.sum() < 0.01, (cx, cy)


@pytest.mark.parametrize("elevation_deg", [5.0, 50.0])
def test_the_patchs_coarse_map_has_the_whole_maps_window_means(elevation_deg):
    """A 1 m window of the Gernez sea (8 m, 128² cells; its sun, sky in cones and small-angle
    scattered light): the whole patch's coarse map (RenderResult.coarse_floor_irradiance, the
    transfer's and the cones' large scales, with the scattered light added as the window's map has
    it) against a render of the whole patch on texels as coarse: the means over the 64 squares the
    window's size agree each within 3 % (measured 2.6 % at a 5° sun, 1.0 % at 50°), their CV within
    3 % (1.7 %, 0.0 %), the sky's part within 1 % (0.1 %), and the patch's mean to 1e-6."""
    from warpcaustics.batch.stats import frame_statistics

    base = {"water.resolution": 128, "sun.elevation_deg": elevation_deg, "sky.diffuse_fraction": 0.5,
            "sky.directions": 4, "sun.disk_samples": 4}
    scene = CONFIGS / "field" / "gernez2009.toml"
    window = wc.load_scene(scene, {**base, "caustics.map_resolution": 64})
    result = wc.render(window, device="cpu")
    patch = {**base, "caustics.map_extent_m": 0.0, "caustics.map_resolution": 64}
    whole = wc.render(wc.load_scene(scene, patch), device="cpu")

    def squares(a):
        return a[0].astype(np.float64).reshape(8, 8, 8, 8).mean(axis=(1, 3))

    coarse, direct = squares(result.coarse_floor_irradiance), squares(whole.floor_irradiance)
    assert np.abs(coarse / direct - 1.0).max() < 0.03
    assert coarse.std() / coarse.mean() == pytest.approx(direct.std() / direct.mean(), rel=0.03)
    assert coarse.mean() == pytest.approx(direct.mean(), rel=1e-6)
    sky = squares(result.coarse_sky_floor_irradiance) / squares(whole.sky_floor_irradiance)
    assert np.abs(sky - 1.0).max() < 0.01
    stats = frame_statistics(result, window.config.stats)["irradiance_w_m2"]["patch_windows"]
    assert stats["count"] == 64 and stats["cv"] == pytest.approx(coarse.std() / coarse.mean(), rel=1e-6)


def test_refracted_paths_follow_snells_law_at_the_local_slope():
    """``SmallAngleScattering.refracted_paths`` (the walked spread's path of each texel's light): on a
    sinusoidal sea (4 m waves, slope up to 0.16) under a sun 40° from the zenith along the waves,
    each texel's path equals (D + h)/cos(θ_t − α) from the angles in float64 — α = atan(h′) the
    facet's tilt, θ_t = asin(sin(θ_sun + α)/n) the refraction from its normal — at the still-water
    entry point, within 1e-4 relative (the slopes are central differences of 1 cm cells: (k dx)²/6
    = 4e-5); on still water it is the mean path D/cos θ_w."""
    from warpcaustics.caustics.small_angle import SmallAngleScattering

    cfg = wc.load_scene(CONFIGS / "ocean.toml", {**SCENE, "optics.scattering": "small_angle",
                                                 "floor.depth_m": 3.0}).config
    ior, n, extent, amp = 1.34, 1600, 16.0, 0.1
    sa = SmallAngleScattering(cfg, ior, np.full(3, 0.1), np.full(3, 0.2))
    centres = (np.arange(n) + 0.5) * extent / n - 0.5 * extent
    k = 2.0 * np.pi * 4 / extent
    zenith = math.radians(40.0)
    light = np.array([math.sin(zenith), 0.0, math.cos(zenith)])
    down, path = sa.beam(light)
    x = np.linspace(-7.0, 7.0, 57)
    y = np.zeros_like(x)
    sa.reset(np.zeros((n, n)))
    np.testing.assert_allclose(sa.refracted_paths(light, down, x, y), path, rtol=1e-12)
    sa.reset(np.tile(amp * np.cos(k * centres), (n, 1)))
    entry = x - down[0] * 3.0 / -down[2]
    h, slope = amp * np.cos(k * entry), -amp * k * np.sin(k * entry)
    tilt = np.arctan(slope)
    refracted = np.arcsin(np.sin(zenith + tilt) / ior)
    expected = (3.0 + h) / np.cos(refracted - tilt)
    np.testing.assert_allclose(sa.refracted_paths(light, down, x, y), expected, rtol=1e-4)
