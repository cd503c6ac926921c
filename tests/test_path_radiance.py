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


@pytest.mark.parametrize("fov_deg, lines_count, tol, legendre",
                         [(0.01, 1, 1e-3, False), (0.01, 1, 1e-3, True), (4.5, 2000, 4e-3, False)])
def test_the_line_of_sights_caustics_are_its_integral_over_the_cone_and_the_disk(fov_deg, lines_count, tol,
                                                                                  legendre):
    """``line_of_sight_modulation`` against a brute force that shares none of its approximations: an
    analytic field of a point sun below the surface, Ē(z) (1 + A cos(k·x + βz)) with Ē(z) = e^{−cz/μ},
    seen through a 4° sun's disk — each of 256 directions over the disk refracted exactly by Snell's
    law and its pattern moved by z Δ(tan θ_w) — and integrated along each line of sight over the
    sensor's cone, e^{−cs} ds with the path's own length, over the same integral of Ē alone, at six
    texels where F ranges over ±0.4 (β keeps the pattern's phase still along the axis, so that the
    blurs decide). A single line (the disk's first-order ellipse and the 400 planes): within 1e-3. A
    4.5° cone of 2000 lines: within 4e-3, the ellipse's second order (the cone's footprint on a plane
    is off-centre by about α² s tan θ; 8000 lines give the same). Planes of unequal layers (120
    Gauss–Legendre nodes, their weights the layers' thickness): as the single line."""
    side, m, depth, c, amp = 0.5, 64, 0.9, 0.8, 0.5
    k = 2.0 * math.pi * np.array([3.0, 2.0]) / side
    to_sun = view_axis(40.0, 30.0)
    down = refract(-to_sun, UP, 1.0 / N)
    mu = -down[2]
    axis = view_axis(30.0, 200.0)
    beta = float(k @ axis[:2]) / axis[2]
    centres = (np.arange(m) + 0.5) * side / m - 0.5 * side
    x, y = np.meshgrid(centres, centres)  # [iy, ix]
    planes = 400
    z, thickness = (np.arange(planes) + 0.5) * depth / planes, None
    if legendre:
        nodes, weights = np.polynomial.legendre.leggauss(120)
        z, thickness = 0.5 * depth * (nodes + 1.0), 0.5 * depth * weights
    phase = k[0] * x + k[1] * y + beta * z[:, None, None]
    slices = np.exp(-c * z / mu)[:, None, None] * (1.0 + amp * np.cos(phase))
    disk = pr.sun_disk_footprint(to_sun, 4.0, N)
    got = pr.line_of_sight_modulation(slices, z, side / m, depth_m=depth, axis=axis, fov_deg=fov_deg, c=c,
                                      thickness_m=thickness, sun_disk=disk)
    assert got.mean() == pytest.approx(1.0, abs=1e-12)
    assert got.std() > 0.25  # the blurs leave a pattern to compare

    # the disk's average of e^{−i k·shift(z)}: each direction's refracted pattern moved by z Δ(tan θ_w)
    suns = cone_directions(to_sun, 4.0, 256)[0]
    rays = np.array([refract(-d, UP, 1.0 / N) for d in suns])
    moved = rays[:, :2] / -rays[:, 2:3] - down[:2] / -down[2]
    zz = np.linspace(0.0, depth, 2001)
    disk_factor = np.mean(np.exp(-1j * (moved @ k)[:, None] * zz[None, :]), axis=0)
    lines, _ = cone_directions(axis, fov_deg, lines_count)
    s_frac = (np.arange(600) + 0.5) / 600
    for iy, ix in ((0, 0), (5, 40), (17, 3), (33, 33), (50, 12), (63, 61)):
        x0 = np.array([x[iy, ix], y[iy, ix]])
        num = den = 0.0
        for d in lines:
            length = depth / d[2]
            s = s_frac * length
            zs = depth - s * d[2]
            mean = np.exp(-c * zs / mu) * np.exp(-c * s)
            pos = x0[None, :] + s[:, None] * d[None, :2]
            factor = np.interp(zs, zz, disk_factor.real) + 1j * np.interp(zs, zz, disk_factor.imag)
            wave = (np.exp(1j * (pos @ k + beta * zs)) * factor).real
            num += float(np.sum(mean * (1.0 + amp * wave))) * length
            den += float(np.sum(mean)) * length
        assert got[iy, ix] == pytest.approx(num / den, abs=tol), (iy, ix)


def test_a_uniform_field_gives_no_modulation():
    """Still water under a point sun: every plane uniform, so F = 1 at every texel."""
    slices = np.exp(-0.5 * np.linspace(0.05, 0.85, 8))[:, None, None] * np.ones((8, 32, 32))
    got = pr.line_of_sight_modulation(slices, np.linspace(0.05, 0.85, 8), 0.01, depth_m=0.9,
                                      axis=view_axis(20.0, 0.0), fov_deg=4.5, c=0.7)
    assert np.allclose(got, 1.0, atol=1e-12)


def test_the_modulation_refuses_a_line_of_sight_it_cannot_follow():
    """A sensor looking down, or a plane below the sensor: a clear error, not a wrong map."""
    slices = np.ones((2, 8, 8))
    with pytest.raises(ValueError, match="upward line of sight"):
        pr.line_of_sight_modulation(slices, np.array([0.2, 0.6]), 0.01, depth_m=0.9,
                                    axis=np.array([0.0, 0.0, -1.0]), fov_deg=4.5, c=0.5)
    with pytest.raises(ValueError, match="above the sensor"):
        pr.line_of_sight_modulation(slices, np.array([0.2, 1.2]), 0.01, depth_m=0.9, axis=UP, fov_deg=4.5,
                                    c=0.5)
