"""sky.sampling = "halves" (issue 32 item 3): the sky's directions as two independently drawn
halves, each an unbiased estimate of the sky's continuum, and the frame statistics' CV and spatial
power spectrum without the directions' own caustic noise (``cv_continuous_sky``, ``band_cov``)."""

import math

import numpy as np
import pytest
from scipy import integrate

import warpcaustics as wc
from warpcaustics.batch.stats import (
    continuous_sky_cv,
    continuous_sky_moments,
    continuous_sky_spectrum,
    cross_band_power,
    frame_statistics,
    octave_band_edges,
)
from warpcaustics.errors import ConfigError

from helpers import fresnel_t_angles

SKY = {"sky.model": "uniform", "sky.diffuse_fraction": 0.3}
FLAT = {"water.model": "flat", "water.extent_m": 4.0, "water.resolution": 8, "caustics.map_resolution": 8,
        "optics.wavelengths": [500.0], "floor.depth_m": 2.0}


def test_the_stratified_set_is_unchanged():
    """Without a generator the directions are the fixed stratified set: sinθ_j = √((j + ½)/K),
    φ_j = (j + ½) × the golden angle."""
    scene = wc.load_scene(None, {**SKY, "sky.directions": 16})
    d, shares = scene.sky_directions()
    j = np.arange(16) + 0.5
    np.testing.assert_allclose(np.hypot(d[:, 0], d[:, 1]), np.sqrt(j / 16), atol=1e-12)
    phi = np.mod(j * math.pi * (3.0 - math.sqrt(5.0)), 2 * math.pi)
    np.testing.assert_allclose(np.mod(np.arctan2(d[:, 1], d[:, 0]), 2 * math.pi), phi, atol=1e-9)
    np.testing.assert_allclose(shares * d[:, 2], 1.0 / 16)


@pytest.mark.parametrize("model", ["uniform", "cie_clear"])
def test_each_half_is_an_unbiased_estimate_of_the_sky(model):
    """Every direction of either half is cosine-distributed, and a CIE sky's shares are over its
    fixed mean radiance: over 4000 draws, each half's share-weighted sums (twice each half's, as it
    stands for the whole sky) of 1, cos²θ, cos⁴θ, sinθ cosφ and sin²θ cos2φ average to the same sums
    over 4096 fixed stratified directions within 4 standard errors (for the uniform sky the
    cosine-weighted integrals 1, 1/2, 1/3, 0, 0, and each half's horizontal share is ½ exactly);
    the halves differ draw to draw."""

    def sums(d, shares):
        h = shares * d[:, 2]  # horizontal shares
        phi = np.arctan2(d[:, 1], d[:, 0])
        sin_t = np.hypot(d[:, 0], d[:, 1])
        f = np.stack([np.ones(len(d)), d[:, 2] ** 2, d[:, 2] ** 4, sin_t * np.cos(phi),
                      sin_t**2 * np.cos(2 * phi)])
        return (f * h).sum(axis=1)

    sky = {"sky.model": model, "sky.diffuse_fraction": 0.3}
    reference = sums(*wc.load_scene(None, {**sky, "sky.directions": 4096}).sky_directions())
    if model == "uniform":
        np.testing.assert_allclose(reference, [1.0, 0.5, 1.0 / 3.0, 0.0, 0.0], atol=1e-4)
    scene = wc.load_scene(None, {**sky, "sky.directions": 8, "sky.sampling": "halves"})
    rng = np.random.default_rng(7)
    moments = {0: [], 1: []}
    for _ in range(4000):
        d, shares = scene.sky_directions(rng)
        for half in (0, 1):
            moments[half].append(2.0 * sums(d[half::2], shares[half::2]))
            if model == "uniform":
                assert (shares * d[:, 2])[half::2].sum() == pytest.approx(0.5, rel=1e-12)
    for half in (0, 1):
        m = np.array(moments[half])
        se = m.std(axis=0) / math.sqrt(len(m))
        assert np.all(np.abs(m.mean(axis=0) - reference) < 4 * se + 1e-6)
    first, second = scene.sky_directions(np.random.default_rng(1))[0], scene.sky_directions(rng)[0]
    assert not np.allclose(first, second)


