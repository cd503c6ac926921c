"""Multiple scattering (optics.scattering = "multiple"): a random walk that accounts for every watt."""

import math

import numpy as np
import pytest
import warp as wp
from scipy import integrate

import warpcaustics as wc
from warpcaustics.batch.stats import cv_without_noise
from warpcaustics.caustics.multiple import MultipleScattering, balance
from warpcaustics.errors import ConfigError
from warpcaustics.kernels.caustics import multiple as mc_kernels

from helpers import CONFIGS, fresnel_t_angles

BASE = {
    "water.model": "flat",
    "water.extent_m": 4.0,
    "water.resolution": 32,
    "caustics.map_resolution": 32,
    "optics.wavelengths": "rgb",
    "floor.depth_m": 3.0,
    "optics.water_type": "turbid_harbor",
    "optics.scattering": "multiple",
    "optics.mc_samples": 8,
}


def test_walk_without_absorption_conserves_energy():
    """Scattering but no absorption (b = 0.5, 1, 2 /m): every watt that enters the water reaches the
    floor, escapes upwards or is stopped after mc_max_events — the tallies close to float32 rounding
    of the weights (1e-6), nothing is absorbed, and the floor map holds the floor tally."""
    scene = wc.load_scene(None, BASE)
    renderer = wc.Renderer(scene, device="cpu")
    surface = renderer.water.at(0.0)
    visible = renderer.visible
    visible.fill_(1.0)
    walk = MultipleScattering(
        scene.config,
        scene.sun_direction,
        1.333,
        renderer.sun_irradiance,
        np.zeros(3),
        np.array([0.5, 1.0, 2.0]),
        "cpu",
    )
    floor, st = walk.run(surface, visible)
    assert np.all(np.array(st["absorbed"]) == 0.0)
    closing = balance(st)
    np.testing.assert_allclose(closing, 1.0, atol=1e-6)
    np.testing.assert_allclose(floor.sum(axis=(1, 2)) * walk.texel_area_m2, st["floor"], rtol=1e-5)
    assert np.all(np.array(st["escaped"]) > 0.0)  # some light is scattered back up


def test_unscattered_part_follows_beer_lambert():
    """The photons that reach the floor without scattering carry e^{−cD/cosθt} of the transmitted
    flux, within 4σ of the binomial noise of 3·32²·64 equal-weight photons; the random walk's
    tallies close (1e-6)."""
    r = wc.render(wc.load_scene(None, BASE), device="cpu")
    st = r.multiple_scattering_stats
    t = np.array(st["transmitted"])
    fraction = np.array(st["unscattered"]) / t
    theta_t = math.asin(math.sin(math.radians(30.0)) / 1.333)
    expected = np.exp(-r.attenuation_per_m * 3.0 / math.cos(theta_t))
    photons = st["photons"] / 3
    sigma = np.sqrt(expected * (1 - expected) / photons)
    assert np.all(np.abs(fraction - expected) < 4 * sigma)
    closing = balance(st)
    np.testing.assert_allclose(closing, 1.0, atol=1e-6)


