"""A radiance sensor at every texel (``floor.view_*``, caustics/view.py) against still water's
analytic cone integrals, the float64 numpy deposit, and its one-line refusals."""

import math

import numpy as np
import pytest

import warpcaustics as wc
from warpcaustics import reference
from warpcaustics.errors import ConfigError

from helpers import flat_floor_irradiance, flat_water_scene, fresnel_t_angles

FOV = 4.5  # Darecki et al. (2011)'s radiometers


def _refracted_zenith_deg(elevation_deg: float, ior: float) -> float:
    """The still-water refracted sun's zenith angle, from Snell's law in angles."""
    return math.degrees(math.asin(math.cos(math.radians(elevation_deg)) / ior))


def _view(zenith_deg, azimuth_deg, fov_deg=FOV):
    return {"floor.view_fov_deg": fov_deg, "floor.view_zenith_deg": zenith_deg,
            "floor.view_azimuth_deg": azimuth_deg}


@pytest.mark.parametrize("elevation_deg", [30.0, 65.0])
def test_still_water_sun_fills_the_cone_towards_it_and_none_beside(device, elevation_deg):
    """Looking back along the refracted sun, the cone holds the whole beam: ∫ L dω = the floor's
    irradiance over cos θ_t (1e-4); 5° beside the beam, and looking away from the sun, nothing."""
    depth = 2.0
    first = wc.render(flat_water_scene(elevation_deg, depth, "jerlov_IB"), device=device)
    n = first.ior.astype(np.float64)
    zenith = _refracted_zenith_deg(elevation_deg, float(n[0]))
    toward = wc.render(flat_water_scene(elevation_deg, depth, "jerlov_IB", **_view(zenith, 37.0)),
                       device=device)
    cos_t = np.cos(np.radians(zenith))
    expected = flat_floor_irradiance(first, elevation_deg, depth, ior=n) / cos_t
    got = toward.floor_irradiance.astype(np.float64)
    np.testing.assert_allclose(got, np.broadcast_to(expected[:, None, None], got.shape), rtol=1e-4)
    for zenith_deg, azimuth_deg in ((zenith + 5.0, 37.0), (zenith, 217.0)):
        scene = flat_water_scene(elevation_deg, depth, "jerlov_IB", **_view(zenith_deg, azimuth_deg))
        beside = wc.render(scene, device=device)
        assert np.all(beside.floor_irradiance == 0.0)


def _uniform_sky_cone_integral(zenith_deg, azimuth_deg, fov_deg, ior, e_sky, c_per_m, depth_m):
    """∫ n² T(θ_a) (E_sky/π) exp(−c D/cos θ_w) dω over the cone, in float64 on a polar grid about the
    axis (ψ from it, φ around it), written apart from the module's Fibonacci directions; beyond
    Snell's window (sin θ_a ≥ 1) the sensor sees the water below: 0."""
    half = math.radians(0.5 * fov_deg)
    psi = (np.arange(1000) + 0.5) * half / 1000
    phi = (np.arange(1000) + 0.5) * 2 * math.pi / 1000
    z, a = math.radians(zenith_deg), math.radians(azimuth_deg)
    axis = np.array([math.sin(z) * math.cos(a), math.sin(z) * math.sin(a), math.cos(z)])
    e1 = np.array([math.cos(z) * math.cos(a), math.cos(z) * math.sin(a), -math.sin(z)])
    e2 = np.cross(axis, e1)
    pp, ff = np.meshgrid(psi, phi, indexing="ij")
    u = (np.cos(pp)[..., None] * axis + (np.sin(pp) * np.cos(ff))[..., None] * e1
         + (np.sin(pp) * np.sin(ff))[..., None] * e2)
    sin_a = ior * np.sqrt(1.0 - u[..., 2] ** 2)
    t = np.where(sin_a < 1.0, fresnel_t_angles(np.arcsin(np.minimum(sin_a, 1.0)), 1.0, ior), 0.0)
    integrand = ior ** 2 * t * e_sky / math.pi * np.exp(-c_per_m * depth_m / u[..., 2])
    return float(np.sum(integrand * np.sin(pp)) * (half / 1000) * (2 * math.pi / 1000)), u


