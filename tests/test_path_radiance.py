"""The light scattered once into a radiance sensor's line of sight (caustics/path_radiance.py),
against integrals the module does not do: along the line of sight by scipy, over the sky by scipy,
and the forward peak by the phase function's own quadrature."""

import math
from pathlib import Path

import numpy as np
import pytest

from warpcaustics.caustics import path_radiance as pr
from warpcaustics.caustics.view import cone_directions, view_axis
from warpcaustics.optics.snell import fresnel_transmittance, refract

integrate = pytest.importorskip("scipy.integrate")

UP = np.array([0.0, 0.0, 1.0])
ROOT = Path(__file__).resolve().parents[1]
RADIANCE = ROOT / "configs/field/darecki2011_radiance.toml"
DEPTH, C, B, N = 0.9, 0.8, 0.5, 1.34


def isotropic(theta):
    return np.full(np.shape(theta), 1.0 / (4.0 * math.pi))


def test_the_suns_beam_scattered_into_a_narrow_cone_is_the_line_of_sights_integral():
    """Sun 40° from the zenith refracted into the water, the sensor looking 10° off the vertical the
    other way (scattering angle about 40°, all of it wide), an isotropic phase function: ∫ over a
    0.5° cone ≈ its solid angle × b p ∫₀^ℓ E⊥ e^{−c(D − s v_z)/μ} e^{−c s} ds, by scipy (1e-4)."""
    to_sun = view_axis(40.0, 0.0)
    down = refract(-to_sun, UP, 1.0 / N)
    beam = 2.0
    axis = view_axis(10.0, 180.0)
    near, wide = pr.sun_part(axis, 0.5, DEPTH, down, beam, C, B, isotropic)
    mu = -down[2]
    length = DEPTH / axis[2]
    along, _ = integrate.quad(lambda s: beam * math.exp(-C * (DEPTH - s * axis[2]) / mu - C * s), 0.0, length)
    omega = 2.0 * math.pi * (1.0 - math.cos(math.radians(0.25)))
    assert near == 0.0
    assert wide == pytest.approx(omega * B / (4.0 * math.pi) * along, rel=1e-4)


def test_a_uniform_skys_light_scattered_straight_down_is_its_double_integral():
    """A uniform sky of radiance L above the water, an isotropic phase function, a narrow cone looking
    straight up: ∫ ≈ Ω b/(4π) ∫ L n² T(θ_a) ∫₀^D e^{−c(D − s)/μ} e^{−c s} ds 2π dμ over Snell's window
    (the n² law: L n² T below the surface), by scipy (2e-3), the forward and the wide parts together."""
    radiance = 3.0

    def sky(d):
        return np.where(np.asarray(d)[..., 2] > 0.0, radiance, 0.0)

    forward = (1.0 - math.cos(math.radians(pr.FORWARD_DEG))) / 2.0  # isotropic p's share below 3°
    near, wide = pr.sky_part(UP, 0.5, DEPTH, sky, N, C, B, isotropic)

    def integrand(s, mu):
        sin_a = N * math.sqrt(1.0 - mu * mu)
        t = float(fresnel_transmittance(math.sqrt(1.0 - sin_a * sin_a), 1.0 / N))
        return radiance * N * N * t * math.exp(-C * (DEPTH - s) / mu - C * s) * 2.0 * math.pi

    mu_c = math.sqrt(1.0 - 1.0 / N**2)
    value, _ = integrate.dblquad(integrand, mu_c, 1.0, 0.0, DEPTH)
    omega = 2.0 * math.pi * (1.0 - math.cos(math.radians(0.25)))
    assert near + wide == pytest.approx(omega * B / (4.0 * math.pi) * value, rel=1e-3)
    # within 3° the sky's radiance hardly changes: the forward part is its value along the vertical
    assert near == pytest.approx(omega * B * forward * radiance * N * N
                                 * float(fresnel_transmittance(1.0, 1.0 / N)) * DEPTH * math.exp(-C * DEPTH),
                                 rel=1e-3)


@pytest.mark.parametrize("g", [0.9, -0.5])
def test_a_peaked_phase_function_scatters_the_sky_by_its_angle_from_the_line_of_sight(g):
    """Henyey–Greenstein with g = 0.9 (a forward peak) and −0.5 (backward): the uniform sky's light
    scattered straight down weights each direction by p at its angle from the downward line of
    sight, by scipy (1e-3): a sign slip in ψ would swap forward and backward."""
    radiance = 3.0

    def sky(d):
        return np.where(np.asarray(d)[..., 2] > 0.0, radiance, 0.0)

    def hg(theta):
        return (1.0 - g * g) / (4.0 * math.pi * (1.0 + g * g - 2.0 * g * np.cos(theta)) ** 1.5)

    near, wide = pr.sky_part(UP, 0.5, DEPTH, sky, N, C, B, hg)

    def integrand(s, mu):  # light travelling down at cos θ = μ is scattered by ψ = θ into the vertical
        sin_a = N * math.sqrt(1.0 - mu * mu)
        t = float(fresnel_transmittance(math.sqrt(1.0 - sin_a * sin_a), 1.0 / N))
        attenuated = math.exp(-C * (DEPTH - s) / mu - C * s)
        return radiance * N * N * t * float(hg(math.acos(mu))) * attenuated * 2.0 * math.pi

    mu_c = math.sqrt(1.0 - 1.0 / N**2)
    value, _ = integrate.dblquad(integrand, mu_c, 1.0, 0.0, DEPTH, epsrel=1e-10)
    omega = 2.0 * math.pi * (1.0 - math.cos(math.radians(0.25)))
    assert near + wide == pytest.approx(omega * B * value, rel=1e-3)


