"""The camera above the water (de la Fuente 2011 §4.2's scene division): still water against the
analytic reflected + transmitted radiance, the sky seen directly, and the errors."""

import math

import numpy as np
import pytest

import warpcaustics as wc
from warpcaustics.errors import ConfigError, WarpcausticsError
from warpcaustics.optics import spectra
from warpcaustics.optics.phase import PhaseFunction

from helpers import CONFIGS, fresnel_t_angles

IOR = 1.333
DEPTH_M = 2.0
CAMERA = np.array([0.3, -1.0, 1.5])


def _scene(**extra):
    base = {
        "caustics.method": "beams",
        "water.model": "flat",
        "water.extent_m": 8.0,
        "water.resolution": 32,
        "caustics.map_resolution": 32,
        "floor.depth_m": DEPTH_M,
        "floor.albedo": 0.5,
        "optics.ior": IOR,
        "optics.water_type": "coastal_ocean",
        "optics.wavelengths": "rgb",
        "sun.elevation_deg": 50.0,
        "sun.azimuth_deg": 30.0,
        "sun.angular_diameter_deg": 0.0,  # a point sun: the analytic light below, and no glint
        "camera.enabled": True,
        "camera.position_m": CAMERA.tolist(),
        "camera.look_at_m": [0.0, 0.5, -DEPTH_M],
        "camera.fov_deg": 30.0,
        "camera.width": 24,
        "camera.height": 16,
        "camera.shaft_samples": 64,
    }
    base.update(extra)
    return wc.load_scene(None, base)


def _pixel_rays(cfg):
    """(H, W, 3) unit pixel rays of the pinhole (kernels/scene/camera/pinhole.py's formula, float64)."""
    cam = cfg.camera
    f = np.asarray(cam.look_at_m, float) - np.asarray(cam.position_m, float)
    f /= np.linalg.norm(f)
    r = np.cross(f, cam.up)
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    t = math.tan(math.radians(cam.fov_deg) / 2)
    x = 2 * (np.arange(cam.width) + 0.5) / cam.width - 1
    y = 1 - 2 * (np.arange(cam.height) + 0.5) / cam.height
    d = f + (x[None, :, None] * t * cam.width / cam.height) * r + (y[:, None, None] * t) * u
    return d / np.linalg.norm(d, axis=-1, keepdims=True)


def _still_water_expected(scene, result):
    """(floor, shafts, through) of the still-water scene, float64: ρ/π E_floor e^{−c d}, the
    in-scattering ∫₀^d σ_s p(θ) E⊥ e^{−c(ℓ(s)+s)} ds in closed form, and (1 − R(θ_v))/n²; and the
    point each refracted ray meets."""
    cfg = scene.config
    optics = spectra.water_optics(cfg.optics, spectra.bins_for(cfg.optics))
    c = optics.attenuation_per_m[:, None, None]
    b = optics.scattering_per_m[:, None, None]
    e_sun = result.sun_irradiance[:, None, None]

    sun = scene.sun_direction
    theta_s = math.acos(sun[2])
    t_s = fresnel_t_angles(np.array([theta_s]), 1.0, IOR)[0]
    cos_ts = math.sqrt(1 - (math.sin(theta_s) / IOR) ** 2)
    d_sun = -np.array([sun[0] / IOR, sun[1] / IOR, cos_ts])  # the refracted sun, going down
    d_sun /= np.linalg.norm(d_sun)

    v = _pixel_rays(cfg)
    cos_v = -v[..., 2]
    sin_v = np.sqrt(1 - cos_v**2)
    t_view = fresnel_t_angles(np.arccos(cos_v), 1.0, IOR)
    cos_vt = np.sqrt(1 - (sin_v / IOR) ** 2)
    tv = np.concatenate([v[..., :2] / IOR, -cos_vt[..., None]], axis=-1)  # refracted view ray
    d = DEPTH_M / cos_vt
    hit = CAMERA + (CAMERA[2] / cos_v)[..., None] * v + d[..., None] * tv

    e_floor = e_sun * math.cos(theta_s) * t_s * np.exp(-c * DEPTH_M / cos_ts)
    floor = 0.5 / math.pi * e_floor * np.exp(-c * d)
    phase_function = PhaseFunction.from_optics(cfg.optics, "cpu")
    phase = phase_function.evaluate(-(tv @ d_sun).ravel(), "cpu").reshape(d.shape)
    alpha = c * (cos_vt / cos_ts + 1.0)
    shafts = b * phase * e_sun * t_s * math.cos(theta_s) / cos_ts * -np.expm1(-alpha * d) / alpha
    return floor, shafts, t_view / IOR**2, hit


