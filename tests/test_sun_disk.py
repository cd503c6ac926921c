"""The sun's disk (sun.angular_diameter_deg), integrated over its directions by every caustic method."""

import math

import numpy as np
import pytest

import warpcaustics as wc
from warpcaustics.errors import ConfigError

from helpers import CONFIGS
from test_lens import APEX_M, FOCAL_M, IOR, RADIUS_OF_CURVATURE_M

IMAGE_RADIUS_M = IOR * RADIUS_OF_CURVATURE_M / (IOR - 1.0) * math.radians(0.53 / 2) / IOR
"""The sun's image at the lens's focus: f'·ρ/n, f' = nR/(n−1) behind the surface, ρ the sun's
angular radius refracted into the water (6.9 mm)."""


def _at_focus(extra: dict) -> dict:
    """Overrides of configs/lens.toml: the floor at the focus, non-absorbing water, one band."""
    return {
        "floor.depth_m": FOCAL_M - APEX_M,
        "optics.water_type": "none",
        "optics.ior": IOR,
        "optics.wavelengths": {"min_nm": 500.0, "max_nm": 600.0, "bins": 1},
        **extra,
    }


@pytest.fixture(scope="module")
def focus_maps():
    """The flux-ratio map at the lens's focus on 2048² texels (1 mm) for a point sun and the disk:
    {diameter: (scene, (K, M, M) map)}, and the texel centres."""
    out = {}
    for diameter in (0.0, 0.53):
        scene = wc.load_scene(CONFIGS / "lens.toml", _at_focus({"caustics.map_resolution": 2048,
                                                              "sun.angular_diameter_deg": diameter}))
        r = wc.render(scene, device="cpu")
        out[diameter] = (scene, r.floor_irradiance)
    return out, r.map_coordinates()[0]


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
            CONFIGS / "lens.toml",
            _at_focus({"caustics.map_resolution": 200, "caustics.map_extent_m": 0.05,
                       "sun.angular_diameter_deg": diameter, "sun.disk_samples": 64}),
        )
        r = wc.render(scene, device="cpu")
        e = r.floor_irradiance[0].astype(np.float64)
        x, y = r.map_coordinates()
        radius = np.hypot(*np.meshgrid(x, y))
        spots[diameter] = (e.max(), radius[e > 0.5 * e.max()].max(), e.sum() * r.texel_area_m2)
    assert spots[0.0][1] < 0.1 * IMAGE_RADIUS_M
    assert spots[0.53][1] == pytest.approx(IMAGE_RADIUS_M, abs=2 * 0.05 / 200)
    assert spots[0.53][0] < 0.1 * spots[0.0][0]
    assert spots[0.53][2] == pytest.approx(spots[0.0][2], rel=1e-3)


def _encircled_radius(e: np.ndarray, x: np.ndarray, share: float) -> float:
    """Radius about the map's centre holding ``share`` of the flux in the map."""
    r = np.hypot(*np.meshgrid(x, x)).ravel()
    order = np.argsort(r)
    cumulative = np.cumsum(e.ravel()[order])
    return float(r[order][np.searchsorted(cumulative, share * cumulative[-1])])