def test_the_suns_light_reaches_a_cone_far_from_it_by_every_azimuth_that_meets_it():
    """A 20° cone 75° from the refracted sun, an isotropic phase function and no attenuation: the
    polar quadrature about the sun (its azimuths cut to the arc that meets the cone) gives
    ∫_cone D/v_z dω, which a fine grid over the cone itself gives too (1e-3)."""
    down = -view_axis(0.0, 0.0)  # the sun at the zenith: its light straight down
    axis = view_axis(75.0, 30.0)
    _, wide = pr.sun_part(axis, 20.0, DEPTH, down, 1.0, 0.0, 1.0, isotropic)
    views, d_omega = cone_directions(axis, 20.0, 400_000)
    expected = float(np.sum(DEPTH / views[:, 2]) * d_omega) / (4.0 * math.pi)
    assert wide == pytest.approx(expected, rel=1e-3)


def test_the_forward_peak_about_the_sun_is_the_phase_functions_own_share():
    """The sun at the zenith in the middle of a 4.5° cone looking up, no attenuation: ∫ over the cone
    = b E⊥ ∫ p(ψ) D/cos ψ dω, Petzold's forward peak and its power-law cone included, which the phase
    function's own quadrature (log-spaced nodes through the cone, ``phase_quadrature``) gives (1e-3);
    what lies below 3° is the near part."""
    import warpcaustics as wc
    from warpcaustics.optics.phase import phase_quadrature, phase_values

    optics = wc.load_scene(RADIANCE).config.optics

    def phase(theta):
        return phase_values(optics, theta)

    near, wide = pr.sun_part(UP, 4.5, DEPTH, -UP, 1.0, 0.0, 1.0, phase)
    theta, w = phase_quadrature(optics.phase_function, optics.hg_g, optics.petzold_station.value)
    inside = theta <= math.radians(2.25)
    expected = float(np.sum(w[inside] * DEPTH / np.cos(theta[inside])))
    below = theta < math.radians(pr.FORWARD_DEG)
    assert near + wide == pytest.approx(expected, rel=1e-3)
    assert near == pytest.approx(expected, rel=1e-3) and wide == 0.0  # the cone lies within 3°
    assert expected > 0.5 * float(np.sum(w[below]) * DEPTH)  # most of the peak is inside the cone


def test_the_sensors_scattered_light_has_a_sky_and_a_sun_part():
    """On the Darecki radiance scene looking away from the sun: both parts positive and finite; without
    the sky a smaller wide part (the sun's alone); and no sensor, a clear error."""
    import warpcaustics as wc

    scene = wc.load_scene(RADIANCE,
                          {"floor.view_zenith_deg": 30.0, "floor.view_azimuth_deg": 180.0})
    scattered = pr.sensor_path_radiance(scene)
    assert scattered.near_sky[0] > 0.0 and scattered.wide[0] > 0.0
    assert scattered.near_sun[0] == 0.0  # 30° away from the sun's side: none of its light within 3°
    dark = wc.load_scene(RADIANCE,
                         {"floor.view_zenith_deg": 30.0, "floor.view_azimuth_deg": 180.0,
                          "sky.model": "none", "sky.diffuse_fraction": 0.0})
    sun_only = pr.sensor_path_radiance(dark)
    assert sun_only.near_sky[0] == 0.0 and 0.0 < sun_only.wide[0] < scattered.wide[0]
    with pytest.raises(ValueError, match="floor.view_fov_deg"):
        pr.sensor_path_radiance(wc.load_scene(ROOT / "configs/field/darecki2011.toml"))


def test_the_beam_below_the_surface_is_the_renderers():
    """``refracted_beam``'s E⊥ and direction against the renderer under still water, no sky: a
    sensor looking back along the refracted beam holds all of it, E⊥ e^{−cD/μ} (1e-4)."""
    import warpcaustics as wc
    from warpcaustics.batch.field.darecki2011_radiance import QUICK_OVERRIDES

    over = {**QUICK_OVERRIDES, "water.model": "flat", "sky.model": "none", "sky.diffuse_fraction": 0.0,
            "sun.elevation_deg": 50.0, "floor.depth_m": 0.7}
    down, _ = pr.refracted_beam(wc.load_scene(RADIANCE, over), 0)
    zenith = math.degrees(math.acos(-down[2]))
    scene = wc.load_scene(RADIANCE, {**over, "floor.view_zenith_deg": zenith, "floor.view_azimuth_deg": 0.0})
    down, beam = pr.refracted_beam(scene, 0)
    r = wc.Renderer(scene, device="cpu").render(0.0)
    c = float(r.attenuation_per_m[0])
    assert down[0] < 0.0 and down[1] == pytest.approx(0.0, abs=1e-12)  # away from the sun, azimuth 0
    held = float(r.floor_irradiance[0].mean())
    assert held == pytest.approx(beam * math.exp(-c * 0.7 / -down[2]), rel=1e-4)
