"""Eikonal caustics (after Mercier 2013): the solver's accuracy, flat fronts, the lens."""

import math

import numpy as np
import pytest
import warp as wp

import warpcaustics as wc
from warpcaustics.caustics.eikonal import relax
from warpcaustics.kernels.caustics import eikonal as eikonal_kernels

from helpers import CONFIGS, fresnel_t_angles

IOR = 1.333


def _flat(elevation, model="flat", **extra):
    overrides = {"caustics.method": "eikonal", "water.model": model, "water.extent_m": 4.0,
                 "water.resolution": 64, "caustics.map_resolution": 64, "caustics.eikonal_resolution": 48,
                 "sun.elevation_deg": elevation, "sun.azimuth_deg": 25.0, "optics.ior": IOR,
                 "floor.depth_m": 1.5, "optics.wavelengths": {"min_nm": 450.0, "max_nm": 650.0, "bins": 2},
                 "sun.angular_diameter_deg": 0.0}  # the references are a point sun's
    overrides.update(extra)
    return wc.load_scene(None, overrides)


def _sphere_case(n, device, radius=0.3):
    """Distance to a sphere of radius R (centre at the grid's middle, slowness 1): the exact values
    frozen in and above the sphere's middle layer, the rest solved. Returns (solved, exact, mask of
    the solved nodes)."""
    extent = 2.0
    h = extent / n
    grid = eikonal_kernels.EikonalGrid()
    grid.n, grid.h, grid.extent_m, grid.periodic, grid.slowness = n, h, extent, 0, 1.0
    grid.z_top = 0.5 * extent - 0.5 * h
    grid.layers = n
    grid.gradient = wp.vec3(0.0, 0.0, 0.0)
    c = (np.arange(n) + 0.5) * h - 0.5 * extent
    z = grid.z_top - np.arange(n) * h
    exact = np.sqrt(c[None, None, :] ** 2 + c[None, :, None] ** 2 + z[:, None, None] ** 2) - radius
    middle = n // 2
    # frozen: every layer down to the middle one, and inside the sphere below it
    below_sphere = np.argmax(exact[middle:] > 0.0, axis=0) + middle - 1
    top = np.maximum(middle, below_sphere).astype(np.int32)
    k = np.arange(n)[:, None, None]
    psi = np.where(k <= top[None], exact, 1.0e30).astype(np.float32)
    psi_wp = wp.array(psi, dtype=wp.float32, device=device)
    relax(grid, wp.array(top, dtype=wp.int32, device=device), psi_wp, device)
    return psi_wp.numpy().astype(np.float64), exact, k > top[None]


def test_solver_distance_to_a_sphere_is_second_order(device):
    """Below a sphere the solver's φ is the distance to it, with the second-order upwind scheme's
    error: the median node's error falls 4.0× when h halves (3.1× again at 128 nodes across), and
    no node is off by more than 0.15 h (the worst, where the front runs sideways beside the
    sphere, where the march falls back to first-order lateral terms)."""
    median, worst = [], []
    for n in (32, 64):
        solved, exact, mask = _sphere_case(n, device)
        err = np.abs(solved - exact)[mask]
        median.append(np.median(err))
        worst.append(err.max() / (2.0 / n))
    assert median[0] / median[1] > 3.5
    assert max(worst) < 0.15


