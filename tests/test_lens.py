"""A paraboloid bump on flat water is a lens: it concentrates the sun as paraxial optics predicts."""

import numpy as np
import pytest

import warpcaustics as wc

N = 256
EXTENT_M = 2.0
RADIUS_OF_CURVATURE_M = 0.5
APERTURE_M = 0.15
IOR = 1.333
# A single refracting surface focuses parallel light at f = n R / (n - 1) behind its apex.
FOCAL_M = IOR * RADIUS_OF_CURVATURE_M / (IOR - 1.0)
APEX_M = APERTURE_M**2 / (2.0 * RADIUS_OF_CURVATURE_M)


@pytest.fixture(scope="module")
def lens_file(tmp_path_factory):
    x = (np.arange(N) + 0.5) * EXTENT_M / N - EXTENT_M / 2
    xx, yy = np.meshgrid(x, x)
    r2 = xx**2 + yy**2
    heights = np.where(r2 < APERTURE_M**2, (APERTURE_M**2 - r2) / (2.0 * RADIUS_OF_CURVATURE_M), 0.0)
    path = tmp_path_factory.mktemp("lens") / "lens.npy"
    np.save(path, heights)
    return path


def _central_gain(lens_file, depth_m, device):
    """Irradiance at the floor centre over the irradiance under flat water."""
    scene = wc.load_scene(None, {
        "water.model": "heightfield", "water.file": str(lens_file), "water.extent_m": EXTENT_M,
        "floor.depth_m": float(depth_m), "sun.elevation_deg": 90.0, "optics.water_type": "none",
        "optics.ior": IOR, "optics.wavelengths.bins": 1, "caustics.map_resolution": N,
        "sun.angular_diameter_deg": 0.0})  # paraxial optics of a point sun
    floor = wc.render(scene, device=device).floor_irradiance[0].astype(np.float64)
    centre = floor[N // 2 - 1:N // 2 + 1, N // 2 - 1:N // 2 + 1].mean()
    return centre / floor[0, 0]


@pytest.mark.parametrize("depth_m", [0.5, 1.0, 1.5])
def test_concentration_before_focus_matches_paraxial_optics(lens_file, depth_m, device):
    """At distance z behind the apex the bump's light fills a disc of radius a(1 - z/f): gain (1 - z/f)^-2."""
    z = depth_m + APEX_M
    expected = 1.0 / (1.0 - z / FOCAL_M) ** 2
    # Paraxial optics on a bump with a/R = 0.3: aberration and Fresnel variation stay below 2 %.
    assert _central_gain(lens_file, depth_m, device) == pytest.approx(expected, rel=0.02)


def test_brightest_depth_is_the_focal_depth(lens_file, device):
    """Scanning the floor depth, the centre is brightest within 10 % of the predicted focus f - apex."""
    depths = np.arange(1.0, 3.01, 0.1)
    gains = np.array([_central_gain(lens_file, d, device) for d in depths])
    predicted = FOCAL_M - APEX_M
    assert abs(depths[np.argmax(gains)] - predicted) <= 0.1 * predicted
    assert gains.max() > 100.0  # a real focus, texel-limited, not a mild brightening


def test_oblique_sun_moves_the_focus_away_from_the_sun(lens_file, device):
    """Sun at 45° elevation, azimuth 30°: the focal spot lies along the refracted chief ray through the
    apex, displaced by (D + apex)·tanθ_t away from the sun's azimuth (checks the azimuth convention)."""
    depth, elevation, azimuth = 1.0, 45.0, 30.0
    scene = wc.load_scene(None, {
        "water.model": "heightfield", "water.file": str(lens_file), "water.extent_m": EXTENT_M,
        "floor.depth_m": depth, "sun.elevation_deg": elevation, "sun.azimuth_deg": azimuth,
        "optics.water_type": "none", "optics.ior": IOR, "optics.wavelengths.bins": 1,
        "caustics.map_resolution": N, "sun.angular_diameter_deg": 0.0})
    floor = wc.render(scene, device=device).floor_irradiance[0].astype(np.float64)
    background = np.median(floor)
    spot = np.where(floor > 2.0 * background, floor, 0.0)  # the concentrated light only
    x = (np.arange(N) + 0.5) * EXTENT_M / N - EXTENT_M / 2
    cx = (spot.sum(axis=0) * x).sum() / spot.sum()
    cy = (spot.sum(axis=1) * x).sum() / spot.sum()
    theta_t = np.arcsin(np.sin(np.radians(90.0 - elevation)) / IOR)
    shift = (depth + APEX_M) * np.tan(theta_t)
    az = np.radians(azimuth)
    texel = EXTENT_M / N
    # Light travels along -s: away from the sun's azimuth. Off-axis aberration shifts the
    # centroid slightly from the chief ray; two texels (16 mm) bound it.
    assert np.hypot(cx + shift * np.cos(az), cy + shift * np.sin(az)) < 2 * texel