@pytest.mark.parametrize("zenith_deg", [0.0, 20.0])
def test_uniform_sky_through_still_water_is_the_cone_integral_of_n2_t_l(device, zenith_deg):
    """Still water under a uniform sky (the sun outside every cone): the map's sky is the cone
    integral of n² T L exp(−c D/cos θ_w) (0.2 %: the module's 64 directions against a fine grid)."""
    depth, fov = 1.5, 10.0
    scene = flat_water_scene(60.0, depth, "jerlov_IB", **_view(zenith_deg, 217.0, fov),
                             **{"sky.model": "uniform", "sky.diffuse_fraction": 0.4,
                                "optics.wavelengths.bins": 2})
    result = wc.render(scene, device=device)
    sky = result.sky_floor_irradiance.astype(np.float64)
    e_sky = result.scene.sky_irradiance(result.sun_irradiance)
    for k, nk in enumerate(result.ior.astype(np.float64)):
        expected, _ = _uniform_sky_cone_integral(zenith_deg, 217.0, fov, nk, e_sky[k],
                                                 float(result.attenuation_per_m[k]), depth)
        np.testing.assert_allclose(sky[k], expected, rtol=2e-3)


def test_a_cone_past_snells_window_sees_no_sky_beyond_it():
    """A 10° cone at 46° reaches past Snell's window (48.6°): beyond it the sensor sees the water
    below and gets nothing. The module's backward rays (4096 of them, to resolve the window's edge;
    the renderer's 64 put it within about 1 %) give the cone integral of the test above (0.2 %)."""
    from warpcaustics.caustics.view import view_axis
    from warpcaustics.reference.view import view_sky

    ior, c, depth, fov = 1.333, 0.2, 1.5, 10.0
    expected, u = _uniform_sky_cone_integral(46.0, 217.0, fov, ior, 1.0, c, depth)
    assert np.mean(ior * np.sqrt(1.0 - u[..., 2] ** 2) >= 1.0) > 0.05  # the edge really cuts the cone
    flat = np.zeros((8, 8, 3))
    up = np.broadcast_to([0.0, 0.0, 1.0], (8, 8, 3))
    got = view_sky(flat, up, 8.0, np.zeros((1, 1)), np.zeros((1, 1)), -depth, view_axis(46.0, 217.0), fov,
                   None, np.array([0.0, 0.0, 1.0]), np.array([1.0]), np.array([ior]), np.array([c]),
                   samples=4096)
    np.testing.assert_allclose(got[0, 0, 0], expected, rtol=2e-3)


def test_wavy_sea_sun_in_the_cone_matches_float64_numpy(device):
    """A rough FFT sea, a point sun, a 10° cone about the refracted sun: the weighted Warp deposit
    equals the float64 numpy deposit with the same weights (reference.floor.view_weights; L1 1e-4),
    and the cone really cuts the light (a part of it lands outside)."""
    scene_args = {"water.model": "fft", "water.resolution": 64, "water.extent_m": 8.0,
                  "water.wind_speed_m_s": 5.0, "water.phillips_amplitude": 4e-3, "floor.depth_m": 2.0,
                  "caustics.map_resolution": 96, "sun.elevation_deg": 55.0, "sun.azimuth_deg": 20.0,
                  "optics.water_type": "jerlov_IB", "optics.wavelengths.bins": 2, "water.seed": 3,
                  "sun.angular_diameter_deg": 0.0}
    zenith = _refracted_zenith_deg(55.0, 1.336)
    view = _view(zenith, 20.0, 10.0)
    result = wc.render(wc.load_scene(None, {**scene_args, **view}), device=device)
    whole = wc.render(wc.load_scene(None, scene_args), device=device)
    axis = np.array([math.sin(math.radians(zenith)) * math.cos(math.radians(20.0)),
                     math.sin(math.radians(zenith)) * math.sin(math.radians(20.0)),
                     math.cos(math.radians(zenith))])
    floor64, _ = reference.floor_caustics(
        result.surface_positions, result.surface_normals, result.scene.sun_direction,
        float(result.ior[0]), 2.0, result.sun_irradiance, result.attenuation_per_m, result.extent_m, 96,
        view=(axis, math.cos(math.radians(5.0))))
    l1 = np.abs(result.floor_irradiance - floor64).sum() / np.abs(floor64).sum()
    assert l1 < 1e-4, f"relative L1 {l1:.2e}"
    # the cone keeps part of the light: less than the whole beam over the steepest cos θ_t, not none
    kept = result.floor_irradiance.sum() * math.cos(math.radians(zenith + 5.0))
    assert 0.05 * whole.floor_irradiance.sum() < kept < 0.99 * whole.floor_irradiance.sum()