def test_photons_run_a_pass_per_disk_direction(focus_maps):
    """Photons (4×4 per cell, 16 disk directions, a pass each) under the lens at its focus: a point
    sun's spot holds half its flux inside a texel or two; the disk's is the sun's image, a uniform
    disc of radius a = f'·ρ/n, so a share q of its flux lies within √q·a (q = ¼, ½, ¾; to one 1 mm
    texel), as with the flux-ratio map's disk; the flux is unchanged (1e-4). On still water the
    floor mean is unchanged (1e-4)."""
    flux_ratio, x = focus_maps
    centre = np.abs(x) < 0.02
    texel = 2.0 / 2048
    maps, flux = {}, {}
    for diameter in (0.0, 0.53):
        overrides = _at_focus({"caustics.method": "photons", "caustics.map_resolution": 2048,
                               "sun.angular_diameter_deg": diameter})
        r = wc.render(wc.load_scene(CONFIGS / "lens.toml", overrides), device="cpu")
        e = r.floor_irradiance[0].astype(np.float64)
        maps["photons", diameter] = e[np.ix_(centre, centre)] - e[0, 0]  # above the flat water's
        flux[diameter] = e.sum() * r.texel_area_m2
    e = flux_ratio[0.53][1][0].astype(np.float64)
    maps["fluxratio", 0.53] = e[np.ix_(centre, centre)] - e[0, 0]
    assert _encircled_radius(maps["photons", 0.0], x[centre], 0.5) < 2 * texel
    assert flux[0.53] == pytest.approx(flux[0.0], rel=1e-4)
    for share in (0.25, 0.5, 0.75):  # the image's encircled flux, √share·a, by both methods
        for method in ("photons", "fluxratio"):
            radius = _encircled_radius(maps[method, 0.53], x[centre], share)
            assert radius == pytest.approx(math.sqrt(share) * IMAGE_RADIUS_M, abs=texel), (method, share)
    flat = {"water.model": "flat", "water.resolution": 32, "caustics.map_resolution": 32,
            "caustics.method": "photons", "sun.elevation_deg": 40.0, "optics.wavelengths": "rgb"}
    point = wc.render(wc.load_scene(None, flat), device="cpu").floor_irradiance.mean(axis=(1, 2))
    disk = wc.render(wc.load_scene(None, {**flat, "sun.angular_diameter_deg": 0.53}),
                     device="cpu").floor_irradiance.mean(axis=(1, 2))
    np.testing.assert_allclose(disk, point, rtol=1e-4)


def test_beams_average_a_pass_per_disk_direction():
    """Beams under the lens at its focus with an 8-direction disk (a pass each, 2 mm texels): the
    spot equals the flux-ratio map's with the same directions (relative L1 < 1e-3, both exact
    methods), its encircled flux follows the sun's uniform image √q·a to one texel, and the flux is
    the point sun's (1e-4)."""
    maps, flux = {}, {}
    for method, diameter in (("beams", 0.53), ("fluxratio", 0.53), ("beams", 0.0)):
        overrides = _at_focus({"caustics.method": method, "caustics.map_resolution": 1024,
                               "sun.angular_diameter_deg": diameter, "sun.disk_samples": 8})
        r = wc.render(wc.load_scene(CONFIGS / "lens.toml", overrides), device="cpu")
        e = r.floor_irradiance[0].astype(np.float64)
        x, _ = r.map_coordinates()
        centre = np.abs(x) < 0.02
        maps[method, diameter] = e[np.ix_(centre, centre)] - e[0, 0]
        flux[method, diameter] = e.sum() * r.texel_area_m2
    beams, reference = maps["beams", 0.53], maps["fluxratio", 0.53]
    assert np.abs(beams - reference).sum() / np.abs(reference).sum() < 1e-3
    for share in (0.25, 0.5, 0.75):
        radius = _encircled_radius(beams, x[centre], share)
        assert radius == pytest.approx(math.sqrt(share) * IMAGE_RADIUS_M, abs=2.0 / 1024), share
    assert flux["beams", 0.53] == pytest.approx(flux["beams", 0.0], rel=1e-4)


def test_grid_methods_move_their_map_by_the_disk_parallax(focus_maps):
    """The eikonal and wave maps take the disk as their map moved by each direction's still-water
    parallax and averaged. Checked on the flux-ratio map at the lens's focus (2048² texels, 1 mm),
    where the exact integration is known: the parallax average of the point sun's map holds its
    flux in the same radii as the exact disk's (q = ¼, ½, ¾, to a texel) and keeps the flux (1e-6,
    periodic). The eikonal map of an ocean keeps its mean with a disk (1e-6)."""
    from warpcaustics.caustics.eikonal import parallax_disk_average

    maps, x = focus_maps
    scene, point_map = maps[0.0]
    disk_scene, disk_map = maps[0.53]
    moved = parallax_disk_average(point_map, scene.sun_direction, disk_scene.sun_disk_directions(), IOR,
                                  FOCAL_M - APEX_M, 2.0, True)
    assert moved.mean() == pytest.approx(point_map.mean(), rel=1e-6)
    centre = np.abs(x) < 0.02
    for share in (0.25, 0.5, 0.75):
        radii = [_encircled_radius(m[0][np.ix_(centre, centre)] - m[0][0, 0], x[centre], share)
                 for m in (moved, disk_map)]
        assert radii[0] == pytest.approx(radii[1], abs=2.0 / 2048), share
    ocean = {"water.resolution": 64, "caustics.map_resolution": 64, "caustics.method": "eikonal",
             "optics.wavelengths": "rgb", "sun.angular_diameter_deg": 0.0}
    point = wc.render(wc.load_scene(CONFIGS / "ocean.toml", ocean), device="cpu").floor_irradiance
    disk = wc.render(wc.load_scene(CONFIGS / "ocean.toml", {**ocean, "sun.angular_diameter_deg": 0.53}),
                     device="cpu").floor_irradiance
    np.testing.assert_allclose(disk.mean(axis=(1, 2)), point.mean(axis=(1, 2)), rtol=1e-6)
    assert np.abs(disk - point).max() > 0.0