def test_still_water_matches_the_analytic_radiance():
    """Still water, a point sun, no sky, coastal water (scattering, HG phase) over a grey floor:
    each pixel is (1 − R(θ_v))/n² × [ρ/π E_floor e^{−c d} + ∫₀^d σ_s p(θ) E⊥ e^{−c(ℓ(s)+s)} ds]
    (float64, written here), with E_floor = E_sun cosθ_s T(θ_s) e^{−cD/cosθ_t}, E⊥ = E_sun T(θ_s)
    cosθ_s / cosθ_t, d = D/cosθ_v' the refracted view ray's length, ℓ(s) = s cosθ_v'/cosθ_t and
    cos θ = −t_sun·t_view; the reflection of a black sky adds nothing. The shafts' 64 midpoint
    samples leave < 1e-5; the rest is float32."""
    scene = _scene()
    renderer = wc.Renderer(scene, "cpu")
    result = renderer.render(0.0)
    floor, shafts, through, hit = _still_water_expected(scene, result)
    # the floor point each refracted ray meets, as the renderer found it
    np.testing.assert_allclose(result.camera_gbuffer["position"], hit, atol=5e-6)
    # the in-scattered part alone (the camera's buffer of the one pass), then the image
    np.testing.assert_allclose(renderer.method.camera.shafts.numpy(), shafts, rtol=2e-4)
    np.testing.assert_allclose(result.camera_radiance, through * (floor + shafts), rtol=2e-4)


def test_the_reflection_of_a_uniform_sky_is_r_e_over_pi():
    """A uniform sky of horizontal irradiance E_sky: the water reflects R(θ_v) E_sky/π into each
    pixel (the surface part, which the light passes do not give), and a pixel above the horizon
    sees E_sky/π itself."""
    scene = _scene(**{"sky.model": "uniform", "sky.diffuse_fraction": 0.2, "sky.directions": 4,
                      "camera.look_at_m": [0.3, 3.0, 1.2], "camera.fov_deg": 60.0})
    renderer = wc.Renderer(scene, "cpu")
    renderer.render(0.0)
    camera = renderer.method.camera
    e_sky = scene.sky_irradiance(renderer.light.sun_irradiance)[:, None, None]
    v = _pixel_rays(scene.config)
    down = v[..., 2] < 0
    assert 0.2 < down.mean() < 0.8
    r = 1.0 - fresnel_t_angles(np.arccos(np.clip(-v[..., 2], 0, 1)), 1.0, IOR)
    expected = np.where(down, r * e_sky / math.pi, e_sky / math.pi)
    np.testing.assert_allclose(camera.surface_radiance, expected, rtol=1e-5)


def test_photons_from_above_light_what_the_refracted_rays_meet_from_their_maps():
    """Photons seen from above. Still water, as the test above: the in-scattered part from the
    photons' E⊥ on 64 horizontal slices (linear between them) within 5e-4 of the closed form
    (measured 1e-4; 16 slices 5e-4, falling as their spacing squared), and the image within 5e-4.
    A rough FFT sea with a sphere in it, no shafts: each pixel that looks into the water is
    (1 − R)/n² ρ/π E e^{−c d} with E the pass's floor map bilinear between texel centres at the
    point the refracted ray meets (periodic) or the sphere's face flux over its area — recomputed
    here in float64 from the result's maps and G-buffer (float32: 1e-5); the sphere and the floor
    are both in view."""
    scene = _scene(**{"caustics.method": "photons"})
    renderer = wc.Renderer(scene, "cpu")
    result = renderer.render(0.0)
    floor, shafts, through, _ = _still_water_expected(scene, result)
    np.testing.assert_allclose(renderer.method.camera.shafts.numpy(), shafts, rtol=5e-4)
    np.testing.assert_allclose(result.camera_radiance, through * (floor + shafts), rtol=5e-4)

    c = spectra.water_optics(scene.config.optics, spectra.bins_for(scene.config.optics)).attenuation_per_m
    c = c[:, None, None]
    rough = _scene(**{"caustics.method": "photons", "caustics.shafts": False, "water.model": "fft",
                      "water.wind_speed_m_s": 6.0, "camera.width": 48, "camera.height": 32,
                      "camera.position_m": [0.3, -3.0, 2.0], "camera.look_at_m": [0.0, 0.5, -DEPTH_M],
                      "camera.fov_deg": 50.0,
                      "receivers": [{"mesh": "sphere", "scale": 1.0, "translate_m": [0.0, 0.5, -1.5]}]})
    renderer = wc.Renderer(rough, "cpu")
    r = renderer.render(0.0)
    g = r.camera_gbuffer
    seen = renderer.method.camera.water_receiver.numpy() >= 0
    floor_faces = renderer.method.receivers.floor_face_count
    on_sphere = seen & (g["face"] >= floor_faces)
    assert on_sphere.sum() > 20 and (seen & ~on_sphere).sum() > 200
    m = r.floor_irradiance.shape[-1]
    u = (g["position"][..., 0] / 8.0 + 0.5) * m - 0.5
    w = (g["position"][..., 1] / 8.0 + 0.5) * m - 0.5
    x0, y0 = np.floor(u).astype(int), np.floor(w).astype(int)
    tu, tv = u - x0, w - y0
    f = r.floor_irradiance.astype(np.float64)
    at = lambda y, x: f[:, y % m, x % m]  # noqa: E731
    e = ((1 - tv) * ((1 - tu) * at(y0, x0) + tu * at(y0, x0 + 1))
         + tv * ((1 - tu) * at(y0 + 1, x0) + tu * at(y0 + 1, x0 + 1)))
    face = np.clip(g["face"] - floor_faces, 0, None)
    e_face = (r.face_flux_w_nm[face] / r.face_area_m2[face][..., None]).transpose(2, 0, 1)
    e = np.where(on_sphere, e_face, e)
    albedo = renderer.method.receivers.albedo[np.maximum(g["receiver"], 0)].transpose(2, 0, 1)
    through = renderer.method.camera.through.numpy().astype(np.float64)
    expected = np.where(seen, through * albedo / math.pi * e * np.exp(-c * g["depth"]), 0.0)
    surface = renderer.method.camera.surface_radiance
    np.testing.assert_allclose(r.camera_radiance - surface, expected, rtol=1e-5, atol=1e-7 * expected.max())