def test_sky_through_a_sinusoid_is_the_exact_surface_s_cone_integral(device, tmp_path):
    """A height field of one sinusoid across x (5 cm high, 2 m long: tilts up to 9°) under a uniform
    sky, a 2° cone at 30° across the crests: every texel's map is the cone integral of n² T L
    exp(−c ℓ) with each ray met on the exact sine (float64 fixed point) and refracted out through
    its exact normal (a polar grid over the cone), independently of the kernel's bilinear grid and
    Fibonacci directions (5e-4); the tilts really change it (by more than 2 % across the row)."""
    n, side, amplitude, wavelength, depth, fov, zenith = 256, 2.0, 0.05, 2.0, 0.5, 2.0, 30.0
    x = (np.arange(n) + 0.5) * side / n - 0.5 * side
    k = 2 * math.pi / wavelength
    np.save(tmp_path / "sine.npy", np.broadcast_to(amplitude * np.sin(k * x), (n, n)).astype(np.float32))
    scene = wc.load_scene(None, {
        "water.model": "heightfield", "water.file": str(tmp_path / "sine.npy"), "water.extent_m": side,
        "floor.depth_m": depth, "caustics.map_resolution": 64, "sun.elevation_deg": 60.0,
        "sun.azimuth_deg": 180.0, "sky.model": "uniform", "sky.diffuse_fraction": 0.3,
        "optics.water_type": "jerlov_II", "optics.wavelengths.bins": 1, **_view(zenith, 0.0, fov)})
    result = wc.render(scene, device=device)
    got = result.sky_floor_irradiance[0, 0].astype(np.float64)  # one row across the crests
    nk, c = float(result.ior[0]), float(result.attenuation_per_m[0])
    e_sky = float(scene.sky_irradiance(result.sun_irradiance)[0])
    half = math.radians(0.5 * fov)
    psi = (np.arange(40) + 0.5) * half / 40
    phi = (np.arange(80) + 0.5) * 2 * math.pi / 80
    pp, ff = np.meshgrid(psi, phi, indexing="ij")
    z = math.radians(zenith)
    axis = np.array([math.sin(z), 0.0, math.cos(z)])
    e1, e2 = np.array([math.cos(z), 0.0, -math.sin(z)]), np.array([0.0, 1.0, 0.0])
    u = (np.cos(pp)[..., None] * axis + (np.sin(pp) * np.cos(ff))[..., None] * e1
         + (np.sin(pp) * np.sin(ff))[..., None] * e2).reshape(-1, 3)
    texel_x = (np.arange(64) + 0.5) * side / 64 - 0.5 * side
    h = np.zeros((64, len(u)))
    for _ in range(60):  # the exact sine: a contraction (slope × tan 31° < 0.1)
        h = amplitude * np.sin(k * (texel_x[:, None] + (h + depth) * u[:, 0] / u[:, 2]))
    hit_x = texel_x[:, None] + (h + depth) * u[:, 0] / u[:, 2]
    normal = np.stack(np.broadcast_arrays(-amplitude * k * np.cos(k * hit_x), 0.0, 1.0), axis=-1)
    normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
    cos_w = np.sum(normal * u, axis=-1)
    sin_a = nk * np.sqrt(1.0 - cos_w ** 2)
    t = np.where(sin_a < 1.0, fresnel_t_angles(np.arcsin(np.minimum(sin_a, 1.0)), 1.0, nk), 0.0)
    d_omega = (np.sin(pp) * (half / 40) * (2 * math.pi / 80)).reshape(-1)
    expected = np.sum(nk ** 2 * t * e_sky / math.pi * np.exp(-c * (h + depth) / u[:, 2]) * d_omega, axis=1)
    np.testing.assert_allclose(got, expected, rtol=5e-4)  # measured: 8e-5
    assert expected.max() / expected.min() > 1.02  # measured: 1.05


