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


# --- §2.5's per-pixel variant (caustics.sunmap_variant = "per_pixel") ---


@pytest.mark.parametrize("elevation", [20.0, 90.0])
def test_per_pixel_flat_water_is_uniform(elevation):
    """Still water: every normal is vertical, so every texel reads the light map's centre."""
    result = wc.render(_scene(**{"sun.elevation_deg": elevation, "caustics.sunmap_variant": "per_pixel"}),
                       device="cpu")
    np.testing.assert_array_equal(result.sunmap_brightness, 1.0)


@pytest.mark.parametrize(("slope_deg", "elevation"), [(0.3, 90.0), (2.0, 90.0), (6.0, 90.0), (4.0, 40.0)])
def test_per_pixel_tilted_plane_reads_the_light_map(device, slope_deg, elevation):
    """A plane z = a·x: §2.5 evaluates it where the sun's still-water refracted ray through the
    texel crosses z = 0, draws the line along its normal to the plane the local depth d above, and
    reads the light map at the offset d·tan θ_n, i.e. the sun map at γ = (n − 1)/H · d·|a| (float64,
    written here). The depth varies along x, so the brightness does too (the chapter: deeper
    floors see a sharper sun)."""
    n, extent, depth = 64, 4.0, 2.0
    x = (np.arange(n) + 0.5) * extent / n - extent / 2
    a = math.tan(math.radians(slope_deg))
    water = HeightfieldWater(np.tile(a * x, (n, 1)), extent, device)
    el, az = math.radians(elevation), math.radians(10.0)
    sun = np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])
    cfg = _scene(**{"sun.elevation_deg": elevation, "sun.azimuth_deg": 10.0, "floor.depth_m": depth,
                    "caustics.sunmap_variant": "per_pixel"}).config
    b = SunMapCaustics(cfg, sun, IOR, device, periodic=True).run(water.at(0.0), water, 0.0).numpy()

    up = -snell(-sun, np.array([0.0, 0.0, 1.0]), 1.0 / IOR)
    m = b.shape[0]
    c = (np.arange(m) + 0.5) * extent / m - extent / 2
    px = (c + up[0] * depth / up[2] + extent / 2) % extent - extent / 2
    interior = np.abs(px) < extent / 2 - 2 * extent / n  # away from the tiled plane's seam
    gamma = np.degrees((IOR - 1.0) / depth * (a * px + depth) * abs(a))
    expected = np.array([brightness_of(g) for g in gamma])
    assert interior.sum() > m / 2
    np.testing.assert_allclose(b[:, interior], np.broadcast_to(expected[interior], b[:, interior].shape),
                               atol=2e-4)


def test_per_pixel_light_map_matches_snell_for_small_tilts():
    """Our scale of the chapter's light map, (n − 1)/H, makes its angle Snell's to first order at
    the still depth H (the chapter: "little visual difference" from refracting): the exact
    deviation of an overhead sun's backward ray, asin(n sin θ) − θ, against (n − 1) tan θ, float64.
    Within 0.1 % up to 3° of tilt (the halo's edge for 0.53°/5.3°: 7.9°), 0.6 % at 10°; beyond,
    the light map reads too near its centre (2.5 % at 20°, 16 % at 40°) and never reaches total
    internal reflection."""
    for tilt_deg, low_by in [(0.5, 1.4e-5), (3.0, 5.1e-4), (10.0, 5.8e-3), (20.0, 0.0252), (40.0, 0.156)]:
        t = math.radians(tilt_deg)
        snell_gamma = math.asin(IOR * math.sin(t)) - t
        light_map_gamma = (IOR - 1.0) * math.tan(t)
        assert light_map_gamma < snell_gamma
        assert (snell_gamma - light_map_gamma) / snell_gamma == pytest.approx(low_by, rel=0.02), tilt_deg


def test_per_pixel_procedural_uses_the_gradient_above_the_texel(device):
    """Overhead sun: the per-pixel variant reads the chapter's ``gradwave`` at the texel itself
    (float64 central differences of ``wave``) and its ``wave`` for the local depth."""
    from test_procedural import PARAMS, chapter_wave

    n, extent, m, depth = 64, 2.0, 48, 1.0
    params = dict(PARAMS, amplitude=0.002)
    water = ProceduralWater(n, extent, device, scale_m=1.0, **params)
    cfg = _scene(**{"sun.elevation_deg": 90.0, "water.model": "procedural", "water.extent_m": extent,
                    "caustics.map_resolution": m, "floor.depth_m": depth,
                    "caustics.sunmap_variant": "per_pixel"}).config
    b = SunMapCaustics(cfg, np.array([0.0, 0.0, 1.0]), IOR, device, periodic=False).run(
        water.at(0.4), water, 0.4).numpy()

    c = (np.arange(m) + 0.5) * extent / m - extent / 2
    xs, ys = np.meshgrid(c, c)
    h = 1e-6
    wave = lambda x, y: chapter_wave(x, y, 0.4, scale_m=1.0, **params)  # noqa: E731
    gx = (wave(xs + h, ys) - wave(xs - h, ys)) / (2 * h)
    gy = (wave(xs, ys + h) - wave(xs, ys - h)) / (2 * h)
    gamma = np.degrees((IOR - 1.0) / depth * (wave(xs, ys) + depth) * np.hypot(gx, gy))
    expected = np.vectorize(brightness_of)(gamma)
    assert 0.05 < expected.mean() < 0.95
    np.testing.assert_allclose(b, expected, atol=1e-3)