def test_above_water_errors():
    """The view from above needs the camera above every crest (and, as every camera, beams or
    photons)."""
    with pytest.raises(ConfigError, match="photons"):
        _scene(**{"caustics.method": "fluxratio"})
    scene = _scene(**{"water.model": "fft", "water.wind_speed_m_s": 8.0,
                      "camera.position_m": [0.3, -1.0, 0.01],
                      "camera.shaft_samples": 2})
    with pytest.raises(WarpcausticsError, match="raise the camera"):
        wc.render(scene, device="cpu")


def test_the_sun_s_glint_is_r_times_the_disk_radiance():
    """Still water and the 0.53° sun's disk: the pixels whose mirror ray falls inside the disk see
    R(θ_v) E_sun/Ω (Ω = 2π(1 − cos r), a uniform disk), the others no reflection (no sky); float64
    geometry and Fresnel written here."""
    elevation, azimuth = 40.0, 30.0
    el, az = math.radians(elevation), math.radians(azimuth)
    sun = np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])
    mirror = np.array([-sun[0], -sun[1], sun[2]])  # the sun's reflection seen from above
    camera = np.array([0.0, 0.0, 1.0])
    look = camera - 3.0 * mirror  # looking down along the reflected sunlight, reversed
    scene = _scene(**{"sun.elevation_deg": elevation, "sun.azimuth_deg": azimuth,
                      "sun.angular_diameter_deg": 0.53, "sun.disk_samples": 2,
                      "camera.position_m": camera.tolist(), "camera.look_at_m": look.tolist(),
                      "camera.fov_deg": 2.0, "camera.width": 32, "camera.height": 32,
                      "camera.shaft_samples": 1})
    renderer = wc.Renderer(scene, "cpu")
    renderer.render(0.0)
    v = _pixel_rays(scene.config)
    reflected = v * np.array([1.0, 1.0, -1.0])
    radius = math.radians(0.53) / 2
    on_disk = reflected @ sun >= math.cos(radius)
    assert 20 < on_disk.sum() < 32 * 32 - 20  # the disk's edge crosses the image
    r = 1.0 - fresnel_t_angles(np.arccos(-v[..., 2]), 1.0, IOR)
    e_sun = renderer.light.sun_irradiance[:, None, None]
    expected = np.where(on_disk, r * e_sun / (2 * math.pi * (1 - math.cos(radius))), 0.0)
    np.testing.assert_allclose(renderer.method.camera.surface_radiance, expected, rtol=1e-5)


def test_photon_shafts_from_above_agree_with_the_beams():
    """configs/ocean.toml (64² surface, coastal water, point sun) seen from 3 m above, 80×60, 32
    samples a ray: the light the refracted rays gather from the photons' slices against the beams'
    gather at the same points, relative L1 over the image within 3 % (measured 1.2 %) and the
    mean within 1 % (measured −0.3 %): the photons' bilinear patches against the beams' triangles,
    and the slices' 128² texels and linear steps in depth against the beams' exact E⊥."""
    base = {"water.resolution": 64, "caustics.map_resolution": 128, "optics.wavelengths": "rgb",
            "optics.water_type": "coastal_ocean", "camera.enabled": True,
            "camera.position_m": [0.0, -6.0, 3.0], "camera.look_at_m": [0.0, 0.0, -3.0],
            "camera.width": 80, "camera.height": 60, "camera.shaft_samples": 32,
            "sun.angular_diameter_deg": 0.0}
    shafts = {}
    for method in ("beams", "photons"):
        scene = wc.load_scene(CONFIGS / "ocean.toml", {**base, "caustics.method": method})
        renderer = wc.Renderer(scene, "cpu")
        renderer.render(0.0)
        shafts[method] = renderer.method.camera.shafts.numpy().astype(np.float64)
    beams, photons = shafts["beams"], shafts["photons"]
    assert np.abs(photons - beams).sum() / beams.sum() < 0.03
    assert photons.mean() == pytest.approx(beams.mean(), rel=0.01)