def test_halves_over_still_water_are_unbiased():
    """A uniform sky over still water through 8 directions drawn anew each frame: each half alone
    (twice its map) is a poor estimate of ∫ L cosθ T(θ) e^{−cD/cosθt} dΩ (float64 quadrature,
    Fresnel in angle form) in one frame, but over 120 frames its mean is that integral within 4
    standard errors, and the frame's whole sky is the halves' sum; the map is uniform, so the CV
    with the sky's continuum is 0."""
    scene = wc.load_scene(None, {**FLAT, **SKY, "sky.directions": 8, "sky.sampling": "halves"})
    renderer = wc.Renderer(scene, device="cpu")
    halves = []
    for frame in range(120):
        r = renderer.render(0.01 * frame)
        sky, even = r.sky_floor_irradiance[0].astype(np.float64), r.sky_floor_irradiance_even[0]
        np.testing.assert_allclose(sky.std(), 0.0, atol=1e-6 * sky.mean())
        halves.append((2.0 * even.mean(), 2.0 * (sky - even).mean()))
        stats = frame_statistics(r, scene.config.stats)
        assert stats["irradiance_w_m2"]["cv_continuous_sky"] == pytest.approx(0.0, abs=1e-5)
    c = float(r.attenuation_per_m[0])

    def integrand(theta):
        t = fresnel_t_angles(np.array([theta]), 1.0, float(r.ior[0]))[0]
        theta_t = math.asin(math.sin(theta) / float(r.ior[0]))
        return math.cos(theta) * math.sin(theta) * t * math.exp(-c * 2.0 / math.cos(theta_t))

    e_sky = scene.sky_irradiance(r.sun_irradiance)[0]
    expected = e_sky / math.pi * 2 * math.pi * integrate.quad(integrand, 0.0, math.pi / 2, limit=200)[0]
    halves = np.array(halves)
    se = halves.std(axis=0) / math.sqrt(len(halves))
    assert np.all(se > 1e-4 * expected)  # each frame's halves do differ
    assert np.all(np.abs(halves.mean(axis=0) - expected) < 4 * se)


def test_the_covariance_of_the_halves_takes_out_their_noise():
    """On fields made up here (float64): a direct part, a sky continuum and two halves, each (twice
    its map, as it stands for the whole sky) with independent noise of 4× the continuum's variance.
    The plain CV is 1.6× too high; the halves' covariance gives the CV of direct + continuum to 2 %;
    with noiseless halves it is that CV exactly (1e-12)."""
    rng = np.random.default_rng(3)
    m = 512
    x = np.linspace(0, 2 * math.pi, m, endpoint=False)
    direct = 1.0 + 0.3 * np.sin(3 * x)[:, None] * np.cos(2 * x)[None, :]
    continuum = 4.0 + 0.4 * np.cos(5 * x)[None, :] + 0.2 * np.sin(7 * x)[:, None]
    noise = 2.0 * continuum.std()
    even = 0.5 * continuum + 0.5 * noise * rng.standard_normal((m, m))
    odd = 0.5 * continuum + 0.5 * noise * rng.standard_normal((m, m))
    truth = direct + continuum
    cv_truth = truth.std() / truth.mean()
    total = direct + even + odd
    assert total.std() / total.mean() > 1.5 * cv_truth
    assert continuous_sky_cv([continuous_sky_moments(total, even + odd, even)]) == pytest.approx(cv_truth,
                                                                                                rel=0.02)
    exact = continuous_sky_moments(truth, continuum, 0.5 * continuum)
    assert continuous_sky_cv([exact]) == pytest.approx(cv_truth, rel=1e-12)
    assert continuous_sky_cv([]) is None


def test_pooled_over_frames_the_halves_noise_in_the_means_drops_out():
    """Frames whose halves' means are off by independent noise (a few random directions misjudge
    the sky's mean) and whose true means differ (the sea's largest scales): pooled over 400 frames
    the covariance gives the pooled CV of direct + continuum to 3 %, while pooling each half's own
    CV (or the map's) keeps the means' noise."""
    rng = np.random.default_rng(5)
    m = 64
    x = np.linspace(0, 2 * math.pi, m, endpoint=False)
    frames, truth, plain = [], [], []
    for _ in range(400):
        level = 1.0 + 0.1 * rng.standard_normal()  # the true mean moves from frame to frame
        direct = level * (1.0 + 0.2 * np.sin(x + rng.uniform(0, 6))[:, None])
        continuum = 3.0 * level * (1.0 + 0.05 * np.cos(2 * x)[None, :])
        bias_even, bias_odd = 0.3 * rng.standard_normal(2)  # each half's error in the mean
        even = 0.5 * continuum * (1.0 + bias_even) + 0.2 * rng.standard_normal((m, m))
        odd = 0.5 * continuum * (1.0 + bias_odd) + 0.2 * rng.standard_normal((m, m))
        frames.append(continuous_sky_moments(direct + even + odd, even + odd, even))
        truth.append(direct + continuum)
        plain.append(direct + even + odd)
    truth, plain = np.array(truth), np.array(plain)
    cv_truth = truth.std() / truth.mean()
    assert plain.std() / plain.mean() > 1.3 * cv_truth
    assert continuous_sky_cv(frames) == pytest.approx(cv_truth, rel=0.03)