@pytest.mark.parametrize("elevation", [90.0, 40.0, 12.0])
@pytest.mark.parametrize("model", ["flat", "procedural"])
def test_flat_interface_is_a_plane_front_up_to_the_faces(elevation, model):
    """Still water: φ is the refracted plane front G·p everywhere (the solver is exact for planes),
    its Laplacian — Mercier's texture — is 0 up to the faces of the grid (periodic, and open with the
    mirrored faces: no bright band, Mercier fig. 3), and the floor gets E_sun cosθ T(θ) e^{−cD/cosθt}
    — on an open patch only where the light comes from inside the patch, as for the flux ratio."""
    extra = {"water.procedural_amplitude": 0.0} if model == "procedural" else {}
    renderer = wc.Renderer(_flat(elevation, model, **extra), device="cpu")
    result = renderer.render(0.0)
    eik = renderer.method.approximate
    assert eik.periodic == (model == "flat")
    psi = eik.psi.numpy()
    # float32 rounding of the upwind solves adds ~1e-7 m of optical path per layer, the same across
    # each layer: ≤ 1e-5 m over the ~35 layers, and flat within each layer to 1e-6 m
    np.testing.assert_allclose(psi, 0.0, atol=1e-5)
    assert (psi.max(axis=(1, 2)) - psi.min(axis=(1, 2))).max() < 1e-6
    texture = eik.texture()
    assert np.abs(texture).max() < 2e-2  # [1/m]; the lens's texture is ~1/m (see below)
    theta = math.radians(90.0 - elevation)
    theta_t = math.asin(math.sin(theta) / IOR)
    analytic = (result.sun_irradiance * math.cos(theta) * fresnel_t_angles(np.array([theta]), 1.0, IOR)[0]
                * np.exp(-result.attenuation_per_m * 1.5 / math.cos(theta_t)))
    floor = result.floor_irradiance
    expected = np.broadcast_to(analytic[:, None, None], floor.shape)
    if eik.periodic:
        np.testing.assert_allclose(floor, expected, rtol=2e-5)
    else:
        # an open patch: where the flux-ratio map is dark (its light came from beyond the patch) so
        # is this one, and it is the analytic value wherever the flux-ratio map is; the texels
        # along the dark strip's edge are partly lit in each, differently (bilinear vs exact area)
        reference = result.comparison.floor_irradiance
        lit = reference > 0.999 * expected
        dark = reference == 0.0
        assert lit.mean() > 0.5 and (elevation == 90.0 or dark.any())
        np.testing.assert_allclose(floor[lit], expected[lit], rtol=2e-5)
        assert np.all(floor[dark] == 0.0)


