"""Sun-map caustics (GPU Gems ch. 2): flat water, the refraction geometry, the procedural path."""

import math

import numpy as np
import pytest

import warpcaustics as wc
from warpcaustics.caustics.sunmap import SunMapCaustics
from warpcaustics.errors import ConfigError
from warpcaustics.water import HeightfieldWater, ProceduralWater

from helpers import CONFIGS, fresnel_t_angles

IOR = 1.333
DISK_DEG, HALO_DEG = 0.53, 5.3


def _scene(**overrides):
    base = {
        "caustics.method": "sunmap",
        "water.model": "flat",
        "water.extent_m": 4.0,
        "water.resolution": 64,
        "caustics.map_resolution": 64,
        "optics.ior": IOR,
        "optics.wavelengths": {"min_nm": 450.0, "max_nm": 650.0, "bins": 2},
        "sun.angular_diameter_deg": DISK_DEG,  # the disk the sun map draws
    }
    base.update(overrides)
    return wc.load_scene(None, base)


def snell(d, n, eta):
    """Refract unit d through unit normal n (facing against d), eta = n1/n2 (float64); None on TIR."""
    c = -np.dot(n, d)
    k = 1.0 - eta * eta * (1.0 - c * c)
    if k < 0:
        return None
    t = eta * d + (eta * c - math.sqrt(k)) * n
    return t / np.linalg.norm(t)


def brightness_of(gamma_deg):
    """The documented soft sun map: 1 on the disk, a raised cosine to 0 at the halo's edge."""
    r_d, r_h = DISK_DEG / 2, HALO_DEG / 2
    if gamma_deg <= r_d:
        return 1.0
    if gamma_deg >= r_h:
        return 0.0
    return 0.5 * (1 + math.cos(math.pi * (gamma_deg - r_d) / (r_h - r_d)))


@pytest.mark.parametrize("elevation", [5.0, 35.0, 90.0])
def test_flat_water_sun_map_is_uniform(elevation):
    """Still water sends every backward ray to the sun's centre: brightness 1 everywhere, and the
    scaled map equals the flat-water irradiance E·cosθ·T(θ)·e^{−cD/cosθt} of the flux-ratio map."""
    # a point sun: the flux-ratio reference is a point sun's (the sun map draws it as a halo alone)
    result = wc.render(_scene(**{"sun.elevation_deg": elevation, "sun.azimuth_deg": 20.0,
                                 "sun.angular_diameter_deg": 0.0}), device="cpu")
    np.testing.assert_array_equal(result.sunmap_brightness, 1.0)
    assert result.comparison.method == "fluxratio"
    theta = math.radians(90.0 - elevation)
    theta_t = math.asin(math.sin(theta) / IOR)
    depth = result.scene.config.floor.depth_m
    analytic = (
        result.sun_irradiance
        * math.cos(theta)
        * fresnel_t_angles(np.array([theta]), 1.0, IOR)[0]
        * np.exp(-result.attenuation_per_m * depth / math.cos(theta_t))
    )
    # float32 flux-ratio map, whose mean sets the scale: 1e-5
    expected = np.broadcast_to(analytic[:, None, None], result.floor_irradiance.shape)
    np.testing.assert_allclose(result.floor_irradiance, expected, rtol=1e-5)


@pytest.mark.parametrize(
    ("slope_deg", "elevation"),
    [(0.5, 90.0), (3.0, 90.0), (5.0, 90.0), (12.0, 90.0), (3.0, 50.0), (-6.0, 50.0)],
)
def test_tilted_plane_brightness_matches_snell(device, slope_deg, elevation):
    """A plane tilted about the y axis: the backward ray leaves it at an angle γ to the sun given
    by Snell's law (float64, written here), and the brightness is the sun map at γ — for γ on the
    disk, in the halo and beyond it."""
    n, extent = 64, 4.0
    x = (np.arange(n) + 0.5) * extent / n - extent / 2
    a = math.tan(math.radians(slope_deg))
    water = HeightfieldWater(np.tile(a * x, (n, 1)), extent, device)
    surface = water.at(0.0)
    az = math.radians(10.0)
    el = math.radians(elevation)
    sun = np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])
    cfg = _scene(**{"sun.elevation_deg": elevation, "sun.azimuth_deg": 10.0, "floor.depth_m": 2.0}).config
    stage = SunMapCaustics(cfg, sun, IOR, device, periodic=True)
    b = stage.run(surface, water, 0.0).numpy()

    up = -snell(-sun, np.array([0.0, 0.0, 1.0]), 1.0 / IOR)
    normal = np.array([-a, 0.0, 1.0]) / math.hypot(a, 1.0)
    out = snell(up, -normal, IOR)
    gamma = math.degrees(math.atan2(np.linalg.norm(np.cross(out, sun)), np.dot(out, sun)))
    expected = brightness_of(gamma)
    # Only texels whose backward ray meets the plane z = a·x away from its periodic seam (where the
    # wrapped differences are wrong): p = floor point + up·τ with a·p_x = p_z.
    m = b.shape[0]
    c = (np.arange(m) + 0.5) * extent / m - extent / 2
    tau = (a * c + 2.0) / (up[2] - a * up[0])
    px = (c + up[0] * tau + extent / 2) % extent - extent / 2
    interior = np.abs(px) < extent / 2 - 8 * extent / n
    assert interior.sum() > m / 2
    np.testing.assert_allclose(b[:, interior], expected, atol=2e-4)