def test_band_powers_add_up_to_the_variance_and_the_halves_give_the_continuums():
    """Fields made up here (float64), 128² over 4 m: the octave bands run from 1/4 to 32 cycles per
    m (the Nyquist corner, 22.6, inside the last); a map's band powers add up to its variance
    (1e-12; a Hann-tapered window of white noise to 2 %); cosines of known amplitude α put α²/2 in
    their own band (1e-12). Halves with independent white noise of 4× the field's variance each:
    pooled over 64 frames the bands of their cross-power are the noiseless field's (within 4
    standard errors of the frames' spread), while one half's own spectrum carries the noise."""
    rng = np.random.default_rng(11)
    m, extent = 128, 4.0
    edges = octave_band_edges(m, extent)
    np.testing.assert_allclose(edges, 2.0 ** np.arange(8) / extent)
    x = (np.arange(m) + 0.5) * extent / m
    modes = [(0.5, 0.3), (1.5, 0.2), (6.0, 0.1)]  # (cycles per m, amplitude): bands 1, 2 and 4
    field = np.tile(2.0 + sum(a * np.cos(2 * math.pi * f * x) for f, a in modes), (m, 1))
    expected = np.zeros(len(edges) - 1)
    for f, a in modes:
        expected[np.searchsorted(edges, f, side="right") - 1] += 0.5 * a**2
    np.testing.assert_allclose(cross_band_power(field, field, extent, periodic=True), expected, atol=1e-12)
    noise = rng.standard_normal((m, m))
    for periodic, rel in ((True, 1e-12), (False, 0.02)):
        total = cross_band_power(noise, noise, extent, periodic=periodic).sum()
        assert total == pytest.approx(noise.var(), rel=rel)
    sigma = 2.0 * field.std()
    frames, own = [], []
    for _ in range(64):
        even = 0.5 * field + 0.5 * sigma * rng.standard_normal((m, m))
        odd = 0.5 * field + 0.5 * sigma * rng.standard_normal((m, m))
        frames.append(continuous_sky_moments(even + odd, even + odd, even, extent_m=extent))
        own.append(cross_band_power(2 * even, 2 * even, extent, periodic=True))
    bands = np.array([f["band_cov"] for f in frames])
    se = bands.std(axis=0) / math.sqrt(len(bands))
    assert np.all(np.abs(bands.mean(axis=0) - expected) < 4 * se + 1e-12), (bands.mean(axis=0), expected, se)
    assert np.mean(own, axis=0)[-1] > 100 * se[-1]  # white noise: most of its power in the top band
    pooled = continuous_sky_spectrum(frames)
    level = np.mean([0.5 * (f["mean_a"] + f["mean_b"]) for f in frames])
    np.testing.assert_allclose(pooled["relative_power"], bands.mean(axis=0) / level**2, rtol=1e-12)
    assert continuous_sky_spectrum([]) is None


