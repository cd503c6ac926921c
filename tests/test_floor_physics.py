"""Floor caustics against analytic values: flat water, energy conservation, periodic wrap."""

import numpy as np
import pytest

import warpcaustics as wc
from warpcaustics import reference

from helpers import flat_floor_irradiance, flat_water_scene, fresnel_t_angles


def _flat_scene(elevation_deg, depth_m, water_type="pure", **extra):
    return flat_water_scene(elevation_deg, depth_m, water_type, **{"caustics.map_resolution": 48, **extra})


@pytest.mark.parametrize("elevation_deg", [15.0, 40.0, 65.0, 90.0])
@pytest.mark.parametrize("depth_m", [0.5, 5.0, 30.0])
def test_flat_water_matches_beer_lambert_and_fresnel(device, elevation_deg, depth_m):
    """Flat water: E = E_sun cosθ T(θ) exp(-c D / cosθ_t), uniform over the floor (1e-4)."""
    result = wc.render(_flat_scene(elevation_deg, depth_m), device=device)
    expected = flat_floor_irradiance(result, elevation_deg, depth_m)
    floor = result.floor_irradiance.astype(np.float64)
    assert np.all(result.attenuation_per_m > 0)  # the pure-water path is really exercised
    # The issue asks for 0.5 %; float32 geometry reaches ~1e-5, so hold it to 1e-4.
    np.testing.assert_allclose(floor, np.broadcast_to(expected[:, None, None], floor.shape), rtol=1e-4)


def test_flat_nonabsorbing_water_keeps_all_transmitted_flux(device):
    """water_type = none: floor flux = E_sun cosθ T(θ) L² exactly (nothing lost on the way down)."""
    result = wc.render(_flat_scene(50.0, 3.0, "none"), device=device)
    theta = np.radians(40.0)
    t_fresnel = fresnel_t_angles(np.array([theta]), 1.0, 1.333)[0]
    expected = result.sun_irradiance * np.cos(theta) * t_fresnel * 8.0**2  # L = 8 m
    np.testing.assert_allclose(result.floor_flux_w_nm, expected, rtol=1e-5)


def _rough_ocean(**extra):
    overrides = {"water.model": "fft", "water.resolution": 64, "water.extent_m": 8.0,
                 "water.wind_speed_m_s": 5.0, "water.phillips_amplitude": 4e-3, "floor.depth_m": 6.0,
                 "caustics.map_resolution": 96, "sun.elevation_deg": 55.0, "sun.azimuth_deg": 20.0,
                 "optics.water_type": "none", "optics.wavelengths.bins": 4, "water.seed": 3,
                 "sun.angular_diameter_deg": 0.0}  # the numpy reference is a point sun's
    overrides.update(extra)
    return wc.load_scene(None, overrides)


def _transmitted_flux_float64(result, ior=None):
    """Σ over surface triangles of E_sun · A⊥ · mean Fresnel T, from the surface alone (float64);
    ``ior`` per band (dispersion) or one index for all."""
    p = result.surface_positions.astype(np.float64)
    nrm = result.surface_normals.astype(np.float64)
    s = result.scene.sun_direction
    n = p.shape[0]
    idx, shift = reference.triangles(n, result.extent_m)
    tri = p.reshape(-1, 3)[idx]
    tri[..., :2] += shift
    a_perp = 0.5 * np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]) @ s
    cos_i = nrm.reshape(-1, 3) @ s
    indices = np.broadcast_to(1.333 if ior is None else np.asarray(ior), result.sun_irradiance.shape)
    flux = []
    for e_sun, n_k in zip(result.sun_irradiance, indices, strict=True):
        t = fresnel_t_angles(np.arccos(np.clip(cos_i, -1, 1)), 1.0, n_k)
        t[cos_i <= 0] = 0.0
        flux.append(e_sun * np.where(a_perp > 0, a_perp * t[idx].mean(axis=1), 0.0).sum())
    return np.array(flux)


