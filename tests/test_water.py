"""Water surfaces: Warp FFT vs numpy.fft, the FFT ocean vs its Fourier series, height fields."""

import numpy as np
import pytest
import warp as wp

from warpcaustics import water
from warpcaustics.kernels.water import heightfield as hf_kernels

from helpers import CONFIGS, low_pass, subnormal_count


@pytest.mark.parametrize("n", [64, 256])
@pytest.mark.parametrize("direction", ["forward", "inverse"])
def test_warp_fft_matches_numpy(device, n, direction, rng):
    """2-D Warp FFT (wp.tile_fft rows, then columns) equals numpy.fft, ‖Δ‖/‖ref‖ ≤ 1e-4."""
    x = rng.standard_normal((n, n)) + 1j * rng.standard_normal((n, n))
    data = water.to_vec2(x, device)
    if direction == "forward":
        water.fft2(data)
        ref = np.fft.fft2(x)
    else:
        water.ifft2(data)
        ref = np.fft.ifft2(x) * n * n  # unnormalised inverse
    got = water.from_vec2(data)
    assert np.linalg.norm(got - ref) / np.linalg.norm(ref) <= 1e-4


def test_fft_round_trip(device, rng):
    """fft2 then ifft2 returns the input times N² (unnormalised transforms)."""
    n = 128
    x = rng.standard_normal((n, n)) + 1j * rng.standard_normal((n, n))
    data = water.to_vec2(x, device)
    water.ifft2(water.fft2(data))
    got = water.from_vec2(data) / (n * n)
    assert np.linalg.norm(got - x) / np.linalg.norm(x) <= 1e-5


PHILLIPS = {"amplitude": 3e-3, "wind_speed_m_s": 5.0, "wind_direction_deg": 25.0, "small_wave_m": 0.0}


def _phillips_h0(n, extent, seed=11, **params):
    k = water.wavenumbers(n, extent)
    spectrum = water.phillips_spectrum(*np.meshgrid(k, k), **{**PHILLIPS, **params})
    return water.initial_spectrum(spectrum, extent, seed=seed)


def _ocean(n, device, extent=10.0, depth=4.0, seed=11, choppiness=0.0, **params):
    return water.FFTOcean(_phillips_h0(n, extent, seed, **params), extent, depth, device,
                          choppiness=choppiness)


def test_ocean_heights_are_real(device):
    """The evolved height spectrum is Hermitian, so its Warp inverse FFT is real (imaginary part
    ≤ 1e-5 of the real part): the condition for packing two real fields in one complex FFT."""
    ocean = _ocean(64, device)
    heights = water.from_vec2(water.ifft2(water.to_vec2(_spectrum_of_heights(ocean, 3.7), device)))
    assert np.abs(heights.imag).max() <= 1e-5 * np.abs(heights.real).max()
    np.testing.assert_allclose(heights.real, ocean.at(3.7).positions.numpy()[..., 2], atol=1e-6)


def _spectrum_of_heights(ocean, t):
    """h̃(k, t) of an FFTOcean rebuilt on the host from its device arrays (cell-centre phase included)."""
    h0 = water.from_vec2(ocean.h0)
    h0m = water.from_vec2(ocean.h0_minus_conj)
    omega = ocean.omega.numpy().astype(np.float64)
    return h0 * np.exp(-1j * omega * t) + h0m * np.exp(1j * omega * t)