def test_the_sun_maps_disk_is_the_suns():
    """The sun map draws the sun's own disk (sun.angular_diameter_deg), so every sun disk goes with
    it; the key it used to have (caustics.sunmap_disk_deg) is refused naming the sun's."""
    for diameter in (0.0, 0.53, 2.0):
        wc.load_scene(CONFIGS / "ocean.toml", {"sun.angular_diameter_deg": diameter,
                                               "caustics.method": "sunmap"})
    with pytest.raises(ConfigError, match="merged into sun.angular_diameter_deg"):
        wc.load_scene(CONFIGS / "ocean.toml", {"caustics.sunmap_disk_deg": 1.0, "caustics.method": "sunmap"})


@pytest.mark.parametrize("periodic", [True, False])
def test_parallax_moves_a_map_as_still_water_displaces_light(periodic):
    """One direction 0.2° off a 40° sun (given twice, so the average is that one move): a bright
    texel's centroid moves by D·(t_xy/|t_z| − t0_xy/|t0_z|), t from Snell's law written out here
    (1e-9 texels: bilinear moves keep centroids), rows along +y and columns along +x. Without
    wrapping, what is moved past the edge is lost, in the bilinear share."""
    from warpcaustics.caustics.eikonal import parallax_disk_average

    n_w, depth, extent, m = 1.34, 5.0, 2.0, 64

    def towards(elevation_deg, azimuth_deg):
        e, a = math.radians(elevation_deg), math.radians(azimuth_deg)
        return np.array([math.cos(e) * math.cos(a), math.cos(e) * math.sin(a), math.sin(e)])

    def floor_offset(s):  # where the ray refracted at the origin meets the floor, Snell by hand
        sin_t = math.hypot(s[0], s[1]) / n_w
        return -depth * (s[:2] / math.hypot(s[0], s[1])) * sin_t / math.sqrt(1.0 - sin_t**2)

    sun, off = towards(40.0, 30.0), towards(40.15, 30.2)
    expected = (floor_offset(off) - floor_offset(sun)) / (extent / m)  # texels (x, y)
    floor = np.zeros((1, m, m))
    floor[0, 30, 20] = 1.0
    moved = parallax_disk_average(floor, sun, np.stack([off, off]), n_w, depth, extent, periodic)[0]
    ys, xs = np.mgrid[0:m, 0:m]
    centroid = np.array([(moved * xs).sum(), (moved * ys).sum()]) / moved.sum()
    np.testing.assert_allclose(centroid - [20.0, 30.0], expected, atol=1e-9)
    assert moved.sum() == pytest.approx(1.0, rel=1e-12)
    edge = np.zeros((1, m, m))
    edge[0, 10, m - 1] = 1.0  # on the last column: the move towards +x takes part of it off the map
    kept = parallax_disk_average(edge, sun, np.stack([off, off]), n_w, depth, extent, periodic)[0].sum()
    assert 0.1 < expected[0] < 1.0
    assert kept == pytest.approx(1.0 if periodic else 1.0 - expected[0], rel=1e-12)


def test_the_default_sun_is_the_real_suns_disk():
    """DESIGN: 0.53° is the default once every method integrates the disk (they all do)."""
    assert wc.load_scene(None).config.sun.angular_diameter_deg == 0.53
