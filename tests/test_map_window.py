"""Floor-map windows (caustics.map_extent_m, map_center_m): a small, finely sampled part of a sea."""

import math

import numpy as np
import pytest

import warpcaustics as wc
from warpcaustics.errors import ConfigError

from helpers import CONFIGS, fresnel_t_angles

BASE = {"water.resolution": 64, "optics.wavelengths": "rgb", "sun.angular_diameter_deg": 0.0}


@pytest.mark.parametrize("centre", [(2.0, -3.0), (7.5, 0.0)])
def test_window_is_the_crop_of_the_whole_map(centre):
    """A 4 m window of the 16 m ocean at the whole map's texel size equals that map's crop, also
    across the patch's periodic seam (x = ±8 m): each footprint lands at its nearest image."""
    full = wc.render(
        wc.load_scene(CONFIGS / "ocean.toml", {**BASE, "caustics.map_resolution": 128}), device="cpu"
    )
    win = wc.render(
        wc.load_scene(
            CONFIGS / "ocean.toml",
            {
                **BASE,
                "caustics.map_resolution": 32,
                "caustics.map_extent_m": 4.0,
                "caustics.map_center_m": list(centre),
            },
        ),
        device="cpu",
    )
    texel = 16.0 / 128
    i0 = round((centre[0] - 2.0 + 8.0) / texel)
    j0 = round((centre[1] - 2.0 + 8.0) / texel)
    crop = np.roll(full.floor_irradiance, (-j0, -i0), axis=(1, 2))[:, :32, :32]
    # float32 footprint coordinates relative to another origin: ≤ 1e-4 of the peak
    np.testing.assert_allclose(win.floor_irradiance, crop, atol=1e-4 * crop.max())
    x, y = win.map_coordinates()
    assert x[0] == pytest.approx(centre[0] - 2.0 + texel / 2) and y[-1] == pytest.approx(
        centre[1] + 2.0 - texel / 2
    )


def test_culling_blocks_away_from_the_window_changes_no_bit():
    """The deposit on a small window skips the surface's blocks whose floor hits cannot reach it
    (``coverage.block_reach``): the map is the same to the bit as with every triangle looked at,
    here across the patch's seam, and most blocks are skipped."""
    scene = wc.load_scene(CONFIGS / "ocean.toml", {
        **BASE, "water.resolution": 256, "caustics.map_resolution": 64, "caustics.map_extent_m": 1.0,
        "caustics.map_center_m": [7.8, -3.0]})
    culled = wc.Renderer(scene, "cpu")
    every = wc.Renderer(scene, "cpu")
    every.method.floor.reach_cells = 0
    a, b = culled.render(0.5), every.render(0.5)
    assert np.array_equal(a.floor_irradiance, b.floor_irradiance)
    assert a.floor_irradiance.max() > 0
    reach = culled.method.floor.reach.numpy()
    assert 0 < reach.sum() < 0.5 * reach.size


@pytest.mark.parametrize("elevation", [90.0, 30.0])
def test_millimetre_window_on_still_water_is_the_flat_irradiance(elevation):
    """Still water seen through a 0.1 m window with 0.5 mm texels: every texel has
    E_sun cosθ T(θ) e^{−cD/cosθt} (each footprint is clipped exactly against the fine texels)."""
    scene = wc.load_scene(
        None,
        {
            **BASE,
            "water.model": "flat",
            "water.extent_m": 4.0,
            "sun.elevation_deg": elevation,
            "caustics.map_resolution": 200,
            "caustics.map_extent_m": 0.1,
            "caustics.map_center_m": [1.3, -0.7],
            "floor.depth_m": 3.0,
        },
    )
    r = wc.render(scene, device="cpu")
    theta = math.radians(90.0 - elevation)
    theta_t = math.asin(math.sin(theta) / 1.333)
    expected = (
        r.sun_irradiance
        * math.cos(theta)
        * fresnel_t_angles(np.array([theta]), 1.0, 1.333)[0]
        * np.exp(-r.attenuation_per_m * 3.0 / math.cos(theta_t))
    )
    # float32 hit positions up to 2 m carry 0.24 µm (5e-4 of a 0.5 mm texel): texels along
    # footprint edges are off by up to 3.4e-4 (measured); the rest agree to 1e-6
    np.testing.assert_allclose(
        r.floor_irradiance, np.broadcast_to(expected[:, None, None], r.floor_irradiance.shape), rtol=1e-3
    )