@pytest.mark.parametrize("depth_m", [0.5, 1.0])
def test_lens_gain_before_focus_matches_paraxial_optics(depth_m):
    """The paraboloid lens (configs/lens.toml): carrying the Laplacian along the rays gives the
    central gain (1 − z/f)⁻² of paraxial optics before the focus: −2.3 % and −3.9 % at 0.5 and
    1.0 m on a 1.6 cm grid (−1.2 % and −1.3 % on a 0.8 cm grid), so within 5 %."""
    from test_lens import APEX_M, FOCAL_M

    scene = wc.load_scene(CONFIGS / "lens.toml", {
        "caustics.method": "eikonal", "floor.depth_m": depth_m, "optics.water_type": "none",
        "optics.wavelengths": {"min_nm": 500.0, "max_nm": 600.0, "bins": 1}, "caustics.map_resolution": 128,
        "caustics.eikonal_resolution": 128})
    result = wc.render(scene, device="cpu")
    floor = result.floor_irradiance[0].astype(np.float64)
    m = floor.shape[0]
    centre = floor[m // 2 - 1:m // 2 + 1, m // 2 - 1:m // 2 + 1].mean()
    gain = centre / floor[2, 2]
    expected = 1.0 / (1.0 - (depth_m + APEX_M) / FOCAL_M) ** 2
    assert gain == pytest.approx(expected, rel=0.05)
    assert result.eikonal_stats["layers"] > 0


def test_eikonal_config_errors():
    """A grid too coarse or too fine is refused with the key's name; a relief is refused for the sun
    map (the error names the methods that light one)."""
    with pytest.raises(wc.errors.ConfigError, match="caustics.eikonal_resolution"):
        _flat(60.0, **{"caustics.eikonal_resolution": 4})
    with pytest.raises(wc.errors.ConfigError, match="floor.shape = 'ripples' needs .*\"eikonal\""):
        _flat(60.0, **{"caustics.method": "sunmap", "floor.shape": "ripples",
                       "floor.ripple_wavelength_m": 0.5})


def _slope(method, **extra):
    """Still water in a 4 m pool over a floor sloping 10° (deeper towards +x, 1.5 m at the centre),
    the sun 65° high at azimuth 200°, no absorption, 64² map and grid."""
    return wc.load_scene(None, {
        "caustics.method": method, "water.model": "pool", "water.extent_m": 4.0, "water.resolution": 64,
        "floor.depth_m": 1.5, "floor.shape": "slope", "floor.slope_deg": 10.0, "optics.water_type": "none",
        "optics.wavelengths": "rgb", "optics.ior": IOR, "sun.elevation_deg": 65.0, "sun.azimuth_deg": 200.0,
        "sun.angular_diameter_deg": 0.0, "caustics.map_resolution": 64, "caustics.eikonal_resolution": 64,
        "caustics.wave3d_resolution": 64, **extra})


@pytest.mark.parametrize(("method", "rtol"), [("eikonal", 1e-4), ("wave3d", 0.02)])
def test_a_sloping_floor_gets_the_analytic_irradiance(method, rtol):
    """Mercier's 3-D texture lights any floor height (his Fig. 7's sand slope): still water over a
    10° slope reads E_sun cosθ T(θ) |n·t|/|t_z| on the slope's true area (t the refracted sun, n the
    slope's normal; float64 here) in every texel whose light enters the pool's water (the walls'
    shadow and the light from beyond them left out): the eikonal to 1e-4, the wave texture to 2 %
    (its damping band and lattice, as on a flat floor). The flux-ratio map is a flat floor's, so
    there is no comparison map."""
    result = wc.render(_slope(method), device="cpu")
    assert result.comparison is None
    theta = math.radians(25.0)
    sun = np.array([math.sin(theta) * math.cos(math.radians(200.0)),
                    math.sin(theta) * math.sin(math.radians(200.0)), math.cos(theta)])
    sin_t = math.sin(theta) / IOR
    t = np.array([-sun[0] / math.sin(theta) * sin_t, -sun[1] / math.sin(theta) * sin_t,
                  -math.sqrt(1 - sin_t**2)])
    slope = math.tan(math.radians(10.0))
    n = np.array([slope, 0.0, 1.0]) / math.hypot(slope, 1.0)  # z = −1.5 − x tan 10°: the normal leans to +x
    fresnel = fresnel_t_angles(np.array([theta]), 1.0, IOR)[0]
    expected = result.sun_irradiance * math.cos(theta) * fresnel * abs(n @ t) / abs(t[2])
    inner = result.floor_irradiance[:, 12:52, 12:52]
    np.testing.assert_allclose(inner, np.broadcast_to(expected[:, None, None], inner.shape), rtol=rtol)


@pytest.mark.parametrize("depth_m", [1.0, 4.0])
def test_transport_keeps_the_flux_of_the_flux_ratio_map(depth_m):
    """Carrying the Laplacian along the rays keeps the light: over the rough ocean (no absorption)
    the eikonal floor receives the flux-ratio map's flux within 0.5 % (measured +0.35 %, +0.29 %),
    before and past the first caustics."""
    r = wc.render(wc.load_scene(CONFIGS / "ocean.toml", {
        "caustics.method": "eikonal", "water.resolution": 64, "caustics.map_resolution": 64,
        "caustics.eikonal_resolution": 64, "optics.water_type": "none", "floor.depth_m": depth_m,
        "optics.wavelengths": "rgb"}), device="cpu")
    np.testing.assert_allclose(r.floor_flux_w_nm, r.comparison.floor_flux_w_nm, rtol=5e-3)


# Mercier 2013 §3.3: the threshold post-process (caustics.eikonal_threshold_depth_m) -------------

@pytest.mark.parametrize("spread_deg", [15.0, 30.0])
def test_threshold_wave_spreads_light_in_cones_of_the_spread_angle(spread_deg):
    """A spot of light (a Gaussian of σ = 1.5 cells) at the threshold layer, run down 40 layers by
    the §3.3 wave: at 20, 30 and 40 layers its brightest ring lies Δz·tan(spread) from the spot, to
    between −0.5 and +2 cells (the spot's own width adds), "the angle of the blue cones" of the
    paper's Fig. 5; on a periodic grid the layer's sum is kept (1e-5, float32)."""
    n, layers = 128, 41
    grid = eikonal_kernels.EikonalGrid()
    grid.n, grid.layers, grid.h, grid.periodic = n, layers, 1.0, 1
    y, x = np.mgrid[0:n, 0:n] - n // 2
    r = np.hypot(x, y)
    volume = np.zeros((layers, n, n), np.float32)
    volume[0] = np.exp(-0.5 * (r / 1.5) ** 2)
    volume[0] /= volume[0].sum()
    horizontal = wp.array(volume, dtype=wp.float32, device="cpu")
    courant2 = math.tan(math.radians(spread_deg)) ** 2
    for k in range(layers - 1):
        wp.launch(eikonal_kernels.threshold_wave_step, dim=(n, n),
                  inputs=[grid, horizontal, k, courant2, int(k == 0)], device="cpu")
    out = horizontal.numpy()
    for depth in (20, 30, 40):
        ring = np.array([out[depth][(r >= q - 0.5) & (r < q + 0.5)].mean() for q in range(n // 2)])
        expected = depth * math.tan(math.radians(spread_deg))
        assert expected - 0.5 <= np.argmax(ring) <= expected + 2.0, (depth, np.argmax(ring), expected)
        assert out[depth].sum(dtype=np.float64) == pytest.approx(1.0, abs=1e-5)


def test_threshold_post_process_leaves_uniform_light_alone_and_spreads_caustics():
    """Still water gives a uniform texture, which the wave leaves as it is (1e-6); under the ocean
    the caustics below the threshold spread (the floor's contrast falls) while the floor's mean is
    kept to the clamping of the wave's negative dips (5e-3; measured 1e-3); unset, the floor map is
    the plain eikonal's to the bit; the key needs the eikonal method."""
    still = {"caustics.eikonal_resolution": 32}
    plain = wc.render(_flat(60.0, **still), device="cpu").floor_irradiance
    spread = wc.render(_flat(60.0, **still, **{"caustics.eikonal_threshold_depth_m": 0.5}),
                       device="cpu").floor_irradiance
    np.testing.assert_allclose(spread, plain, rtol=1e-6)
    base = {"caustics.method": "eikonal", "water.resolution": 64, "caustics.map_resolution": 64,
            "optics.wavelengths": "rgb", "caustics.eikonal_resolution": 64, "sun.angular_diameter_deg": 0.0}
    off = wc.render(wc.load_scene(CONFIGS / "ocean.toml", base), device="cpu").floor_irradiance.sum(0)
    unset = wc.render(wc.load_scene(CONFIGS / "ocean.toml", {**base, "caustics.eikonal_spread_deg": 30.0}),
                      device="cpu").floor_irradiance.sum(0)
    np.testing.assert_array_equal(unset, off)
    on = wc.render(wc.load_scene(CONFIGS / "ocean.toml", {**base, "caustics.eikonal_threshold_depth_m": 1.0}),
                   device="cpu").floor_irradiance.sum(0)
    assert on.mean() == pytest.approx(off.mean(), rel=5e-3)
    assert on.std() / on.mean() < 0.5 * off.std() / off.mean()
    with pytest.raises(wc.ConfigError, match="eikonal_threshold_depth_m"):
        wc.load_scene(CONFIGS / "ocean.toml", {"caustics.eikonal_threshold_depth_m": 1.0})
