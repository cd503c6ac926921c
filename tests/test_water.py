"""Water surfaces: Warp FFT vs numpy.fft, the FFT ocean vs its Fourier series, height fields."""

import numpy as np
import pytest
import warp as wp

from warpcaustics import water
from warpcaustics.kernels import heightfield as hf_kernels


@pytest.mark.parametrize("n", [64, 256])
@pytest.mark.parametrize("direction", ["forward", "inverse"])
def test_warp_fft_matches_numpy(device, n, direction, rng):
    """2-D Warp FFT (wp.tile_fft rows + transposes) equals numpy.fft, ‖Δ‖/‖ref‖ ≤ 1e-4."""
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


def _ocean(n, device, **kw):
    params = {"amplitude": 3e-3, "wind_speed_m_s": 5.0, "wind_direction_deg": 25.0, "small_wave_m": 0.0}
    params.update(kw)
    return water.FFTOcean(n, 10.0, 4.0, device, seed=11, **params)


def test_ocean_heights_are_real(device):
    """The evolved spectrum is Hermitian: its Warp inverse FFT is real (imaginary part ≤ 1e-5 of the
    real part), which is what lets two real fields share one complex transform."""
    ocean = _ocean(64, device)
    _, slope_y = ocean.spectra_at(3.7)
    field = water.from_vec2(water.ifft2(slope_y))  # i ky H alone: must transform to ∂h/∂y, real
    assert np.abs(field.imag).max() <= 1e-5 * np.abs(field.real).max()


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
        ocean = water.FFTOcean(n, extent, 1000.0, device, seed=seed, **params)
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

    h0 = water.initial_spectrum(n, extent, seed=11, amplitude=3e-3, wind_speed_m_s=5.0,
                                wind_direction_deg=25.0, small_wave_m=0.0)
    k = water.wavenumbers(n, extent)
    kx, ky = np.meshgrid(k, k)
    kk = np.hypot(kx, ky)
    omega = np.sqrt(9.81 * kk * np.tanh(kk * 4.0))
    neg = (-np.arange(n)) % n
    ht = h0 * np.exp(1j * omega * t) + np.conj(h0[neg][:, neg]) * np.exp(-1j * omega * t)
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