def test_window_statistics_use_its_texels():
    """Statistics on a window use the window's texel size and centre (the default probe)."""
    r = wc.render(
        wc.load_scene(
            CONFIGS / "ocean.toml",
            {
                **BASE,
                "caustics.map_resolution": 40,
                "caustics.map_extent_m": 0.4,
                "caustics.map_center_m": [1.0, 1.0],
                "stats.collector_mm": 30.0,
            },
        ),
        device="cpu",
    )
    assert r.texel_area_m2 == pytest.approx(1e-4)
    from warpcaustics.batch.stats import (
        band_integrated,
        collector_average,
        field_statistics,
        frame_statistics,
    )

    st = frame_statistics(r, r.scene.config.stats)
    total = band_integrated(r.floor_irradiance, r.bin_widths_nm)
    # the 30 mm collector over 10 mm texels of an open window (not the patch's 0.25 m texels)
    expected = field_statistics(collector_average(total, 0.01, 0.03, periodic=False), 1.5)
    assert st["irradiance_w_m2"]["cv"] == pytest.approx(expected["cv"], rel=1e-9)
    assert expected["cv"] < field_statistics(total, 1.5)["cv"]  # the collector does smooth


@pytest.mark.parametrize(
    ("overrides", "needle"),
    [
        ({"caustics.map_extent_m": 20.0}, "exceeds water.extent_m"),
        ({"caustics.map_extent_m": 10.0}, "more than half"),
        ({"caustics.map_center_m": [1.0, 1.0]}, "caustics.map_extent_m is 0"),
        ({"caustics.map_extent_m": 1.0, "caustics.method": "beams"},  # both fixes offered
         r"set caustics.method = \"fluxratio\", or caustics.map_extent_m = 0"),
        ({"caustics.map_extent_m": 1.0, "caustics.map_center_m": [1.0]}, "caustics.map_center_m"),
        ({"caustics.map_extent_m": 1.0, "stats.probes": [{"x_m": 3.0, "y_m": 0.0}]}, r"stats.probes\[0\]"),
    ],
)
def test_window_errors_are_one_line(overrides, needle):
    """A window larger than the sea, a centre without a window, a window with another method, a
    malformed centre and a probe off the window are refused naming the key."""
    with pytest.raises(ConfigError, match=needle) as err:
        wc.load_scene(CONFIGS / "ocean.toml", overrides)
    assert "\n" not in str(err.value)
    with pytest.raises(ConfigError, match="reaches past"):
        wc.load_scene(
            CONFIGS / "pool.toml", {"caustics.map_extent_m": 1.0, "caustics.map_center_m": [1.8, 0.0]}
        )


def test_a_window_as_wide_as_the_patch_wraps_and_keeps_the_flux():
    """On a periodic sea a window the size of the patch is the patch, shifted: it wraps, keeps
    every watt (floor = transmitted, water_type none), and equals the whole map rolled."""
    base = {**BASE, "caustics.map_resolution": 64, "optics.water_type": "none"}
    full = wc.render(wc.load_scene(CONFIGS / "ocean.toml", base), device="cpu")
    shifted = wc.render(
        wc.load_scene(
            CONFIGS / "ocean.toml",
            {**base, "caustics.map_extent_m": 16.0, "caustics.map_center_m": [3.0, 0.0]},
        ),
        device="cpu",
    )
    np.testing.assert_allclose(shifted.floor_flux_w_nm, shifted.transmitted_flux_w_nm, rtol=1e-5)
    rolled = np.roll(full.floor_irradiance, -12, axis=2)  # 3 m = 12 texels of 0.25 m
    np.testing.assert_allclose(shifted.floor_irradiance, rolled, atol=1e-4 * rolled.max())
    assert shifted.map_periodic