def test_sky_kernel_on_a_wavy_sea_matches_float64_numpy(device):
    """A rough FFT sea under the CIE clear sky, a 4.5° cone at 35° away from the sun, a 1 m window:
    the kernel's backward trace equals the float64 numpy one over the same directions (relative L1
    1e-4), and the waves really make it vary (CV above 1 %)."""
    from warpcaustics.caustics.view import view_axis
    from warpcaustics.caustics.window import MapWindow
    from warpcaustics.reference.view import view_sky

    scene = wc.load_scene(None, {
        "water.model": "fft", "water.resolution": 64, "water.extent_m": 4.0, "water.wind_speed_m_s": 6.0,
        "water.phillips_amplitude": 4e-3, "water.seed": 5, "floor.depth_m": 0.8, "sun.elevation_deg": 50.0,
        "caustics.map_resolution": 48, "caustics.map_extent_m": 1.0, "sky.model": "cie_clear",
        "sky.diffuse_fraction": 0.3, "optics.water_type": "jerlov_II", "optics.wavelengths.bins": 2,
        **_view(35.0, 180.0)})
    result = wc.render(scene, device=device)
    window = MapWindow(scene.config)
    expected = view_sky(result.surface_positions.astype(np.float64),
                        result.surface_normals.astype(np.float64), result.extent_m, window.texel_x,
                        window.texel_y, -0.8, view_axis(35.0, 180.0), FOV, 12,
                        scene.sun_direction, scene.sky_irradiance(result.sun_irradiance),
                        result.ior.astype(np.float64), result.attenuation_per_m.astype(np.float64))
    got = result.sky_floor_irradiance
    l1 = np.abs(got - expected).sum() / np.abs(expected).sum()
    assert l1 < 1e-4, f"relative L1 {l1:.2e}"
    assert np.std(expected[0]) / np.mean(expected[0]) > 0.01


def test_the_flux_fields_count_the_light_entering_the_water_not_the_cone(device):
    """With a sensor the transmitted flux is still the light entering the water (the irradiance
    map's own, 1e-6), whichever way the cone looks; the delivered flux, which the cone's ∫ L dω is
    not, is None; the map stays float32 with a traced sky; PAR is not reported of ∫ L dω."""
    from warpcaustics.batch.stats import frame_statistics

    plain = wc.render(flat_water_scene(50.0, 2.0, "jerlov_IB"), device=device)
    zenith = _refracted_zenith_deg(50.0, float(plain.ior[0]))
    for azimuth in (37.0, 217.0):
        seen = wc.render(flat_water_scene(50.0, 2.0, "jerlov_IB", **_view(zenith, azimuth)), device=device)
        np.testing.assert_allclose(seen.transmitted_flux_w_nm, plain.transmitted_flux_w_nm, rtol=1e-6)
        assert seen.delivered_flux_w_nm is None
    sky_args = {"sky.model": "cie_clear", "sky.diffuse_fraction": 0.2}
    sky_scene = flat_water_scene(50.0, 2.0, "jerlov_IB", **_view(zenith, 37.0), **sky_args)
    sky = wc.render(sky_scene, device=device)
    assert sky.floor_irradiance.dtype == np.float32 and sky.sky_floor_irradiance.dtype == np.float32
    stats = frame_statistics(sky, sky.scene.config.stats)
    assert "irradiance_w_m2" in stats and "par_umol_m2_s" not in stats
    assert "par_umol_m2_s" in frame_statistics(plain, plain.scene.config.stats)


@pytest.mark.parametrize("overrides, needle", [
    ({"caustics.method": "photons"}, 'caustics.method = "fluxratio"'),
    ({"optics.scattering": "small_angle"}, 'optics.scattering = "single"'),
    ({"water.model": "procedural"}, "a periodic sea"),
    ({"water.model": "fft", "water.choppiness": 1.0}, "water.choppiness = 0"),
    ({"floor.view_zenith_deg": 89.0}, "use a zenith of at most 87.75"),
    ({"output.netcdf": True}, "output.netcdf = false"),
    ({"output.npz": True}, "output.npz = false"),
    ({"floor.view_fov_deg": 0.0, "floor.view_zenith_deg": 20.0}, "floor.view_zenith_deg = 20 is only read"),
    ({"floor.view_fov_deg": 0.0, "floor.view_azimuth_deg": 90.0}, "set floor.view_fov_deg"),
])
def test_a_view_it_cannot_render_is_refused_in_one_line(overrides, needle):
    with pytest.raises(ConfigError) as err:
        wc.load_scene(None, {"floor.view_fov_deg": FOV, **overrides})
    assert needle in str(err.value) and "\n" not in str(err.value)
