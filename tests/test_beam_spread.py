"""optics.beam_spread = "walk": the water column's beam spread function from a random walk (issue 32).

The walk of a pencil beam in still water (:mod:`warpcaustics.optics.beam_spread`) is checked against
what it did not produce: its mean against PythonicDISORT's plane-parallel solution (every band from
one walk, by the bands' likelihood weights), its spatial spread against the exact single-scattering
integral in optically thin water (the geometry of wide angles and the absorption along lengthened
paths), its tally against a spread with a closed-form spectrum, and the small-angle map it makes,
with its first-order response to the surface, against a Monte Carlo of a sinusoidal sea written
apart from the package.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.special import j0

import warpcaustics as wc
from warpcaustics.config import PhaseFunctionKind
from warpcaustics.optics import spectra
from warpcaustics.optics.beam_spread import OVERSAMPLE, SpreadSample, spread_multiplier, walk_column
from warpcaustics.optics.phase import phase_quadrature

from helpers import CONFIGS

IOR = 1.333


def sample_mean(sample: SpreadSample) -> tuple[np.ndarray, np.ndarray]:
    """((K,) the scattered light reaching the floor per unit of the beam's power, (K,) its standard
    error from the photons' spread)."""
    n = sample.photons
    total = sample.weight.sum(axis=1)
    second = (sample.weight**2).sum(axis=1) * n
    return total, np.sqrt(np.maximum(second - total**2, 0.0) / n)


@pytest.mark.parametrize("phase", ["henyey_greenstein", "petzold"])
@pytest.mark.parametrize("depth_m, sun_zenith_deg", [(5.0, 60.0), (1.5, 0.0)])
def test_the_spread_holds_the_plane_parallel_solution(phase, depth_m, sun_zenith_deg):
    """∫ BSF over the floor is the plane wave's irradiance there: e^{−c s} plus the walk's scattered
    light equals PythonicDISORT's Ed(D)/F0 under a Fresnel top over a black floor, in
    ``turbid_harbor`` water at 450/550/650 nm (b·D up to 4.8; the bands' b differ, so every band but
    the one with the largest b is reached through the likelihood weights), within 1 % or three
    standard errors of the 2¹⁸ photons plus the solver's quadrature error."""
    pytest.importorskip("PythonicDISORT")
    from test_walk_boundaries import petzold_moments

    from warpcaustics.reference.disort import floor_irradiance, hg_moments

    cfg = wc.load_scene(None, {"optics.water_type": "turbid_harbor", "optics.phase_function": phase,
                               "optics.wavelengths": [450.0, 550.0, 650.0]}).config.optics
    optics = spectra.water_optics(cfg, spectra.bins_for(cfg))
    a, b = np.asarray(optics.absorption_per_m), np.asarray(optics.scattering_per_m)
    assert np.ptp(b) > 0.01 * b.max()  # the bands' b differ
    theta, weight = phase_quadrature(cfg.phase_function, cfg.hg_g, cfg.petzold_station.value)
    sin_w = math.sin(math.radians(sun_zenith_deg)) / IOR
    cos_w = math.sqrt(1.0 - sin_w**2)
    sample = walk_column(theta, weight, a, b, cos_w, depth_m, IOR, 2**18, seed=5)
    scattered, se = sample_mean(sample)
    ed = np.exp(-(a + b) * depth_m / cos_w) + scattered
    if phase == "petzold":
        moments = petzold_moments(cfg.petzold_station.value)
    else:
        from warpcaustics.optics.phase import mean_cosine

        moments = hg_moments(mean_cosine(theta, weight), 300)
    for band in range(3):
        ref = floor_irradiance(depth_m, float(a[band]), float(b[band]), cos_w, moments, fresnel_ior=IOR)
        bound = max(0.01 * ref["ed"], 3.0 * se[band] + ref["error"])
        assert abs(ed[band] - ref["ed"]) <= bound, (band, ed[band], ref, se[band])


def single_scattering(theta, weight, a: float, b: float, depth_m: float, q: np.ndarray) -> np.ndarray:
    """The spread's Hankel transform to first order in b for a vertical beam, float64 quadrature:
    b ∫₀^D e^{−c z} ∫_{θ<90°} p(θ) e^{−c (D−z)/cos θ} J₀(q (D−z) tan θ) dΩ dz — scattered once at
    depth z by θ, then straight to the floor, its path (D − z)/cos θ attenuated."""
    c = a + b
    forward = theta < 0.5 * np.pi - 1e-9
    th, w = theta[forward], weight[forward] / weight.sum()
    nodes, gauss = np.polynomial.legendre.leggauss(96)
    z = 0.5 * depth_m * (nodes + 1.0)
    out = np.zeros(len(q))
    for zi, gi in zip(z, gauss * 0.5 * depth_m):
        left = depth_m - zi
        att = np.exp(-c * zi - c * left / np.cos(th)) * w
        out += gi * b * (j0(np.outer(q, left * np.tan(th))) @ att)
    return out


def test_the_spread_has_the_exact_geometry_of_single_scattering():
    """Optically thin water (b D = 0.004, so light scattered twice is below 0.2 % of the scattered):
    the walked spread's Hankel transform, Σ w J₀(q r), against the float64 single-scattering
    integral at q D = 0, 0.5, 2, 8 in three bands of absorption (0, 0.5 and 2 m⁻¹, so the lengthened
    paths of wide angles are absorbed more), a Henyey–Greenstein g = 0.8 (many wide angles) and no
    reflecting top (first-order light from above would come back down): within three standard
    errors of the 2²⁰ photons plus b D of the scattered light (the twice scattered). Wells's closed
    form, which displaces by u θ and never absorbs the lengthened path, misses the same values by
    more than that at q D = 0.5 and 2 (by 33 % and 24 % in the most absorbed band)."""
    theta, weight = phase_quadrature(PhaseFunctionKind.HENYEY_GREENSTEIN, 0.8, "HAOCE 11")
    depth = 2.0
    a = np.array([0.0, 0.5, 2.0])
    b = np.full(3, 0.002)
    sample = walk_column(theta, weight, a, b, 1.0, depth, IOR, 2**20, seed=3, fresnel_top=False)
    r = np.hypot(sample.along, sample.across)
    q = np.array([0.0, 0.5, 2.0, 8.0]) / depth
    basis = j0(np.outer(q, r))  # (Q, n)
    n = sample.photons
    for band in range(3):
        values = basis * sample.weight[band] * n
        measured = values.sum(axis=1) / n
        se = np.sqrt(np.maximum((values**2).sum(axis=1) / n - measured**2, 0.0) / n)  # zeros: the rest
        expected = single_scattering(theta, weight, a[band], b[band], depth, q)
        bound = 3.0 * se + b[band] * depth * expected[0]
        assert np.all(np.abs(measured - expected) <= bound), (band, measured, expected, se)
    from warpcaustics.optics.small_angle import spread_from_phase

    x, g = spread_from_phase(theta, weight)
    c = a[2] + b[2]
    wells = np.exp(-c * depth) * np.expm1(b[2] * depth * np.interp(q * depth, x, g))
    exact = single_scattering(theta, weight, a[2], b[2], depth, q)
    assert np.all(np.abs(wells[1:3] - exact[1:3]) > bound[1:3]), (wells, exact, bound)


def test_water_that_scatters_nothing_walks_no_photon(recwarn):
    """b = 0 in every band (optics.water_type = "none"): no photon scatters, so the spread holds none,
    without numpy's divide-by-zero warnings (its free paths 1/b and log b/b* had raised two), and the
    small-angle map is the single-scattering one to the bit."""
    theta, weight = phase_quadrature(PhaseFunctionKind.PETZOLD, None, "HAOCE 11")
    sample = walk_column(theta, weight, np.zeros(3), np.zeros(3), 0.9, 3.0, 1.34, 4096, 1)
    assert sample.along.size == 0 and sample.weight.shape == (3, 0) and sample.memory.shape == (4, 0)
    scene = {"water.resolution": 32, "caustics.map_resolution": 32, "optics.wavelengths": "rgb",
             "optics.water_type": "none"}
    single = wc.render(wc.load_scene(CONFIGS / "ocean.toml", scene), device="cpu")
    walked = wc.render(wc.load_scene(CONFIGS / "ocean.toml", {**scene, "optics.scattering": "small_angle",
                                                              "optics.beam_spread": "walk"}), device="cpu")
    np.testing.assert_array_equal(walked.floor_irradiance, single.floor_irradiance)
    assert not [w for w in recwarn if issubclass(w.category, RuntimeWarning)]


def test_the_tally_gives_the_spectrum_of_a_known_spread():
    """A spread of Gaussian offsets (σ = 2.5 map texels, along a beam at 30° azimuth) tallied on the
    map's grid: its multiplier is e^{−k²σ²/2} times the gain e^{c s} within the photons' noise
    (3/√N) and the tally's nearest-texel response (below 0.7 % where it is taken as measured); on a
    grid too wide to oversample, past the measured range it is the given fine-scale multiplier."""
    rng = np.random.default_rng(11)
    n = 200_000
    sigma_texels, texel = 2.5, 0.01
    offsets = rng.normal(0.0, sigma_texels * texel, (2, n))
    sample = SpreadSample(offsets[0], offsets[1], np.full((1, n), 0.3 / n), n)
    azimuth = (math.cos(math.radians(30.0)), math.sin(math.radians(30.0)))
    gain = np.array([2.0])

    def gaussian(m):
        k = 2.0 * np.pi * np.fft.fftfreq(m, d=texel)
        kx, ky = np.meshgrid(k, k)
        return 0.3 * 2.0 * np.exp(-0.5 * (kx**2 + ky**2) * (sigma_texels * texel) ** 2)

    m = 64
    assert OVERSAMPLE * m <= 1024  # fully oversampled: the tally alone
    multiplier, at_zero = spread_multiplier(sample, azimuth, texel, m, np.log(gain), 1.0, lambda band: 0.0)
    np.testing.assert_allclose(at_zero, [0.6], rtol=1e-12)
    got = multiplier(0)
    np.testing.assert_allclose(got.real, gaussian(m), atol=0.6 * (3.0 / math.sqrt(n) + 0.007))
    np.testing.assert_allclose(got.imag, 0.0, atol=0.6 * 3.0 / math.sqrt(n))
    m = 1024  # the tally on the map's own texels: measured to 1/16 cycle per texel, then the fine form
    multiplier, _ = spread_multiplier(sample, azimuth, texel, m, np.log(gain), 1.0, lambda band: gaussian(m))
    np.testing.assert_allclose(multiplier(0).real, gaussian(m), atol=0.6 * (3.0 / math.sqrt(n) + 0.007))


def independent_walk(heights, extent_m: float, depth_m: float, a: float, b: float, g: float, ior: float,
                     photons: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """((photons,) where each photon of a vertical sun meets a black floor [m], its weight): a
    float64 Monte Carlo written apart from the package for a sea whose height varies along x only,
    ``heights(x) -> (h, dh/dx)``: each photon enters at its point of the surface (Fresnel
    transmission, refraction at the local normal, the flux per unit of horizontal length), walks at
    rate b turning by Henyey–Greenstein angles (their inverse CDF in closed form), is absorbed along
    its path (its weight), and meets the flat mean level going up, where it is reflected with the
    Fresnel reflectance (total past the critical angle) or leaves."""
    rng = np.random.default_rng(seed)
    x0 = (np.arange(photons) + rng.random(photons)) * extent_m / photons
    h, slope = heights(x0)
    normal = np.stack([-slope, np.zeros(photons), np.ones(photons)]) / np.sqrt(1.0 + slope**2)
    cos_i = normal[2]  # the sun straight down: cos of the incidence on each facet
    cos_t = np.sqrt(1.0 - (1.0 - cos_i**2) / ior**2)
    rs = (cos_i - ior * cos_t) / (cos_i + ior * cos_t)
    rp = (ior * cos_i - cos_t) / (ior * cos_i + cos_t)
    weight = (1.0 - 0.5 * (rs**2 + rp**2)) * cos_i / normal[2]
    d = np.array([0.0, 0.0, -1.0])[:, None] / ior + (cos_i / ior - cos_t) * normal
    pos = np.stack([x0, np.zeros(photons), h])
    landed_x, landed_w = [], []
    alive = np.arange(photons)
    while alive.size:
        p, v = pos[:, alive], d[:, alive]
        step = rng.exponential(1.0 / b, alive.size)
        to_floor = np.where(v[2] < 0, (-depth_m - p[2]) / np.minimum(v[2], -1e-300), np.inf)
        to_top = np.where(v[2] > 0, -p[2] / np.maximum(v[2], 1e-300), np.inf)
        t = np.minimum(step, np.minimum(to_floor, np.maximum(to_top, 0.0)))
        p = p + t * v
        weight[alive] *= np.exp(-a * t)
        floor = to_floor <= step
        landed_x.append(p[0, floor])
        landed_w.append(weight[alive[floor]])
        top = ~floor & (to_top <= step)
        mu = v[2, top]
        sin_out = ior * np.sqrt(np.maximum(0.0, 1.0 - mu**2))
        cos_out = np.sqrt(np.maximum(0.0, 1.0 - sin_out**2))
        r_s = (ior * mu - cos_out) / (ior * mu + cos_out)
        r_p = (mu - ior * cos_out) / (mu + ior * cos_out)
        reflect = np.where(sin_out >= 1.0, 1.0, 0.5 * (r_s**2 + r_p**2))
        stays = rng.random(mu.size) < reflect
        v[2, top] = -v[2, top]
        scatter = ~floor & ~top
        n = int(scatter.sum())
        xi = rng.random(n)
        cos_s = (1.0 + g * g - ((1.0 - g * g) / (1.0 - g + 2.0 * g * xi)) ** 2) / (2.0 * g)
        sin_s = np.sqrt(np.maximum(0.0, 1.0 - cos_s**2))
        phi = 2.0 * np.pi * rng.random(n)
        ux, uy, uz = v[:, scatter]
        den = np.sqrt(np.maximum(1e-300, 1.0 - uz**2))
        steep = den < 1e-6
        nx = np.where(steep, sin_s * np.cos(phi),
                      sin_s * (ux * uz * np.cos(phi) - uy * np.sin(phi)) / den + ux * cos_s)
        ny = np.where(steep, sin_s * np.sin(phi),
                      sin_s * (uy * uz * np.cos(phi) + ux * np.sin(phi)) / den + uy * cos_s)
        nz = np.where(steep, np.sign(uz) * cos_s, -sin_s * np.cos(phi) * den + uz * cos_s)
        v[:, scatter] = np.stack([nx, ny, nz])
        pos[:, alive], d[:, alive] = p, v
        keep = scatter.copy()
        keep[np.flatnonzero(top)[stays]] = True
        alive = alive[keep]
        low = weight[alive] < 1e-3  # Russian roulette
        survive = rng.random(int(low.sum())) < 0.1
        weight[alive[low][survive]] *= 10.0
        alive = np.concatenate([alive[~low], alive[low][survive]])
    return np.concatenate(landed_x), np.concatenate(landed_w)


def test_a_sinusoidal_sea_deep_down_has_an_independent_walks_pattern(tmp_path):
    """Two long waves (8 m and 2 m, slopes 0.09 and 0.05) over Darecki et al.'s water at 9.58 m
    (443 nm, b s = 5.8: almost all the light scattered), a vertical sun, Henyey–Greenstein g = 0.9:
    the relative amplitude of the floor's pattern at the two waves' wavenumbers from ``small_angle``
    with the walked spread against a float64 Monte Carlo written apart from the package
    (:func:`independent_walk`, 4·10⁶ photons; its standard error from eight random batches): within
    three standard errors plus 3 % (the two surfaces, facets against the exact sinusoid, and the
    flat top for the wavy one) at both. Measured 0.0338 against 0.0326 ± 0.0009 (8 m) and 0.0081
    against 0.0081 ± 0.0010 (2 m). The spread alone, with each texel's own path as a weight of its
    light only, gave 0.0377 at 8 m, beyond the bound: a longer path also spreads its light wider,
    and a turned ray's light lands further out (:meth:`SmallAngleScattering.terms`). Wells's spread
    gives 0.0338 and 0.0060."""
    extent, n, depth, g = 32.0, 256, 9.58, 0.9
    waves = ((4, 0.12), (16, 0.015))  # (cycles per patch, amplitude [m])

    def heights(x):
        return (sum(amp * np.cos(2 * np.pi * k * x / extent) for k, amp in waves),
                sum(-amp * 2 * np.pi * k / extent * np.sin(2 * np.pi * k * x / extent) for k, amp in waves))

    centres = (np.arange(n) + 0.5) * extent / n - 0.5 * extent
    h, _ = heights(np.meshgrid(centres, centres)[0])
    np.save(tmp_path / "h.npy", h.astype(np.float32))
    base = {"water.model": "heightfield", "water.file": str(tmp_path / "h.npy"), "water.resolution": n,
            "water.extent_m": extent, "floor.depth_m": depth, "caustics.map_extent_m": 0.0,
            "caustics.map_resolution": n, "sun.elevation_deg": 90.0, "sun.angular_diameter_deg": 0.0,
            "sky.model": "none", "sky.diffuse_fraction": 0.0, "stats.collector_mm": 0.0,
            "optics.wavelengths": [443.0], "optics.phase_function": "henyey_greenstein",
            "optics.hg_g": g, "optics.mc_samples": 1, "optics.scattering": "small_angle"}
    modes = np.array([k for k, _ in waves])

    def amplitudes(overrides):
        scene = wc.load_scene(CONFIGS / "field" / "darecki2011.toml", {**base, **overrides})
        row = wc.render(scene, device="cpu").floor_irradiance[0].astype(np.float64).mean(axis=0)
        return 2.0 * np.abs(np.fft.rfft(row / row.mean() - 1.0)[modes]) / n, scene

    walked, scene = amplitudes({"optics.beam_spread": "walk"})
    optics = spectra.water_optics(scene.config.optics, spectra.bins_for(scene.config.optics))
    a, b = float(optics.absorption_per_m[0]), float(optics.scattering_per_m[0])
    x, w = independent_walk(heights, extent, depth, a, b, g, scene.config.optics.ior, 4_000_000, seed=4)
    batches = np.array_split(np.random.default_rng(0).permutation(len(x)), 8)
    phase = np.exp(-2j * np.pi * modes[:, None] * x[None] / extent)
    per_batch = [2.0 * np.abs((phase[:, i] * w[i]).sum(axis=1)) / w[i].sum() for i in batches]
    reference = 2.0 * np.abs((phase * w).sum(axis=1)) / w.sum()
    se = np.std(per_batch, axis=0, ddof=1) / math.sqrt(len(batches))
    bound = 3.0 * se + 0.03 * reference
    assert np.all(np.abs(walked - reference) <= bound), (walked, reference, se)

