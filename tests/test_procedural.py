"""GPU Gems ch. 2 procedural octave waves: heights, analytic gradient, statelessness, an open patch."""

import numpy as np
import pytest

import warpcaustics as wc
from warpcaustics.errors import ConfigError
from warpcaustics.water import ProceduralWater

from helpers import CONFIGS

PARAMS = dict(amplitude=0.01, frequency=10.0, factor=1.0, speed_rad_s=2.0, octaves=4)


def chapter_wave(x, y, t, *, amplitude, frequency, factor, speed_rad_s, octaves, scale_m):
    """float64 transcription of the chapter's ``wave(x, y, timer)`` in unit coordinates x/ℓ, scaled
    back to metres (written from the chapter, independently of kernels/water/procedural.py)."""
    u, v = np.asarray(x, np.float64) / scale_m, np.asarray(y, np.float64) / scale_m
    d = np.sqrt(u * u + v * v)
    z = np.zeros_like(u)
    f = factor
    for _ in range(octaves):
        z -= f * np.cos(t * speed_rad_s + (1.0 / f) * u * v * frequency)
        f /= 2.0
    return scale_m * 2.0 * amplitude * d * z


def test_heights_match_the_chapter_function(device):
    """Vertex heights equal a float64 transcription of the chapter's wave() at the cell centres."""
    n, extent = 128, 4.0
    water = ProceduralWater(n, extent, device, **PARAMS)
    surface = water.at(0.37)
    p = surface.positions.numpy().astype(np.float64)
    x = (np.arange(n) + 0.5) * extent / n - extent / 2
    xs, ys = np.meshgrid(x, x)
    np.testing.assert_allclose(p[..., 0], xs, atol=1e-6)
    np.testing.assert_allclose(p[..., 1], ys, atol=1e-6)
    ref = chapter_wave(xs, ys, 0.37, scale_m=extent / 2, **PARAMS)
    assert np.abs(ref).max() > 0.02  # real waves, not a flat sheet
    # float32 phases up to W·16 ≈ 160 rad: ~1e-5 rad of rounding times heights of ~0.1 m
    np.testing.assert_allclose(p[..., 2], ref, atol=2e-5)
    assert not surface.periodic


@pytest.mark.parametrize("time_s", [0.0, 1.3])
def test_analytic_gradient_matches_finite_differences(device, time_s):
    """The analytic gradient (the chapter's gradwave) gives the same normals as central differences
    of the float64 heights with a step of 1e-5 m (O(h²) error ≪ the 1e-4 tolerance), away from the
    cone point at the origin."""
    n, extent = 64, 4.0
    scale = 1.5
    water = ProceduralWater(n, extent, device, scale_m=scale, **PARAMS)
    surface = water.at(time_s)
    p = surface.positions.numpy().astype(np.float64)
    xs, ys = p[..., 0], p[..., 1]
    h = 1e-5
    wave = lambda x, y: chapter_wave(x, y, time_s, scale_m=scale, **PARAMS)  # noqa: E731
    gx = (wave(xs + h, ys) - wave(xs - h, ys)) / (2 * h)
    gy = (wave(xs, ys + h) - wave(xs, ys - h)) / (2 * h)
    fd = np.stack([-gx, -gy, np.ones_like(gx)], -1)
    fd /= np.linalg.norm(fd, axis=-1, keepdims=True)
    assert np.abs(fd[..., 2] - 1).max() > 0.1  # steep enough to test the slopes
    np.testing.assert_allclose(surface.normals.numpy(), fd, atol=1e-4)


def test_waves_are_stateless_and_move(device):
    """A frame is a function of time alone: at(t) twice gives the same bits, in any order, and a
    later time gives another surface (the phase advances at the chapter's SPEED)."""
    water = ProceduralWater(32, 2.0, device, **PARAMS)
    a = water.at(0.5).positions.numpy().copy()
    water.at(3.0)
    b = water.at(0.5).positions.numpy()
    np.testing.assert_array_equal(a, b)
    # SPEED·t = 2π returns every octave to its phase
    c = water.at(0.5 + 2 * np.pi / PARAMS["speed_rad_s"]).positions.numpy()
    np.testing.assert_allclose(c, a, atol=1e-5)
    assert np.abs(water.at(1.0).positions.numpy()[..., 2] - a[..., 2]).max() > 1e-3


def test_open_patch_floor_keeps_the_transmitted_flux():
    """Gentle procedural waves under an overhead sun with no absorption: the light through the open
    patch lands on the floor except what is bent out across its edge. That part grows with the
    amplitude: with A = 1e-4 (slopes ≤ 0.01) it is 2.8e-4 of the flux, with A = 1e-6 it must be
    ≤ 1e-5 (there are no walls to catch or lose more)."""
    scene = wc.load_scene(CONFIGS / "procedural.toml", overrides={
        "water.procedural_amplitude": 1e-6, "water.resolution": 64, "sun.elevation_deg": 90.0,
        "sun.angular_diameter_deg": 0.0,  # a disk's tilted rays would also cross the edge
        "optics.water_type": "none", "caustics.map_resolution": 64,
        "optics.wavelengths": {"min_nm": 500.0, "max_nm": 600.0, "bins": 2}})
    result = wc.render(scene, time_s=0.2, device="cpu")
    assert np.all(result.floor_flux_w_nm <= result.transmitted_flux_w_nm * (1 + 1e-6))
    np.testing.assert_allclose(result.floor_flux_w_nm, result.transmitted_flux_w_nm, rtol=1e-5)


def test_procedural_config_errors():
    """Bad procedural settings fail with one line naming the key."""
    with pytest.raises(ConfigError, match="water.procedural_octaves"):
        wc.load_scene(CONFIGS / "procedural.toml", overrides={"water.procedural_octaves": 0})
    with pytest.raises(ConfigError, match="water.procedural_frequency"):
        wc.load_scene(CONFIGS / "procedural.toml", overrides={"water.procedural_frequency": -1.0})
    with pytest.raises(ConfigError, match="caustics.beam_levels"):
        wc.load_scene(CONFIGS / "procedural.toml", overrides={"caustics.beam_levels": 1,
                                                            "caustics.method": "beams"})


def test_open_patch_loses_the_light_bent_past_its_edge():
    """Still water on the open patch under a 40° sun (water_type none): the floor receives the
    transmitted flux times the lit fraction (L − dx)(L − dy)/L², dx, dy the refracted ray's
    horizontal run D·tanθt along x and y — light from beyond the patch does not exist."""
    import math

    depth, extent, el, az = 1.5, 4.0, 40.0, 25.0
    scene = wc.load_scene(CONFIGS / "procedural.toml", {
        "water.procedural_amplitude": 0.0, "water.resolution": 64, "sun.elevation_deg": el,
        "sun.azimuth_deg": az, "floor.depth_m": depth, "optics.water_type": "none",
        "caustics.map_resolution": 64, "optics.wavelengths": {"min_nm": 500.0, "max_nm": 600.0, "bins": 1}})
    result = wc.render(scene, device="cpu")
    run = depth * math.tan(math.asin(math.cos(math.radians(el)) / 1.333))
    dx, dy = run * abs(math.cos(math.radians(az))), run * abs(math.sin(math.radians(az)))
    lit = (extent - dx) * (extent - dy) / extent**2
    np.testing.assert_allclose(result.floor_flux_w_nm / result.transmitted_flux_w_nm, lit, rtol=1e-4)