def test_energy_conserved_on_rough_ocean(device):
    """Non-absorbing water: flux on the floor = flux transmitted through the surface (1e-4),
    with focused (sub-texel) and folded footprints present."""
    result = wc.render(_rough_ocean(), device=device)
    transmitted = _transmitted_flux_float64(result)
    np.testing.assert_allclose(result.floor_flux_w_nm, transmitted, rtol=1e-4)

    # The scene must really contain the hard cases the deposit claims to handle.
    hit, _, _ = reference.refract_to_floor(result.surface_positions.astype(np.float64),
                                           result.surface_normals.astype(np.float64),
                                           result.scene.sun_direction, 1.333, -6.0)
    idx, shift = reference.triangles(64, 8.0)
    q = hit.reshape(-1, 2)[idx] + shift
    e1, e2 = q[:, 1] - q[:, 0], q[:, 2] - q[:, 0]
    signed = 0.5 * (e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    texel_area = (8.0 / 96) ** 2
    assert np.mean(signed < 0) > 0.01, "some footprints fold over"
    assert np.mean(np.abs(signed) < texel_area) > 0.05, "some footprints are smaller than a texel"


def test_warp_floor_map_matches_float64_numpy(device):
    """The Warp floor map equals the float64 numpy implementation of the same deposit (L1 1e-4)."""
    result = wc.render(_rough_ocean(**{"optics.water_type": "pure"}), device=device)
    floor64, _ = reference.floor_caustics(
        result.surface_positions, result.surface_normals, result.scene.sun_direction, 1.333, 6.0,
        result.sun_irradiance, result.attenuation_per_m, result.extent_m, 96)
    l1 = np.abs(result.floor_irradiance - floor64).sum() / np.abs(floor64).sum()
    assert l1 < 1e-4, f"relative L1 {l1:.2e}"  # float32 positions and atomics vs float64


def test_floor_map_is_periodic(device, tmp_path):
    """Rolling a periodic height field by whole cells rolls the floor map by the same distance."""
    ocean = wc.render(_rough_ocean(), device=device)
    heights = ocean.surface_positions[..., 2]
    base = {"water.model": "heightfield", "water.extent_m": 8.0, "floor.depth_m": 6.0,
            "caustics.map_resolution": 128, "sun.elevation_deg": 55.0, "sun.azimuth_deg": 20.0,
            "optics.water_type": "none", "optics.wavelengths.bins": 1}
    maps = []
    for name, h in (("a.npy", heights), ("b.npy", np.roll(heights, (5, -9), axis=(0, 1)))):
        np.save(tmp_path / name, h)
        scene = wc.load_scene(None, {**base, "water.file": str(tmp_path / name)})
        maps.append(wc.render(scene, device=device).floor_irradiance[0])
    # 64 vertices, 128 texels: a shift of one cell is two texels; footprints wrap across the edges.
    expected = np.roll(maps[0], (10, -18), axis=(0, 1))
    # The shifted run sees other float32 coordinates: a footprint that straddles a texel edge may
    # move ~1e-3 of its flux across it. Whole-map agreement is far tighter than any misplaced wrap.
    l1 = np.abs(maps[1] - expected).sum() / np.abs(expected).sum()
    assert l1 < 1e-5, f"relative L1 {l1:.2e}"
    np.testing.assert_allclose(maps[1], expected, rtol=0, atol=2e-3 * maps[0].max())


def test_crests_shade_the_surface_behind_them(device, tmp_path):
    """A ridged sea under a low sun: vertices are shaded exactly where a float64 ray march over the
    1-D profile finds a crest between them and the sun (boundary vertices may differ by one)."""
    n, extent, amplitude, elevation = 128, 8.0, 0.4, 12.0
    x = (np.arange(n) + 0.5) * extent / n - extent / 2
    profile = amplitude * np.sin(2 * np.pi * 2 * x / extent) + 0.1 * np.sin(2 * np.pi * 5 * x / extent)
    np.save(tmp_path / "ridges.npy", np.tile(profile, (n, 1)))
    scene = wc.load_scene(None, {"water.model": "heightfield", "water.file": str(tmp_path / "ridges.npy"),
                                 "water.extent_m": extent, "sun.elevation_deg": elevation,
                                 "sun.azimuth_deg": 0.0, "floor.depth_m": 3.0,
                                 "caustics.map_resolution": 32, "optics.wavelengths.bins": 1})
    renderer = wc.Renderer(scene, device)
    renderer.render(0.0)
    visible = renderer.visible.numpy()[0]  # one row: the ridges run along y

    # float64 reference on a 64× finer, exactly periodic profile: shaded iff some point between the
    # vertex and 2 periods towards the sun (+x) rises above the ray.
    fine = np.linspace(0, 2 * extent, 64 * 2 * n, endpoint=False)
    tan_el = np.tan(np.radians(elevation))
    h = lambda xx: amplitude * np.sin(2 * np.pi * 2 * xx / extent) + 0.1 * np.sin(2 * np.pi * 5 * xx / extent)  # noqa: E731
    expected = np.array([np.all(h(xi + fine[1:]) <= h(xi) + fine[1:] * tan_el) for xi in x], float)
    assert 0.2 < 1 - expected.mean() < 0.8, "the scene must have both lit and shaded vertices"
    mismatch = np.nonzero(visible != expected)[0]
    boundaries = np.nonzero(np.diff(np.r_[expected, expected[0]]))[0]
    # A mismatch is allowed only at a shadow edge (the bilinear surface differs from the sine there).
    assert all(np.min(np.abs((mismatch[:, None] - boundaries[None, :] + n // 2) % n - n // 2), axis=1) <= 1)


def test_floor_never_receives_more_than_the_beam(device):
    """Low sun on a steep sea: the floor flux stays below E_sun·L²·sinθ_el even though the
    triangles facing the sun add up to more than the beam's cross-section (crests shade)."""
    scene = wc.load_scene(None, {"water.model": "fft", "water.resolution": 64, "water.extent_m": 8.0,
                                 "water.wind_speed_m_s": 5.0, "water.phillips_amplitude": 0.05,
                                 "floor.depth_m": 20.0, "caustics.map_resolution": 64,
                                 "sun.elevation_deg": 10.0, "optics.water_type": "none",
                                 "optics.wavelengths.bins": 1, "water.seed": 1})
    result = wc.render(scene, device=device)
    s = scene.sun_direction
    idx, shift = reference.triangles(64, 8.0)
    tri = result.surface_positions.astype(np.float64).reshape(-1, 3)[idx]
    tri[..., :2] += shift
    a_perp = 0.5 * np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]) @ s
    beam_area = 64.0 * s[2]
    assert np.maximum(a_perp, 0).sum() > 1.05 * beam_area, "without shading this sea would overshoot"
    assert result.floor_flux_w_nm[0] <= result.sun_irradiance[0] * beam_area


def test_water_below_the_floor_is_refused(device):
    """A floor shallower than the wave troughs stops with a one-line error naming floor.depth_m."""
    scene = wc.load_scene(None, {"water.resolution": 32, "caustics.map_resolution": 16,
                                 "water.phillips_amplitude": 0.5, "floor.depth_m": 0.01,
                                 "optics.wavelengths.bins": 1})
    with pytest.raises(wc.WarpcausticsError, match=r"floor.depth_m = 0.01 is too shallow"):
        wc.render(scene, device=device)


def test_huge_footprints_stay_bounded_and_conserve_flux(device):
    """Grazing rays onto a deep floor make footprints of millions of texels: they are deposited by
    area samples (bounded work) and the floor still receives all the transmitted flux."""
    scene = wc.load_scene(None, {"water.model": "fft", "water.resolution": 32, "water.extent_m": 8.0,
                                 "water.phillips_amplitude": 0.2, "floor.depth_m": 50.0,
                                 "caustics.map_resolution": 64, "sun.elevation_deg": 5.0,
                                 "optics.water_type": "none", "optics.wavelengths.bins": 2})
    renderer = wc.Renderer(scene, device)
    result = renderer.render(0.0)
    assert renderer.method.floor.coarse_count.numpy()[0] > 0
    np.testing.assert_allclose(result.floor_flux_w_nm, result.transmitted_flux_w_nm, rtol=1e-4)


def test_dispersion_flat_water_and_energy(device):
    """With dispersion every band refracts with its own n(λ): still water gives each band
    E_sun cosθ T_λ(θ) exp(−c D/cosθ_t,λ) (1e-4; one index for all bands would miss by 5e-3), and a
    rough ocean keeps each band's transmitted flux (1e-4, against a float64 sum with that band's n)
    while the bands' maps differ (coloured fringes)."""
    from warpcaustics.optics import spectra

    result = wc.render(_flat_scene(35.0, 5.0, **{"optics.dispersion": True}), device=device)
    n = spectra.quan_fry_index(result.wavelengths_nm, 35.0, 20.0)
    np.testing.assert_allclose(result.ior, n)
    expected = flat_floor_irradiance(result, 35.0, 5.0, ior=n)
    floor = result.floor_irradiance.astype(np.float64)
    np.testing.assert_allclose(floor, np.broadcast_to(expected[:, None, None], floor.shape), rtol=1e-4)

    rough = wc.render(_rough_ocean(**{"optics.dispersion": True}), device=device)
    np.testing.assert_allclose(rough.floor_flux_w_nm, _transmitted_flux_float64(rough, rough.ior), rtol=1e-4)
    normalised = rough.floor_irradiance / rough.floor_irradiance.mean(axis=(1, 2), keepdims=True)
    assert np.abs(normalised[0] - normalised[-1]).mean() > 1e-3  # blue and red caustics differ
