"""Light through glass receivers and off mirrors (``caustics.bounces``, Liktor & Dachsbacher 2011 §6):
the flat slab's analytic lateral shift and Fresnel losses, the flux balance over every bounce, and
the errors."""

import math

import numpy as np
import pytest

import warpcaustics as wc
from warpcaustics.errors import ConfigError

from helpers import CONFIGS, fresnel_t_angles

N_WATER = 1.333
N_GLASS = 1.5
SLAB = {"mesh": "cube", "scale": [3.6, 3.6, 0.5], "translate_m": [0.0, 0.0, -0.8], "ior": N_GLASS}
"""A glass slab 0.5 m thick, its top 0.55 m under the water, over most of the pool."""


def _pool(receivers, bounces, **extra):
    return wc.load_scene(None, {
        "caustics.method": "photons", "water.model": "pool", "water.extent_m": 4.0, "water.resolution": 32,
        "floor.depth_m": 2.0, "optics.ior": N_WATER, "optics.water_type": "none", "optics.wavelengths": "rgb",
        "sun.elevation_deg": 30.0, "sun.azimuth_deg": 0.0, "sun.angular_diameter_deg": 0.0,
        "caustics.photon_subdivisions": 2, "caustics.map_resolution": 64, "caustics.bounces": bounces,
        "receivers": receivers, **extra})


def _photons(scene):
    renderer = wc.Renderer(scene, "cpu")
    result = renderer.render(0.0)
    return result, renderer.method.caustics[0]


def test_a_glass_slab_shifts_every_photon_by_the_analytic_offset():
    """Still water, sun 30° high: light runs at θ_w in the water and θ_g in the glass (Snell), so a
    slab of thickness t moves every photon that crosses it by t (tan θ_w − tan θ_g) along the light's
    horizontal direction, backwards (float64 here; 0.0737 m), and keeps T_wg(θ_w) T_gw(θ_g) of its
    flux (exact Fresnel at both faces); nothing else changes."""
    _, plain = _photons(_pool([], 1))
    _, glass = _photons(_pool([SLAB], 2))
    theta_air = math.radians(60.0)
    sin_w = math.sin(theta_air) / N_WATER
    sin_g = math.sin(theta_air) / N_GLASS
    theta_w, theta_g = math.asin(sin_w), math.asin(sin_g)
    shift = 0.5 * (math.tan(theta_w) - math.tan(theta_g))
    hit0, hit1 = plain.hit.numpy().astype(np.float64), glass.hit.numpy().astype(np.float64)
    landed = (plain.face.numpy() >= 0) & (glass.face.numpy() >= 0)
    # photons whose straight path crosses the slab well inside its faces
    through = landed & (np.abs(hit0[:, 0]) < 0.5) & (np.abs(hit0[:, 1]) < 1.0)
    assert through.sum() > 400
    expected = np.broadcast_to([shift, 0.0, 0.0], (through.sum(), 3))
    np.testing.assert_allclose(hit1[through] - hit0[through], expected, atol=2e-5)
    t_in = fresnel_t_angles(np.array([theta_w]), N_WATER, N_GLASS)[0]
    t_out = fresnel_t_angles(np.array([theta_g]), N_GLASS, N_WATER)[0]
    ratio = glass.carried.numpy()[through] / glass.weight.numpy()[through]
    np.testing.assert_allclose(ratio, t_in * t_out, rtol=1e-5)
    assert 0.98 < t_in * t_out < 1.0


