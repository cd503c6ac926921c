"""Photon footprint splats on the floor map (``caustics.photon_splat = "footprint"``): still water
at any photon density, the flux kept, and closer to the exact beams than texel photons."""

import numpy as np
import pytest

import warpcaustics as wc
from warpcaustics.reference import relative_l1

from helpers import CONFIGS, flat_floor_irradiance, flat_water_scene


@pytest.mark.parametrize(("subdivisions", "map_m"), [(3, 50), (2, 97), (5, 64)])
def test_still_water_is_analytic_in_every_texel_at_any_density(subdivisions, map_m):
    """A periodic still sea, sun 40° high, 3 m deep: every texel reads E_sun cosθ T(θ) e^{−cD/cosθ_t}
    whether or not a texel holds a whole number of photon spacings (the cells of a regular lattice
    tile the floor; exact clipping spreads each over the texels it covers). float32 clipping and
    sums: 2e-5. Texel photons at the same densities are off by 70–130 % (the histogram's aliasing)."""
    scene = flat_water_scene(40.0, 3.0, "pure", **{
        "caustics.method": "photons", "caustics.photon_subdivisions": subdivisions,
        "caustics.map_resolution": map_m, "water.resolution": 32})
    result = wc.render(scene, device="cpu")
    expected = flat_floor_irradiance(result, 40.0, 3.0)
    uniform = np.broadcast_to(expected[:, None, None], result.floor_irradiance.shape)
    np.testing.assert_allclose(result.floor_irradiance, uniform, rtol=2e-5)


def test_footprints_keep_the_flux_on_a_rough_ocean():
    """No absorption, a rough FFT ocean (focusing, folds at the crests): the floor map's flux equals
    the flux that entered the water (float32 texels summed in float64: 1e-5)."""
    scene = wc.load_scene(CONFIGS / "ocean.toml", {
        "caustics.method": "photons", "water.resolution": 64, "caustics.map_resolution": 64,
        "optics.water_type": "none", "optics.wavelengths": "rgb", "water.wind_speed_m_s": 8.0,
        "floor.depth_m": 6.0})
    result = wc.render(scene, device="cpu")
    assert result.photon_stats["landed"] == result.photon_stats["carrying"]
    np.testing.assert_allclose(result.floor_flux_w_nm, result.transmitted_flux_w_nm, rtol=1e-5)


def test_footprints_agree_with_beams_better_than_texels():
    """configs/ocean.toml (64² surface, 64² map, no absorption, point sun) against the beams' exact
    map of the same frame: footprint photons at 4 and 16 photons per texel are closer than texel
    photons at the same counts, by more than 2× (measured: docs/validation.md)."""
    base = {"water.resolution": 64, "caustics.map_resolution": 64, "optics.water_type": "none",
            "optics.wavelengths": "rgb", "sun.angular_diameter_deg": 0.0}
    beams = wc.render(wc.load_scene(CONFIGS / "ocean.toml", {**base, "caustics.method": "beams"}),
                      device="cpu").floor_irradiance
    l1 = {}
    for splat in ("texel", "footprint"):
        for s in (2, 4):
            scene = wc.load_scene(CONFIGS / "ocean.toml", {**base, "caustics.method": "photons",
                                                            "caustics.photon_splat": splat,
                                                            "caustics.photon_subdivisions": s})
            l1[splat, s] = relative_l1(wc.render(scene, device="cpu").floor_irradiance, beams)
    # measured 0.046 / 0.038 against 0.197 / 0.083; what is left is the photons' bilinear surface
    # patches against the beams' triangles, not noise (it hardly falls from 4 to 16 per texel)
    for s in (2, 4):
        assert l1["footprint", s] < 0.5 * l1["texel", s], l1


def test_footprints_on_a_sphere_agree_with_beams_better_than_texels():
    """configs/ocean.toml (64² surface) with a sphere (radius 1 m, 7,936 faces, centre 2.5 m down),
    no absorption: the flux on each of the sphere's faces from footprint photons, spread over the
    faces their cells cover, is closer to the beams' (another method) than the photons' face
    deposits at the same count — by more than 5× at 4 and 16 photons per cell — and the flux on
    floor and sphere together is what entered the water (float32 sums: 1e-5)."""
    centre = [0.0, 0.0, -2.5]
    base = {"water.resolution": 64, "caustics.map_resolution": 32, "optics.wavelengths": "rgb",
            "optics.water_type": "none",
            "receivers": [{"mesh": "sphere", "scale": 2.0, "translate_m": centre}]}
    beams = wc.render(wc.load_scene(CONFIGS / "ocean.toml", {**base, "caustics.method": "beams"}),
                      device="cpu")
    sphere = beams.face_receiver == 2
    reference = beams.face_flux_w_nm[sphere]
    l1 = {}
    for splat in ("texel", "footprint"):
        for s in (2, 4):
            result = wc.render(wc.load_scene(CONFIGS / "ocean.toml", {
                **base, "caustics.method": "photons", "caustics.photon_splat": splat,
                "caustics.photon_subdivisions": s}), device="cpu")
            l1[splat, s] = relative_l1(reference, result.face_flux_w_nm[sphere])
            total = result.floor_flux_w_nm + result.face_flux_w_nm.sum(axis=0)
            np.testing.assert_allclose(total, result.transmitted_flux_w_nm, rtol=1e-5)
    # measured 0.177 / 0.094 against 1.73 / 1.09 (a face holds ~1 photon at 4 per cell)
    for s in (2, 4):
        assert l1["footprint", s] < 0.2 * l1["texel", s], l1