@pytest.mark.parametrize("wind_speed", [4.0, 8.0])
def test_ocean_height_variance_matches_the_spectrum(device, wind_speed):
    """Mean height variance over 24 seeds equals Σ P(k) Δk² of the spectrum it was drawn from
    (tolerance 3σ of the 24-seed mean, σ estimated from the seeds: 1–2.3 % relative); on this
    large, fine patch that sum is within 2 % of the continuous integral A π (V²/g)² / 2, and the
    significant wave height Hs = 4σ_h follows it within 3 %."""
    n, extent, amplitude = 512, 200.0, 3e-3  # k from 0.03 to 8 rad/m: the spectrum fits
    params = {"amplitude": amplitude, "wind_speed_m_s": wind_speed, "wind_direction_deg": 40.0,
              "small_wave_m": 0.0}
    variances = []
    for seed in range(24):
        ocean = water.FFTOcean(_phillips_h0(n, extent, seed, **params), extent, 1000.0, device)
        variances.append(np.var(ocean.at(1.3).positions.numpy()[..., 2].astype(np.float64)))
    variances = np.array(variances)
    k = water.wavenumbers(n, extent)
    kx, ky = np.meshgrid(k, k)
    p = water.phillips_spectrum(kx, ky, **params)
    p[n // 2, :] = 0.0
    p[:, n // 2] = 0.0  # the Nyquist modes are not drawn
    drawn = p.sum() * (2 * np.pi / extent) ** 2
    sigma_mean = variances.std(ddof=1) / np.sqrt(len(variances))
    assert abs(variances.mean() - drawn) <= 3 * sigma_mean
    # σ of the 24-seed mean is ~1 % (4 m/s) and ~2.3 % (8 m/s, fewer long waves in the patch):
    # the 3σ test is tighter than 7 %.
    assert sigma_mean < 0.03 * drawn
    big_l = wind_speed**2 / 9.81
    continuous = amplitude * np.pi * big_l**2 / 2
    assert drawn == pytest.approx(continuous, rel=0.02)
    hs = 4 * np.sqrt(variances.mean())
    assert hs == pytest.approx(4 * np.sqrt(continuous), rel=0.03)


def test_ocean_matches_its_fourier_series(device):
    """Heights and normals equal h(x,t) = Σ h̃(k,t) e^{ik·x} and its gradient, evaluated directly in
    float64 at the cell-centre vertices; the series only holds k = 2πm/L, so h is L-periodic."""
    n, extent, t = 32, 10.0, 2.5
    ocean = _ocean(n, device)
    surface = ocean.at(t)
    pos = surface.positions.numpy().astype(np.float64)
    nrm = surface.normals.numpy().astype(np.float64)

    h0 = _phillips_h0(n, extent)
    k = water.wavenumbers(n, extent)
    kx, ky = np.meshgrid(k, k)
    kk = np.hypot(kx, ky)
    omega = np.sqrt(9.81 * kk * np.tanh(kk * 4.0))
    neg = (-np.arange(n)) % n
    # h̃0(k) travels along +k: e^{-iωt} (Tessendorf eq. 26 with t → −t).
    ht = h0 * np.exp(-1j * omega * t) + np.conj(h0[neg][:, neg]) * np.exp(1j * omega * t)
    x = (np.arange(n) + 0.5) * extent / n - extent / 2
    xs, ys = np.meshgrid(x, x)
    phase = np.exp(1j * (np.multiply.outer(xs, kx) + np.multiply.outer(ys, ky)))  # (n,n,n,n)
    h = np.einsum("abij,ij->ab", phase, ht)
    hx = np.einsum("abij,ij->ab", phase, 1j * kx * ht)
    hy = np.einsum("abij,ij->ab", phase, 1j * ky * ht)
    assert np.abs(h.imag).max() < 1e-9 * np.abs(h.real).max()
    np.testing.assert_allclose(pos[..., 0], xs, atol=1e-6)
    np.testing.assert_allclose(pos[..., 1], ys, atol=1e-6)
    scale = np.abs(h.real).max()
    np.testing.assert_allclose(pos[..., 2], h.real, atol=1e-5 * scale)  # float32 FFT of 32² terms
    expected_n = np.stack([-hx.real, -hy.real, np.ones_like(h.real)], axis=-1)
    expected_n /= np.linalg.norm(expected_n, axis=-1, keepdims=True)
    np.testing.assert_allclose(nrm, expected_n, atol=1e-5)


def test_negligible_amplitudes_become_zero_not_subnormal(device, monkeypatch):
    """``ocean.toml`` at 512²: its h̃0 in float32 would hold subnormal numbers (slow on x86 CPUs);
    the ocean's has none, its heights and slopes still equal a float64 numpy.fft synthesis of the
    whole, unzeroed spectrum to float32 accuracy, and its choppy surface is the same to the bit as
    that of an ocean built from the unzeroed spectrum."""
    import warpcaustics as wc

    n = 512
    cfg = wc.load_scene(CONFIGS / "ocean.toml", {"water.resolution": n}).config
    k = water.wavenumbers(n, cfg.water.extent_m)
    kx, ky = np.meshgrid(k, k)
    h0 = water.initial_spectrum(water.ocean_spectrum(cfg, kx, ky), cfg.water.extent_m, seed=cfg.water.seed)
    assert subnormal_count(h0.astype(np.complex64).view(np.float32)) > 0.01 * n * n  # what is avoided
    ocean = water.FFTOcean(h0, cfg.water.extent_m, cfg.floor.depth_m, device)
    for arr in (ocean.h0, ocean.h0_minus_conj):
        assert subnormal_count(arr.numpy()) == 0
    t = 1.7
    surface = ocean.at(t)
    # float64 synthesis of the raw spectrum (h̃0 travels along +k: Tessendorf eq. 26, t → −t)
    neg = (-np.arange(n)) % n
    omega = water.dispersion(np.hypot(kx, ky), cfg.floor.depth_m)
    x0 = -0.5 * cfg.water.extent_m + 0.5 * cfg.water.extent_m / n
    ht = (h0 * np.exp(-1j * omega * t) + np.conj(h0[neg][:, neg]) * np.exp(1j * omega * t)) \
        * np.exp(1j * (kx + ky) * x0)
    h = np.fft.ifft2(ht).real * n * n
    hx = np.fft.ifft2(1j * kx * ht).real * n * n
    hy = np.fft.ifft2(1j * ky * ht).real * n * n
    heights = surface.positions.numpy()[..., 2].astype(np.float64)
    assert np.abs(heights - h).max() <= 1e-5 * np.abs(h).max()
    expected = np.stack([-hx, -hy, np.ones_like(h)], -1)
    expected /= np.linalg.norm(expected, axis=-1, keepdims=True)
    np.testing.assert_allclose(surface.normals.numpy(), expected, atol=1e-5)

    choppy = water.FFTOcean(h0, cfg.water.extent_m, cfg.floor.depth_m, device, choppiness=1.0).at(t)
    monkeypatch.setattr("warpcaustics.water.ocean.negligible_to_zero", lambda h: h)
    unzeroed = water.FFTOcean(h0, cfg.water.extent_m, cfg.floor.depth_m, device, choppiness=1.0)
    assert subnormal_count(unzeroed.h0.numpy()) > 0
    raw = unzeroed.at(t)
    for name in ("positions", "normals", "jacobian"):
        np.testing.assert_array_equal(getattr(choppy, name).numpy(), getattr(raw, name).numpy(), err_msg=name)


def test_heightfield_normals_and_bilinear_sampling(device, rng):
    """Height-field normals are the periodic central differences of the heights (checked on a sine
    wave), and periodic bilinear sampling equals numpy's interpolation between cell centres."""
    n, extent = 64, 4.0
    x = (np.arange(n) + 0.5) * extent / n - extent / 2
    xs, ys = np.meshgrid(x, x)
    kx = 2 * np.pi * 3 / extent
    heights = 0.05 * np.sin(kx * xs)
    surf = water.HeightfieldWater(heights, extent, device).at(0.0)
    nrm = surf.normals.numpy()
    cell = extent / n
    slope = 0.05 * kx * np.cos(kx * xs) * np.sin(kx * cell) / (kx * cell)  # central difference of sin
    expected = np.stack([-slope, np.zeros_like(slope), np.ones_like(slope)], -1)
    expected /= np.linalg.norm(expected, axis=-1, keepdims=True)
    np.testing.assert_allclose(nrm, expected, atol=2e-6)

    hf = rng.standard_normal((n, n)).astype(np.float32)
    pts = rng.uniform(-extent, extent, size=(500, 2))
    out = wp.empty(500, dtype=wp.float32, device=device)
    wp.launch(hf_kernels.sample_heights, dim=500,
              inputs=[wp.array(hf, dtype=wp.float32, device=device), extent,
                      wp.array(pts.astype(np.float32), dtype=wp.vec2, device=device)],
              outputs=[out], device=device)
    u = (pts[:, 0] + extent / 2) / cell - 0.5
    v = (pts[:, 1] + extent / 2) / cell - 0.5
    i0, j0 = np.floor(u).astype(int), np.floor(v).astype(int)
    tu, tv = u - i0, v - j0
    g = lambda j, i: hf[j % n, i % n].astype(np.float64)  # noqa: E731
    ref = (1 - tv) * ((1 - tu) * g(j0, i0) + tu * g(j0, i0 + 1)) + tv * ((1 - tu) * g(j0 + 1, i0)
                                                                      + tu * g(j0 + 1, i0 + 1))
    # float32 sample coordinates: |u| <= 200 texels -> ~1e-5 in the weights, times jumps of up to
    # ~6 between random neighbours.
    np.testing.assert_allclose(out.numpy(), ref, atol=1e-4)


def _single_mode(n, extent, m, amplitude=0.01):
    """h̃0 with one Fourier mode (m, 0): a single wave travelling along +x."""
    h0 = np.zeros((n, n), complex)
    h0[0, m] = amplitude
    return h0


@pytest.mark.parametrize("depth_m", [1000.0, 1.0])
def test_single_mode_moves_at_the_phase_speed(device, depth_m):
    """A single-mode ocean travels along +k at c = ω/k with ω² = g k tanh(k h) (deep and finite
    depth, k h = 0.79), measured from the phase of its Fourier mode over time, within 1 %."""
    n, extent, m = 64, 32.0, 4
    ocean = water.FFTOcean(_single_mode(n, extent, m), extent, depth_m, device)
    k = 2 * np.pi * m / extent
    expected = np.sqrt(9.81 * k * np.tanh(k * depth_m)) / k
    dt = 0.05
    phases = []
    for t in (0.0, dt):
        h = ocean.at(t).positions.numpy()[..., 2].astype(np.float64)
        phases.append(np.angle(np.fft.fft(h[0])[m]))
    # h ∝ cos(k x - ω t + φ): the mode's phase falls by ω dt, i.e. the crest moves along +x.
    speed = -np.angle(np.exp(1j * (phases[1] - phases[0]))) / (k * dt)
    assert speed == pytest.approx(expected, rel=0.01)
    if depth_m < 10:
        assert expected < 0.9 * np.sqrt(9.81 / k)  # the finite-depth case really differs from deep


def test_spectral_normals_match_finite_differences(device):
    """Normals from spectral derivatives agree with central differences of the heights on a fine grid
    (a band-limited ocean, so the O((kΔ)²) difference error is below 1e-3)."""
    n, extent = 256, 10.0
    ocean = _ocean(n, device, extent=extent, small_wave_m=0.25)
    surface = ocean.at(0.7)
    h = surface.positions.numpy()[..., 2].astype(np.float64)
    cell = extent / n
    hx = (np.roll(h, -1, axis=1) - np.roll(h, 1, axis=1)) / (2 * cell)
    hy = (np.roll(h, -1, axis=0) - np.roll(h, 1, axis=0)) / (2 * cell)
    fd = np.stack([-hx, -hy, np.ones_like(h)], -1)
    fd /= np.linalg.norm(fd, axis=-1, keepdims=True)
    assert np.abs(fd[..., 2] - 1).max() > 1e-3  # the surface is not flat
    np.testing.assert_allclose(surface.normals.numpy(), fd, atol=1e-3)


def test_choppy_jacobian_and_folds(device):
    """Choppy waves: J = 1 everywhere for λ = 0; J equals finite differences of the displaced
    vertices; the folded fraction (J ≤ 0) is 0 for small λ and grows with λ."""
    n, extent = 128, 20.0
    folds = []
    for lam in (0.0, 0.5, 1.5, 3.0):
        surface = _ocean(n, device, extent=extent, choppiness=lam, amplitude=5e-2,
                         small_wave_m=0.5).at(1.0)  # band-limited: differences are accurate
        jac = surface.jacobian.numpy().astype(np.float64)
        folds.append(np.mean(jac <= 0.0))
        if lam == 0.0:
            assert np.all(jac == 1.0)
        if lam == 0.5:
            p = surface.positions.numpy().astype(np.float64)
            cell = extent / n
            dxdx = (np.roll(p[..., 0], -1, 1) - np.roll(p[..., 0], 1, 1)) / (2 * cell)
            dydy = (np.roll(p[..., 1], -1, 0) - np.roll(p[..., 1], 1, 0)) / (2 * cell)
            dxdy = (np.roll(p[..., 0], -1, 0) - np.roll(p[..., 0], 1, 0)) / (2 * cell)
            dydx = (np.roll(p[..., 1], -1, 1) - np.roll(p[..., 1], 1, 1)) / (2 * cell)
            inner = (slice(2, -2), slice(2, -2))  # x wraps by L at the edges
            fd = (dxdx * dydy - dxdy * dydx)[inner]
            # O((kΔ)²) difference error with kΔ ≲ 0.3 at the cut-off.
            assert np.abs(jac[inner] - fd).mean() < 0.03 * np.abs(jac[inner] - 1).mean()
    assert folds[0] == 0.0 and folds[1] == 0.0
    assert folds[3] > folds[2] > 0.0


def test_jonswap_variance_matches_its_frequency_spectrum(device):
    """JONSWAP drawn on the wavenumber grid keeps the variance of the frequency spectrum it came
    from: Σ P(k) Δk² = ∫ S(ω) dω within 3 % (tests the change of variables and the spreading's
    normalisation), and the seeds' mean variance matches within 3σ."""
    from warpcaustics.config import config_from_dict

    cfg = config_from_dict({}, {"water.spectrum": "jonswap", "water.wind_speed_m_s": 6.0,
                                "water.fetch_m": 20000.0, "water.extent_m": 300.0,
                                "water.resolution": 512, "floor.depth_m": 30.0})
    k = water.wavenumbers(512, 300.0)
    p = water.ocean_spectrum(cfg, *np.meshgrid(k, k))
    drawn = p.sum() * (2 * np.pi / 300.0) ** 2

    g, u, f = 9.81, 6.0, 20000.0
    alpha = 0.076 * (u * u / (f * g)) ** 0.22
    wp_ = 22.0 * (g * g / (u * f)) ** (1 / 3)
    omega = np.linspace(0.2 * wp_, 12 * wp_, 200001)
    sigma = np.where(omega <= wp_, 0.07, 0.09)
    s = alpha * g * g / omega**5 * np.exp(-1.25 * (wp_ / omega) ** 4) * 3.3 ** np.exp(
        -((omega - wp_) ** 2) / (2 * sigma**2 * wp_**2))
    assert drawn == pytest.approx(np.trapezoid(s, omega), rel=0.03)

    variances = [np.var(water.FFTOcean.from_config(
        config_from_dict({}, {"water.spectrum": "jonswap", "water.wind_speed_m_s": 6.0,
                              "water.fetch_m": 20000.0, "water.extent_m": 300.0,
                              "water.resolution": 512, "floor.depth_m": 30.0, "water.seed": sd}),
        device).at(0.0).positions.numpy()[..., 2].astype(np.float64)) for sd in range(16)]
    sigma_mean = np.std(variances, ddof=1) / np.sqrt(len(variances))
    assert abs(np.mean(variances) - drawn) <= 3 * sigma_mean


def test_choppy_single_wave_sharpens_its_crest(device):
    """A single choppy wave is a Gerstner wave: vertices move towards the crest, so the Jacobian is
    J = 1 − λ k h (smallest at the crest, where folds start), and x' − x = λ D with ∂D/∂x = −k h."""
    n, extent, m, lam = 64, 32.0, 4, 1.5
    ocean = water.FFTOcean(_single_mode(n, extent, m, amplitude=0.05), extent, 1000.0, device,
                           choppiness=lam)
    surface = ocean.at(0.3)
    k = 2 * np.pi * m / extent
    z = surface.positions.numpy()[..., 2].astype(np.float64)
    jac = surface.jacobian.numpy().astype(np.float64)
    np.testing.assert_allclose(jac, 1.0 - lam * k * z, atol=1e-5)
    x = (np.arange(n) + 0.5) * extent / n - extent / 2
    shift = surface.positions.numpy()[0, :, 0].astype(np.float64) - x
    crest = np.argmax(z[0])
    # just before the crest the vertices move forward (+x), just after it backward: towards it
    assert shift[(crest - 2) % n] > 0 > shift[(crest + 2) % n]


WATER_MODEL_SCENES = {"flat": "flat.toml", "heightfield": "lens.toml", "fft": "ocean.toml",
                      "pool": "pool.toml", "wavepool": "wavepool.toml", "procedural": "procedural.toml"}
"""One example scene per ``water.model`` (``lens.toml``'s file fixes its size; the others run at 32²)."""


def _water_model_scene(model: str):
    import warpcaustics as wc

    overrides = {} if model == "heightfield" else {"water.resolution": 32}
    scene = wc.load_scene(CONFIGS / WATER_MODEL_SCENES[model], overrides)
    assert scene.config.water.model.value == model
    return scene


def _held_array_bytes(*roots) -> int:
    """Bytes of the distinct ``wp.array``s reachable from ``roots`` through the attributes of
    warpcaustics objects, lists, tuples and dicts (an array met twice counts once)."""
    seen_objects, seen_arrays, total, stack = set(), set(), 0, list(roots)
    while stack:
        obj = stack.pop()
        if isinstance(obj, wp.array):
            if obj.ptr not in seen_arrays:
                seen_arrays.add(obj.ptr)
                total += obj.capacity
        elif id(obj) in seen_objects:
            continue
        elif isinstance(obj, dict):
            seen_objects.add(id(obj))
            stack.extend(obj.values())
        elif isinstance(obj, (list, tuple)):
            seen_objects.add(id(obj))
            stack.extend(obj)
        elif type(obj).__module__.startswith("warpcaustics") and hasattr(obj, "__dict__"):
            seen_objects.add(id(obj))
            stack.extend(vars(obj).values())
    return total


def test_every_water_model_is_registered():
    """Each ``water.model`` value names a class in the registry, and make_water builds that class."""
    from warpcaustics.config import WaterModel

    assert set(water.WATER_MODELS) == set(WaterModel) == set(WATER_MODEL_SCENES)
    for model in WaterModel:
        scene = _water_model_scene(model.value)
        built = water.make_water(scene.config, "cpu", scene.heights, scene.floor_relief)
        assert type(built) is water.WATER_MODELS[model]


@pytest.mark.parametrize("model", sorted(WATER_MODEL_SCENES))
def test_water_bytes_is_what_the_model_allocates(device, model):
    """water_bytes on a device equals the bytes of the device arrays the model holds after stepping,
    plus the Surface it returned (the estimate the renderer checks free memory against)."""
    scene = _water_model_scene(model)
    n = scene.water_resolution or scene.heights.shape[0]
    model_water = water.make_water(scene.config, device, scene.heights, scene.floor_relief)
    surface = model_water.at(0.05)  # the pools step: whatever a substep allocates is held now
    assert surface.resolution == n
    assert water.water_bytes(scene.config, n, device) == _held_array_bytes(model_water, surface)


@pytest.mark.parametrize("model", sorted(WATER_MODEL_SCENES))
def test_water_bytes_counts_the_cuda_fft_scratch(model):
    """On CUDA the FFT ocean holds one more N×N complex array than on the CPU, the transposes'
    scratch (FFTOcean.__init__ allocates it only there); every other model holds the same arrays.
    Checked from the device's name, so it runs without a GPU; CUDA is also the default."""
    scene = _water_model_scene(model)
    n = scene.water_resolution or scene.heights.shape[0]
    scratch = n * n * wp.types.type_size_in_bytes(wp.vec2) if model == "fft" else 0
    cpu = water.water_bytes(scene.config, n, "cpu")
    assert water.water_bytes(scene.config, n, "cuda:0") - cpu == scratch
    assert water.water_bytes(scene.config, n) == cpu + scratch


def test_water_depth_sets_the_depth_the_waves_feel():
    """water.depth_m (0: floor.depth_m) is the depth of the dispersion and of JONSWAP's k–ω mapping:
    an ocean over a 0.86 m sensor plane in 1000 m of sea draws the deep sea's spectrum and moves
    at its frequencies, not a 0.86 m shallow sea's."""
    from warpcaustics.config import config_from_dict

    base = {"water.model": "fft", "water.spectrum": "jonswap", "water.resolution": 64, "water.extent_m": 16.0}
    deep = config_from_dict({}, {**base, "floor.depth_m": 1000.0})
    sensor = config_from_dict({}, {**base, "floor.depth_m": 0.86, "water.depth_m": 1000.0})
    shallow = config_from_dict({}, {**base, "floor.depth_m": 0.86})
    k = water.wavenumbers(64, 16.0)
    kx, ky = np.meshgrid(k, k)
    np.testing.assert_array_equal(water.ocean_spectrum(sensor, kx, ky), water.ocean_spectrum(deep, kx, ky))
    assert not np.allclose(water.ocean_spectrum(shallow, kx, ky), water.ocean_spectrum(deep, kx, ky))
    omega = water.FFTOcean.from_config(sensor, "cpu").omega.numpy()
    np.testing.assert_allclose(omega, water.dispersion(np.hypot(kx, ky), 1000.0), rtol=1e-6)


def test_a_long_wave_patch_holds_the_waves_longer_than_its_cut():
    """``water.shortest_wave_m`` = L drops the waves of wavelength L or shorter: the spectrum is zero
    at |k| ≥ 2π/L and unchanged below, and the elevation variance a 128 m patch of the waves over
    8 m holds (Σ P Δk²) is the float64 integral of Elfouhaily et al.'s omnidirectional spectrum
    (eqs. 31, 40: S = (B_l + B_h)/k³) below 2π/8 m⁻¹ to 2 %: half of a 5 m/s sea's, whose peak is
    10 m long."""
    from warpcaustics.config import config_from_dict
    from warpcaustics.water.elfouhaily import curvature_spectra

    def drawn(shortest_m: float) -> tuple[np.ndarray, np.ndarray, float]:
        cfg = config_from_dict({}, {"water.spectrum": "elfouhaily", "water.wind_speed_m_s": 5.0,
                                    "water.fetch_m": 20000.0, "floor.depth_m": 3.2, "water.depth_m": 1000.0,
                                    "water.extent_m": 128.0, "water.resolution": 1024,
                                    "water.shortest_wave_m": shortest_m})
        kx, ky = np.meshgrid(water.wavenumbers(1024, 128.0), water.wavenumbers(1024, 128.0))
        p = water.ocean_spectrum(cfg, kx, ky)
        return p, np.hypot(kx, ky), float(p.sum() * (2 * np.pi / 128.0) ** 2)

    whole, k, total = drawn(0.0)
    long, _, long_part = drawn(8.0)
    cut = 2 * np.pi / 8.0
    assert np.all(long[k >= cut * (1 - 1e-9)] == 0.0)
    below = k < cut * (1 - 1e-9)
    np.testing.assert_array_equal(long[below], whole[below])
    kk = np.logspace(-3, 4, 400001)
    b_long, b_short, _ = curvature_spectra(kk, 5.0, 20000.0)
    s = (b_long + b_short) / kk**3
    assert long_part == pytest.approx(np.trapezoid(s[kk < cut], kk[kk < cut]), rel=0.02)
    assert 0.3 < long_part / total < 0.7


@pytest.mark.parametrize("choppiness", [0.0, 0.8])
def test_a_truncated_ocean_is_the_full_one_s_low_pass(device, choppiness):
    """``FFTOcean.truncated(M)`` (the sky's coarser surface, ``sky.surface_resolution``) is the same
    sea without its shorter waves: its heights, horizontal displacements and (linear sea) normals
    equal the full ocean's, low-passed to the M-grid's wavenumbers in float64 numpy and evaluated at
    its cell centres, to float32 rounding (≤ 1e-5 of the height's scale), at two times."""
    n, m, extent = 128, 32, 10.0
    ocean = _ocean(n, device, extent=extent, choppiness=choppiness)
    coarse = ocean.truncated(m)
    x_fine = (np.arange(n) + 0.5) * extent / n - extent / 2
    x_coarse = (np.arange(m) + 0.5) * extent / m - extent / 2
    for t in (0.0, 2.7):
        fine, cut = ocean.at(t), coarse.at(t)
        pos, expected = cut.positions.numpy(), fine.positions.numpy().astype(np.float64)
        scale = np.abs(expected[..., 2]).max()
        np.testing.assert_allclose(pos[..., 2], low_pass(expected[..., 2], m, extent), atol=1e-5 * scale)
        displaced = expected[..., :2] - np.stack(np.meshgrid(x_fine, x_fine), axis=-1)
        grid = np.stack(np.meshgrid(x_coarse, x_coarse), axis=-1)
        for axis in range(2):
            np.testing.assert_allclose(pos[..., axis] - grid[..., axis],
                                       low_pass(displaced[..., axis], m, extent), atol=1e-5 * scale)
        if choppiness == 0.0:  # the slopes, from the low-passed heights' own spectrum
            heights = low_pass(expected[..., 2], m, extent)
            k = water.wavenumbers(m, extent)
            spectrum = np.fft.fft2(heights)
            sx = np.fft.ifft2(1j * k[None, :] * spectrum).real
            sy = np.fft.ifft2(1j * k[:, None] * spectrum).real
            normal = np.stack([-sx, -sy, np.ones_like(sx)], axis=-1)
            normal /= np.linalg.norm(normal, axis=-1, keepdims=True)
            np.testing.assert_allclose(cut.normals.numpy(), normal, atol=1e-5)
    assert coarse.resolution == m and coarse.extent_m == extent
    with pytest.raises(ValueError, match="power of two"):
        ocean.truncated(48)