def test_a_seas_continuum_spectrum_from_halves_is_the_many_directions_sky():
    """A 32² FFT sea over 2 m, the sun 5° high with 85 % sky, 3 m deep, no absorption: the power
    spectrum of E/Ē − 1 in octave bands (0.5 to 32 cycles per m) from the cross-power of 64
    directions in halves, 16 draws 1 µs apart (the same sea to float32, new directions each), within
    3 standard errors of the stratified sky extrapolated to a continuum — (4 P₄₀₉₆ − P₁₀₂₄)/3, its
    excess falling as 1/D — in every band (measured within 1.0), where 16 stratified directions
    carry 4–37× too much power (measured) and more than 5× in the three finest bands. (From 256 and
    1024 directions the extrapolation undershot the 2–4 cycles per m band by 40 %: 1024 directions
    had converged there, their excess no longer falling as 1/D.)"""
    sea = {"water.model": "fft", "water.resolution": 32, "water.extent_m": 2.0, "water.depth_m": 50.0,
           "caustics.map_resolution": 32, "optics.wavelengths.bins": 1, "floor.depth_m": 3.0,
           "sky.model": "uniform", "sky.diffuse_fraction": 0.85, "sun.elevation_deg": 5.0,
           "optics.water_type": "none"}

    def spectrum(directions):
        scene = wc.load_scene(None, {**sea, "sky.directions": directions})
        f = wc.render(scene, device="cpu").floor_irradiance[0]
        return cross_band_power(f, f, 2.0, periodic=True) / float(np.mean(f, dtype=np.float64)) ** 2

    continuum = (4.0 * spectrum(4096) - spectrum(1024)) / 3.0
    renderer = wc.Renderer(wc.load_scene(None, {**sea, "sky.directions": 64, "sky.sampling": "halves"}),
                           device="cpu")
    frames = []
    for j in range(16):
        r = renderer.render(j * 1e-6)
        frames.append(continuous_sky_moments(r.floor_irradiance[0], r.sky_floor_irradiance[0],
                                             r.sky_floor_irradiance_even[0], extent_m=2.0))
    halves = continuous_sky_spectrum(frames)["relative_power"]
    mean = np.mean([0.5 * (f["mean_a"] + f["mean_b"]) for f in frames])
    se = np.std([f["band_cov"] for f in frames], axis=0) / mean**2 / math.sqrt(len(frames))
    assert np.all(np.abs(halves - continuum) < 3 * se), (halves, continuum, se)
    assert np.all(spectrum(16)[-3:] > 5 * continuum[-3:])


@pytest.mark.parametrize("scattering", ["single", "small_angle"])
def test_a_sea_under_halves_reports_the_continuum_cv(scattering):
    """On a small FFT sea, with single and small-angle scattering: the halves' maps add up to the
    sky's (its even half holds about half the sky, scattered light included), the walk of the
    small-angle mode lights from this frame's directions, and the total, each
    band and the sky alone report ``cv_continuous_sky``, the direct sun's part does not (it has no
    sky), nor does a stratified sky."""
    sea = {"water.model": "fft", "water.resolution": 32, "water.extent_m": 2.0, "water.depth_m": 50.0,
           "caustics.map_resolution": 32, "optics.wavelengths": [450.0, 550.0], "floor.depth_m": 1.5,
           "stats.per_band": True, "optics.scattering": scattering, **SKY}
    scene = wc.load_scene(None, {**sea, "sky.directions": 8, "sky.sampling": "halves"})
    renderer = wc.Renderer(scene, device="cpu")
    r = renderer.render(0.0)
    walk = renderer.method.multiple
    if walk is not None:  # the walk that sets the scattered light's mean takes this frame's directions
        np.testing.assert_allclose(walk.sky_dirs.numpy(), renderer.light.sky_directions, atol=1e-7)
    even, sky = r.sky_floor_irradiance_even, r.sky_floor_irradiance
    assert np.all(even.mean(axis=(1, 2)) > 0.25 * sky.mean(axis=(1, 2)))
    assert np.all((sky - even).mean(axis=(1, 2)) > 0.25 * sky.mean(axis=(1, 2)))
    stats = frame_statistics(r, scene.config.stats)
    for s in (stats["irradiance_w_m2"], stats["sky_irradiance_w_m2"], *stats["bands"].values()):
        assert s["cv_continuous_sky"] is not None and s["cv_continuous_sky"] >= 0.0
    assert "cv_continuous_sky" not in stats["direct_irradiance_w_m2"]
    plain = wc.render(wc.load_scene(None, {**sea, "sky.directions": 8}), device="cpu")
    assert plain.sky_floor_irradiance_even is None
    assert "cv_continuous_sky" not in frame_statistics(plain, scene.config.stats)["irradiance_w_m2"]


@pytest.mark.parametrize(("overrides", "needle"), [
    ({"sky.directions": 7}, "even number of at least 2"),
    ({"caustics.method": "photons"}, 'caustics.method = "fluxratio"'),
    ({"optics.scattering": "multiple"}, '"single" or "small_angle"'),
    ({"sky.model": "none", "sky.diffuse_fraction": 0.0}, "set sky.model"),
])
def test_halves_errors_are_one_line(overrides, needle):
    with pytest.raises(ConfigError, match=needle):
        wc.load_scene(None, {**FLAT, **SKY, "sky.directions": 8, "sky.sampling": "halves", **overrides})
