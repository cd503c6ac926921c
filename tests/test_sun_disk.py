"""The sun's disk (sun.angular_diameter_deg), integrated over directions by the flux-ratio map."""

import math

import numpy as np
import pytest

import warpcaustics as wc
from warpcaustics.errors import ConfigError

from test_lens import APEX_M, FOCAL_M, IOR, RADIUS_OF_CURVATURE_M


@pytest.mark.parametrize("elevation", [90.0, 30.0, 10.0])
def test_disk_on_flat_water_keeps_the_floor_uniform_and_its_mean(elevation):
    """Still water under a 0.53° disk: the floor stays uniform and equals the point sun's to 1e-4
    (the mirrored pattern cancels the first-order term; what is left is of order ρ² ≈ 2e-5, 5e-5
    at a 10° sun)."""
    base = {
        "water.model": "flat",
        "water.extent_m": 4.0,
        "water.resolution": 32,
        "caustics.map_resolution": 64,
        "sun.elevation_deg": elevation,
        "optics.wavelengths": "rgb",
    }
    point = wc.render(wc.load_scene(None, base), device="cpu").floor_irradiance
    disk = wc.render(
        wc.load_scene(None, {**base, "sun.angular_diameter_deg": 0.53}), device="cpu"
    ).floor_irradiance
    np.testing.assert_allclose(disk, point, rtol=1e-4)


def test_disk_widens_the_lens_focus_to_the_suns_image():
    """The paraboloid lens with the floor at its focus, seen through a 5 cm window of 0.25 mm
    texels: a point sun makes a sub-millimetre spot; the 0.53° disk makes the sun's image, a disc
    of radius f'·ρ/n (f' = nR/(n−1) behind the surface, ρ the sun's angular radius, refracted into
    the water) within two texels, its peak falls more than tenfold, and the flux in the window
    stays the same (1e-3)."""
    spots = {}
    for diameter in (0.0, 0.53):
        scene = wc.load_scene(
            "configs/lens.toml",
            {
                "floor.depth_m": FOCAL_M - APEX_M,
                "optics.water_type": "none",
                "optics.ior": IOR,
                "optics.wavelengths": {"min_nm": 500.0, "max_nm": 600.0, "bins": 1},
                "caustics.map_resolution": 200,
                "caustics.map_extent_m": 0.05,
                "sun.angular_diameter_deg": diameter,
                "sun.disk_samples": 64,
            },
        )
        r = wc.render(scene, device="cpu")
        e = r.floor_irradiance[0].astype(np.float64)
        x, y = r.map_coordinates()
        radius = np.hypot(*np.meshgrid(x, y))
        spots[diameter] = (e.max(), radius[e > 0.5 * e.max()].max(), e.sum() * r.texel_area_m2)
    image_radius = IOR * RADIUS_OF_CURVATURE_M / (IOR - 1.0) * math.radians(0.53 / 2) / IOR
    assert spots[0.0][1] < 0.1 * image_radius
    assert spots[0.53][1] == pytest.approx(image_radius, abs=2 * 0.05 / 200)
    assert spots[0.53][0] < 0.1 * spots[0.0][0]
    assert spots[0.53][2] == pytest.approx(spots[0.0][2], rel=1e-3)


def test_disk_with_another_method_is_refused():
    """The disk is integrated by the flux-ratio map only so far: other methods say so."""
    with pytest.raises(ConfigError, match="sun.angular_diameter_deg"):
        wc.load_scene("configs/ocean.toml", {"sun.angular_diameter_deg": 0.53, "caustics.method": "beams"})