def contrast_without_noise(scene_overrides: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(CV single, CV multiple, mean multiple / mean single) per band: the random walk run with two
    seeds, its photon noise (the variance of their difference / 2) taken out of the variance of
    their mean."""
    maps = []
    for seed in (1, 2):
        r = wc.render(
            wc.load_scene(CONFIGS / "ocean.toml", {"sun.angular_diameter_deg": 0.0, **scene_overrides,
                                                 "optics.mc_seed": seed}), device="cpu"
        )
        maps.append(r.floor_irradiance.astype(np.float64))
    single = r.comparison.floor_irradiance.astype(np.float64)
    mean, cv_multi = cv_without_noise(maps[0], maps[1], axis=(1, 2))
    cv_single = single.std(axis=(1, 2)) / single.mean(axis=(1, 2))
    return cv_single, cv_multi, mean.mean(axis=(1, 2)) / single.mean(axis=(1, 2))


def test_multiple_scattering_brightens_and_smooths_the_floor():
    """Over an ocean in coastal water at 3 m, light scattered out of the beam still reaches the
    floor: more irradiance than single scattering, and less caustic contrast once the walk's own
    photon noise is taken out (two seeds)."""
    cv_single, cv_multi, gain = contrast_without_noise(
        {
            "water.resolution": 64,
            "caustics.map_resolution": 32,
            "optics.wavelengths": "rgb",
            "optics.water_type": "coastal_ocean",
            "floor.depth_m": 3.0,
            "optics.scattering": "multiple",
            "optics.mc_samples": 4,
        }
    )
    assert np.all(gain > 1.0)
    assert np.all(cv_multi < cv_single)


def test_multiple_scattering_errors_are_one_line():
    """The random walk runs on flux-ratio scenes of a periodic sea only: anything else says so."""
    with pytest.raises(ConfigError, match="optics.scattering"):
        wc.load_scene(None, {**BASE, "caustics.method": "beams"})
    with pytest.raises(ConfigError, match="periodic sea"):
        wc.load_scene(CONFIGS / "pool.toml", {"optics.scattering": "multiple"})


def test_the_walk_into_a_window_fills_the_whole_maps_texels():
    """A floor-map window (8 m of a 16 m sea, centred at (4, −2) m, texels half the whole map's):
    the same photons land in the same places, so each 2×2 block of window texels averages to the
    whole map's texel there (1e-5, float32 sums), and every watt on the floor is tallied alike."""
    base = {"water.resolution": 32, "optics.wavelengths": "rgb", "optics.water_type": "coastal_ocean",
            "floor.depth_m": 3.0, "optics.scattering": "multiple", "caustics.map_resolution": 32}
    whole = wc.render(wc.load_scene(CONFIGS / "ocean.toml", base), device="cpu")
    window = wc.render(wc.load_scene(CONFIGS / "ocean.toml", {**base, "caustics.map_extent_m": 8.0,
                                                            "caustics.map_center_m": [4.0, -2.0]}),
                       device="cpu")
    blocks = window.floor_irradiance.reshape(3, 16, 2, 16, 2).mean(axis=(2, 4))
    part = whole.floor_irradiance[:, 4:20, 16:32]  # rows from y = −6 m, columns from x = 0 m
    np.testing.assert_allclose(blocks, part, rtol=1e-5, atol=1e-6 * part.max())
    floor = whole.multiple_scattering_stats["floor"]
    assert window.multiple_scattering_stats["floor"] == pytest.approx(floor, rel=1e-12)


def sky_walker(scene, renderer, absorption: np.ndarray, scattering: np.ndarray) -> MultipleScattering:
    """A walk of ``scene``'s sky, each direction carrying its share of the sky's irradiance."""
    dirs, shares = scene.sky_directions()
    e_sky = scene.sky_irradiance(renderer.sun_irradiance)
    return MultipleScattering(scene.config, scene.sun_direction, 1.333, renderer.sun_irradiance, absorption,
                              scattering, "cpu", sky_dirs=dirs, sky_irradiance=shares[:, None] * e_sky)


def sky_walk(absorption: np.ndarray, scattering: np.ndarray, depth_m: float = 2.0):
    """The sky's walk alone over still water, uniform sky, every crest lit: (scene, walk, floor,
    tallies, E_sky per band)."""
    scene = wc.load_scene(None, {**BASE, "floor.depth_m": depth_m, "sky.model": "uniform",
                                 "sky.diffuse_fraction": 0.3})
    renderer = wc.Renderer(scene, device="cpu")
    e_sky = scene.sky_irradiance(renderer.sun_irradiance)
    walk = sky_walker(scene, renderer, absorption, scattering)
    visible = renderer.light.sky_visible
    visible.fill_(1.0)
    floor, st = walk.run_sky(renderer.water.at(0.0), visible)
    return scene, walk, floor, st, e_sky


def uniform_sky_on_floor(e_sky: float, c: float, depth_m: float) -> float:
    """∫ (E_sky/π) cosθ T(θ) e^{−cD/cosθt} dΩ over a uniform sky (float64 quadrature, Fresnel in
    angle form) [W m⁻² nm⁻¹]."""

    def integrand(theta):
        t = fresnel_t_angles(np.array([theta]), 1.0, 1.333)[0]
        theta_t = math.asin(math.sin(theta) / 1.333)
        return math.cos(theta) * math.sin(theta) * t * math.exp(-c * depth_m / math.cos(theta_t))

    return e_sky / math.pi * 2 * math.pi * integrate.quad(integrand, 0.0, math.pi / 2, limit=200)[0]


def test_walk_of_a_uniform_sky_over_still_water_is_the_analytic_integral():
    """The sky's photons (64 directions taken in turn) in clear water without scattering: the floor
    receives the analytic integral over the sky — within 1e-3 (the directions' quadrature; measured
    6e-4 for the flux-ratio map) with no absorption, and within that plus 4σ of the photons'
    Beer–Lambert noise with absorption (a = 0.1, 0.3, 0.6 /m, whose photons are absorbed at their
    first interaction); the tallies close (1e-6)."""
    for absorption in (np.zeros(3), np.array([0.1, 0.3, 0.6])):
        _, walk, floor, st, e_sky = sky_walk(absorption, np.zeros(3))
        t = np.array(st["transmitted"])
        reached = np.array(st["floor"]) / t
        photons = st["photons"] / 3
        for k, a in enumerate(absorption):
            expected = uniform_sky_on_floor(e_sky[k], a, 2.0)
            sigma = math.sqrt(max(reached[k] * (1.0 - reached[k]), 0.0) / photons)
            assert floor[k].mean() == pytest.approx(expected, rel=1e-3 + 4 * sigma / reached[k])
        closing = balance(st)
        np.testing.assert_allclose(closing, 1.0, atol=1e-6)
        assert np.all(np.array(st["unscattered"]) == np.array(st["floor"]))


def test_sky_walk_without_absorption_conserves_energy():
    """The sky's photons scatter (b = 0.5, 1, 2 /m) but nothing is absorbed: every watt of skylight
    that enters the water reaches the floor, escapes or is stopped (1e-6)."""
    _, walk, floor, st, _ = sky_walk(np.zeros(3), np.array([0.5, 1.0, 2.0]))
    assert np.all(np.array(st["absorbed"]) == 0.0)
    closing = balance(st)
    np.testing.assert_allclose(closing, 1.0, atol=1e-6)
    np.testing.assert_allclose(floor.sum(axis=(1, 2)) * walk.texel_area_m2, st["floor"], rtol=1e-5)
    assert np.all(np.array(st["escaped"]) > 0.0)


def test_render_walks_the_sky_apart_from_the_sun():
    """A render with a sky and the random walk: the sun's part is the sun-only walk (the same
    photons: 1e-5 of the peak, float32 sums; measured 9e-8), the sky's is walked with its own
    photons and tallies, which close (1e-6), and the skylight entering the water is Fresnel's
    share of it (1e-5)."""
    sky = {"sky.model": "uniform", "sky.diffuse_fraction": 0.3, "sky.directions": 16}
    sun_only = wc.render(wc.load_scene(None, BASE), device="cpu")
    r = wc.render(wc.load_scene(None, {**BASE, **sky}), device="cpu")
    np.testing.assert_allclose(r.floor_irradiance - r.sky_floor_irradiance, sun_only.floor_irradiance,
                               rtol=1e-5, atol=1e-6 * sun_only.floor_irradiance.max())
    st = r.multiple_scattering_stats
    sky_st = st["sky"]
    t = np.array(sky_st["transmitted"])
    closing = balance(sky_st)
    np.testing.assert_allclose(closing, 1.0, atol=1e-6)
    # skylight entering still water: the patch's area × E_sky × the mean Fresnel transmittance over
    # the 16 cosine-weighted directions
    dirs, _ = r.scene.sky_directions()
    e_sky = r.scene.sky_irradiance(r.sun_irradiance)
    fresnel = fresnel_t_angles(np.arccos(dirs[:, 2]), 1.0, 1.333).mean()
    np.testing.assert_allclose(t, 4.0**2 * e_sky * fresnel, rtol=1e-5)
    np.testing.assert_allclose(np.array(st["transmitted"]) + t, r.transmitted_flux_w_nm, rtol=1e-12)
    np.testing.assert_allclose(r.sky_floor_irradiance.sum(axis=(1, 2)) * r.texel_area_m2, sky_st["floor"],
                               rtol=1e-5)


def test_sky_walk_shades_each_direction_by_its_own_crests():
    """The sky's photons read the shading of their own direction: with every direction shaded out
    but one (still water, 8 directions), exactly that direction's skylight enters the water —
    the patch's area × E_sky T(θ)/8, Fresnel in angle form (1e-5) — for each of three directions."""
    scene = wc.load_scene(None, {**BASE, "sky.model": "uniform", "sky.diffuse_fraction": 0.3,
                                 "sky.directions": 8})
    renderer = wc.Renderer(scene, device="cpu")
    e_sky = scene.sky_irradiance(renderer.sun_irradiance)
    dirs, _ = scene.sky_directions()
    walk = sky_walker(scene, renderer, np.zeros(3), np.zeros(3))
    surface = renderer.water.at(0.0)
    theta = np.arccos(dirs[:, 2])
    for lit in (0, 3, 7):
        shading = np.zeros((8, 32, 32), np.float32)
        shading[lit] = 1.0
        _, st = walk.run_sky(surface, wp.array(shading, dtype=wp.float32, device="cpu"))
        expected = 4.0**2 * e_sky * fresnel_t_angles(theta[lit : lit + 1], 1.0, 1.333)[0] / 8
        np.testing.assert_allclose(st["transmitted"], expected, rtol=1e-5)


@pytest.mark.parametrize(("light", "threshold"), [("sky", 0.05), ("disk", 0.03)])
def test_no_direction_is_tied_to_a_part_of_every_cell(light, threshold):
    """The photons of a cell take the directions (16 of the sky, or of the sun's disk) in turn
    from a random start per cell, so the expected map carries no fixed pattern: over still water,
    without scattering or absorption, two seeds' maps (texels half a cell) vary independently —
    the correlation of their deviations stays within ~4σ of 0 for 12 288 texels (measured 0.01;
    0.70 and 0.06 when each direction always took the same sub-cell)."""
    overrides = {**BASE, "water.resolution": 32, "caustics.map_resolution": 64, "floor.depth_m": 2.0}
    if light == "sky":
        overrides.update({"sky.model": "uniform", "sky.diffuse_fraction": 0.3, "sky.directions": 16})
    else:
        overrides.update({"sun.angular_diameter_deg": 0.53, "sun.disk_samples": 16})
    deviations = []
    for seed in (1, 2):
        scene = wc.load_scene(None, {**overrides, "optics.mc_seed": seed})
        renderer = wc.Renderer(scene, device="cpu")
        surface = renderer.water.at(0.0)
        if light == "sky":
            walk = sky_walker(scene, renderer, np.zeros(3), np.zeros(3))
            renderer.light.sky_visible.fill_(1.0)
            floor, _ = walk.run_sky(surface, renderer.light.sky_visible)
        else:
            walk = MultipleScattering(scene.config, renderer.light.sun_directions, 1.333,
                                      renderer.sun_irradiance,
                                      np.zeros(3), np.zeros(3), "cpu")
            renderer.visible.fill_(1.0)
            floor, _ = walk.run(surface, renderer.visible)
        floor = floor.astype(np.float64)
        deviations.append(floor - floor.mean(axis=(1, 2), keepdims=True))
    a, b = deviations
    assert abs((a * b).sum() / np.sqrt((a * a).sum() * (b * b).sum())) < threshold


@wp.kernel
def _map_texels(walk: mc_kernels.Walk, xs: wp.array[wp.float32], m: int, out: wp.array[wp.int32]):
    i = wp.tid()
    out[i] = mc_kernels.map_texel(xs[i], walk.map_center[0], walk, m)


@pytest.mark.parametrize(("extent_m", "m"), [(3.7, 96), (5.3, 100), (12.0, 500)])
def test_the_walk_keeps_photons_at_the_seam_on_the_whole_map(extent_m, m):
    """On the whole periodic map every landing point has a texel, also the float32 neighbours of the
    seam at ±L/2 that round onto its far edge (before the fix, 1–2 of these 6000 points per patch
    were dropped from the map while the tally counted them). A window still drops what is
    outside it."""
    walk = mc_kernels.Walk()
    walk.extent_m = extent_m
    walk.map_extent_m = extent_m
    walk.map_scale = m / extent_m
    walk.map_center = wp.vec2(0.0, 0.0)
    xs = []
    for edge in (0.5 * extent_m, -0.5 * extent_m):
        for way in (-np.inf, np.inf):
            x = np.float32(edge)
            for _ in range(1500):
                xs.append(x)
                x = np.nextafter(x, np.float32(way))
    xs = wp.array(np.array(xs, np.float32), dtype=wp.float32)
    out = wp.zeros(xs.shape[0], dtype=wp.int32)
    wp.launch(_map_texels, dim=xs.shape[0], inputs=[walk, xs, m], outputs=[out], device="cpu")
    texels = out.numpy()
    assert texels.min() == 0 and texels.max() == m - 1
    walk.map_extent_m = 0.25 * extent_m  # a window about the origin: the seam is outside it
    walk.map_scale = m / walk.map_extent_m
    wp.launch(_map_texels, dim=xs.shape[0], inputs=[walk, xs, m], outputs=[out], device="cpu")
    assert np.all(out.numpy() == -1)


def test_russian_roulette_ends_long_paths_without_bias():
    """Turbid, absorbing water and a walk allowed 10,000 events: every photon ends (nothing is
    truncated), the floor map holds no float32 subnormal, the books close (1e-6), and the roulette
    tally — the weight of the photons it ended less what its survivors gained, zero in expectation —
    stays within 4σ of zero: each photon's term is at most its roulette weight, 1/64 of its start,
    so σ ≤ max start / 64 × √photons, with a start at most twice the mean (Fresnel and cos θ vary
    little over this sea)."""
    from helpers import subnormal_count

    scene = wc.load_scene(None, {**BASE, "optics.water_type": "turbid_harbor", "optics.mc_max_events": 10000})
    r = wc.render(scene, device="cpu")
    st = r.multiple_scattering_stats
    t = np.array(st["transmitted"])
    closing = balance(st)
    np.testing.assert_allclose(closing, 1.0, atol=1e-6)
    assert np.all(np.array(st["truncated"]) == 0.0)
    assert subnormal_count(r.floor_irradiance) == 0
    photons = st["photons"] / 3
    bound = 4.0 * 2.0 / (64.0 * math.sqrt(photons))
    assert np.all(np.abs(np.array(st["roulette"])) / t < bound), (np.array(st["roulette"]) / t, bound)
