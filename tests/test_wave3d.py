"""Wave caustic texture (after Mercier 2013 §4): still water, boundedness, the active band, flux."""

import math

import numpy as np
import pytest

import warpcaustics as wc
from warpcaustics.errors import ConfigError

from helpers import CONFIGS, fresnel_t_angles

IOR = 1.333


def _scene(elevation=90.0, model="flat", **extra):
    overrides = {"caustics.method": "wave3d", "water.model": model, "water.extent_m": 4.0,
                 "water.resolution": 64, "caustics.map_resolution": 64, "caustics.wave3d_resolution": 48,
                 "sun.elevation_deg": elevation, "sun.azimuth_deg": 25.0, "optics.ior": IOR,
                 "floor.depth_m": 1.5, "sun.angular_diameter_deg": 0.0,  # a point sun's references
                 "optics.wavelengths": {"min_nm": 450.0, "max_nm": 650.0, "bins": 2}}
    overrides.update(extra)
    return wc.load_scene(None, overrides)


@pytest.mark.parametrize("elevation", [90.0, 40.0, 15.0])
def test_still_water_gives_the_flat_irradiance(elevation):
    """Still water on a periodic patch: the refracted plane wave is an exact mode of the grid, so
    the floor is uniform (max/min ≤ 1.015; measured 1.000, 1.011, 1.010 at 90°, 40°, 15°) at
    E_sun cosθ T(θ) e^{−cD/cosθt} (to 2 %: what the damping band under the floor reflects and the
    periodic lattice's tilt)."""
    result = wc.render(_scene(elevation), device="cpu")
    floor = result.floor_irradiance
    assert (floor.max(axis=(1, 2)) / floor.min(axis=(1, 2))).max() < 1.015
    np.testing.assert_allclose(floor.mean(axis=(1, 2)), _analytic(result, elevation), rtol=0.02)


@pytest.mark.parametrize("elevation", [90.0, 40.0, 12.0])
def test_open_patch_lets_still_water_through_its_faces(elevation):
    """Still water on an open (non-periodic) patch: the faces pass the plane wave, so the floor is
    the flat irradiance (median within 2 %, 90 % of texels within 8 %) wherever the flux-ratio
    map is lit, and dark exactly where that map is (light from beyond the patch)."""
    result = wc.render(_scene(elevation, "procedural", **{"water.procedural_amplitude": 0.0}), device="cpu")
    floor = result.floor_irradiance
    reference = result.comparison.floor_irradiance
    expected = np.broadcast_to(_analytic(result, elevation)[:, None, None], floor.shape)
    lit = reference > 0.999 * expected
    ratio = floor[lit] / expected[lit]
    assert abs(np.median(ratio) - 1.0) < 0.02
    assert np.all(np.abs(np.percentile(ratio, [5, 95]) - 1.0) < 0.08)
    assert np.all(floor[reference == 0.0] == 0.0)


def _analytic(result, elevation):
    theta = math.radians(90.0 - elevation)
    theta_t = math.asin(math.sin(theta) / IOR)
    return (result.sun_irradiance * math.cos(theta) * fresnel_t_angles(np.array([theta]), 1.0, IOR)[0]
            * np.exp(-result.attenuation_per_m * 1.5 / math.cos(theta_t)))


def test_texture_stays_finite_and_bounded_for_1000_steps():
    """Steep procedural waves (slopes near 1, folding just under the surface), 1000 steps: the
    field stays finite, and no node's intensity exceeds 100× the mean — the damping band and the
    leapfrog at Courant 0.5 keep it stable."""
    scene = _scene(60.0, "procedural", **{"water.procedural_amplitude": 0.02,
                                          "caustics.wave3d_resolution": 48})
    renderer = wc.Renderer(scene, device="cpu")
    renderer.render(0.0)
    wave = renderer.method.approximate
    surface = renderer.water.at(0.0)
    highest = float(surface.positions.numpy()[..., 2].max())
    wave.run(surface, highest, steps=1000)
    texture = wave.texture()
    u = wave.u.numpy()
    assert np.all(np.isfinite(texture)) and np.all(np.isfinite(u))
    below = texture[int(wave.top.numpy().max()) + 1:]
    assert below.mean() > 0.05  # light does get through
    assert below.max() < 100.0 * below.mean()


def test_only_the_layers_the_wave_can_reach_are_stepped():
    """After s steps nothing has moved more than s nodes below the deepest driven node (the
    stencil's domain of dependence): those layers are still exactly zero, and the node updates
    counted are fewer than a full grid's."""
    renderer = wc.Renderer(_scene(), device="cpu")
    renderer.render(0.0)
    wave = renderer.method.approximate
    surface = renderer.water.at(0.0)
    wave.run(surface, 0.0, steps=10)
    top = int(wave.top.numpy().max())
    u = wave.u.numpy()
    assert np.abs(u[top + 1:top + 4]).max() > 0.0
    assert np.all(u[top + 12:] == 0.0)
    assert wave.stats.node_updates < 10 * wave.layers * 48 * 48


def test_wave_floor_flux_matches_the_flux_ratio_map():
    """Non-absorbing water under the default ocean (64² grid): the wave's floor flux is within 2 %
    of the flux-ratio map's (measured +0.5 % at 128²): energy is carried, not made."""
    scene = wc.load_scene(CONFIGS / "ocean.toml", {
        "caustics.method": "wave3d", "water.resolution": 64, "caustics.map_resolution": 64,
        "caustics.wave3d_resolution": 64, "optics.water_type": "none", "floor.depth_m": 2.0,
        "optics.wavelengths": {"min_nm": 500.0, "max_nm": 600.0, "bins": 1}})
    result = wc.render(scene, device="cpu")
    ratio = result.floor_flux_w_nm / result.comparison.floor_flux_w_nm
    np.testing.assert_allclose(ratio, 1.0, atol=0.02)


def test_grid_method_config_errors():
    """Too few or too many grid spacings per wavelength, and dispersion with a method that traces
    one index, are refused with one line naming the key."""
    with pytest.raises(ConfigError, match="caustics.wave3d_cells_per_wavelength"):
        _scene(**{"caustics.wave3d_cells_per_wavelength": 2.0})
    with pytest.raises(ConfigError, match="caustics.wave3d_cells_per_wavelength = 10"):
        _scene(**{"caustics.wave3d_cells_per_wavelength": 10.0})  # λ > L/6 at 48 nodes
    for method in ("wave3d", "eikonal", "sunmap"):
        with pytest.raises(ConfigError, match="optics.dispersion"):
            _scene(**{"caustics.method": method, "optics.dispersion": True})