def test_procedural_sun_map_uses_the_analytic_gradient(device):
    """Under an overhead sun the backward ray is vertical, so each texel sees the surface right
    above it: the procedural path's brightness equals the sun map of the chapter's gradient there
    (float64 central differences of the wave function, Snell written here)."""
    from test_procedural import PARAMS, chapter_wave

    n, extent, m = 64, 2.0, 48
    params = dict(PARAMS, amplitude=0.002)
    water = ProceduralWater(n, extent, device, scale_m=1.0, **params)
    cfg = _scene(
        **{
            "sun.elevation_deg": 90.0,
            "water.model": "procedural",
            "water.extent_m": extent,
            "caustics.map_resolution": m,
        }
    ).config
    sun = np.array([0.0, 0.0, 1.0])
    stage = SunMapCaustics(cfg, sun, IOR, device, periodic=False)
    b = stage.run(water.at(0.4), water, 0.4).numpy()

    c = (np.arange(m) + 0.5) * extent / m - extent / 2
    xs, ys = np.meshgrid(c, c)
    h = 1e-6
    wave = lambda x, y: chapter_wave(x, y, 0.4, scale_m=1.0, **params)  # noqa: E731
    gx = (wave(xs + h, ys) - wave(xs - h, ys)) / (2 * h)
    gy = (wave(xs, ys + h) - wave(xs, ys - h)) / (2 * h)
    expected = np.empty_like(gx)
    for j in range(m):
        for i in range(m):
            normal = np.array([-gx[j, i], -gy[j, i], 1.0])
            out = snell(sun, -normal / np.linalg.norm(normal), IOR)
            gamma = 90.0 if out is None else math.degrees(math.atan2(np.hypot(out[0], out[1]), out[2]))
            expected[j, i] = brightness_of(gamma)
    assert 0.05 < expected.mean() < 0.95  # a mix of lit, half-lit and dark texels
    np.testing.assert_allclose(b, expected, atol=1e-3)


def test_sunmap_config_errors():
    """The halo must surround the disk; receivers and the camera need photons or beams."""
    with pytest.raises(ConfigError, match="caustics.sunmap_halo_deg"):
        _scene(**{"caustics.sunmap_halo_deg": 0.4})
    with pytest.raises(ConfigError, match="camera.enabled"):
        _scene(**{"camera.enabled": True})


def test_compare_command_on_the_lens(tmp_path, capsys):
    """``warpcaustics compare`` renders one frame by each method: the flux-ratio map compares to
    itself exactly, beams agree with it (same footprints gathered instead of scattered), the sun
    map sees the lens's bright centre (positive correlation), and every file is written."""
    from warpcaustics.cli import main

    out = tmp_path / "cmp"
    code = main(["compare", str(CONFIGS / "lens.toml"), "--out", str(out), "--methods", "sunmap,beams",
                 "--set", "caustics.map_resolution=64",
                 "--set", "optics.wavelengths={min_nm = 450.0, max_nm = 650.0, bins = 2}"])
    assert code == 0
    rows = {r["method"]: r for r in __import__("json").loads((out / "compare.json").read_text())["rows"]}
    assert list(rows) == ["fluxratio", "sunmap", "beams"]
    assert rows["fluxratio"]["relative_l1"] == 0.0 and rows["fluxratio"]["correlation"] == pytest.approx(1.0)
    assert rows["beams"]["relative_l1"] < 1e-3
    assert rows["sunmap"]["correlation"] > 0.1
    for name in ("compare.csv", "compare.png", "fluxratio/frame_0000.exr", "sunmap/frame_0000.exr",
                 "sunmap/frame_0000_fluxratio.exr", "beams/run.json"):
        assert (out / name).is_file(), name
    assert main(["compare", str(CONFIGS / "lens.toml"), "--out", str(out), "--methods", "raytrace"]) == 2
    assert "not a floor-caustics method" in capsys.readouterr().err