@pytest.mark.parametrize("receiver", [
    {"mesh": "sphere", "scale": 0.6, "translate_m": [0.0, 0.0, -0.8], "ior": N_GLASS},
    {"mesh": "cube", "scale": [1.2, 1.2, 0.05], "rotate_deg": [0.0, 35.0, 0.0],
     "translate_m": [0.3, 0.0, -1.0], "specular": True},
], ids=["glass-sphere", "mirror"])
def test_flux_is_kept_over_every_bounce(receiver):
    """No absorption: the flux entering the water equals what lands on the floor and the walls
    plus what the bounces left behind (reflected at glass faces, beyond the bounce limit, trapped
    by total internal reflection, or sent where no receiver is), per band (1e-4)."""
    result, _ = _photons(_pool([receiver], 2, **{"sun.elevation_deg": 65.0}))
    s = result.photon_stats
    left = s["reflected_w_nm"] + s["beyond_limit_w_nm"] + s["trapped_w_nm"] + s["missed_w_nm"]
    landed = result.floor_flux_w_nm + result.face_flux_w_nm.sum(axis=0)
    np.testing.assert_allclose(landed + left, result.transmitted_flux_w_nm, rtol=1e-4)
    moved = s["reflected_w_nm"] if "ior" in receiver else s["missed_w_nm"]  # a mirror sends light up
    assert np.all(moved > 1e-3 * result.transmitted_flux_w_nm)


def test_one_bounce_too_few_is_tallied():
    """Two glass slabs one above the other with bounces = 2: the light through the first meets the
    second after its last bounce, so it is tallied as beyond the limit and the floor under both is
    dark; with bounces = 3 it passes both."""
    upper = dict(SLAB, scale=[3.6, 3.6, 0.2], translate_m=[0.0, 0.0, -0.5])
    lower = dict(SLAB, scale=[3.6, 3.6, 0.2], translate_m=[0.0, 0.0, -1.2])
    two, _ = _photons(_pool([upper, lower], 2, **{"sun.elevation_deg": 80.0}))
    three, _ = _photons(_pool([upper, lower], 3, **{"sun.elevation_deg": 80.0}))
    centre = slice(24, 40)
    assert two.floor_irradiance[:, centre, centre].max() == 0.0
    assert two.photon_stats["beyond_limit_w_nm"].min() > 0.5 * two.transmitted_flux_w_nm.min()
    assert three.floor_irradiance[:, centre, centre].min() > 0.0
    assert np.all(three.photon_stats["beyond_limit_w_nm"] == 0.0)


def test_two_sided_config_renders_the_sphere_s_caustic():
    """configs/two_sided.toml: the glass sphere focuses light into a bright spot on the floor under
    it (the sun is near the zenith), brighter than anywhere else."""
    scene = wc.load_scene(CONFIGS / "two_sided.toml", {"water.resolution": 48, "caustics.map_resolution": 96,
                                                        "camera.enabled": False, "optics.wavelengths": "rgb"})
    result = wc.render(scene, device="cpu")
    floor = result.floor_irradiance[1]
    j, i = np.unravel_index(np.argmax(floor), floor.shape)
    x = (np.array([i, j]) + 0.5) * 4.0 / 96 - 2.0
    assert np.hypot(*(x - np.array([0.0, 0.0]))) < 0.5  # under the sphere (its centre at the origin)
    assert floor.max() > 5.0 * np.median(floor)


@pytest.mark.parametrize(("overrides", "match"), [
    ({"caustics.method": "fluxratio", "receivers": []}, "caustics.bounces = 2 is implemented for"),
    ({"caustics.intersection": "newton"}, "caustics.bounces = 2 is implemented for"),
    ({"receivers": [{"mesh": "sphere", "translate_m": [0.0, 0.0, -1.0]}]}, "has nothing to bounce off"),
    ({"caustics.bounces": 1}, r"receivers\[0\].ior needs caustics.bounces"),
    ({"receivers": [dict(SLAB, specular=True)]}, r"receivers\[0\] sets both ior and specular"),
])
def test_bounce_errors(overrides, match):
    with pytest.raises(ConfigError, match=match):
        wc.load_scene(None, {"caustics.method": "photons", "water.model": "pool", "water.resolution": 16,
                             "receivers": [SLAB], "caustics.bounces": 2, **overrides})
