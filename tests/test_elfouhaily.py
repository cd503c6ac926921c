"""The Elfouhaily et al. (1997) unified spectrum (``water.spectrum = "elfouhaily"``): against the
paper's formulas written out here in float64, its spreading's normalisation, and its slope
variance against Cox & Munk (1954)'s clean-surface laws."""

import math

import numpy as np
import pytest

from warpcaustics.config import config_from_dict
from warpcaustics.errors import ConfigError
from warpcaustics.water import elfouhaily as elf

G = 9.81


def paper_spectrum(k: float, phi: float, u10: float, fetch: float) -> float:
    """Ψ(k, φ) [m⁴] of ECKV, one wavenumber at a time, as the paper's equations read (numbers in
    warpcaustics/water/elfouhaily.py's docstring), in plain math: the reference the vectorised
    module is checked against."""
    k0 = G / u10**2
    omega_c = 0.84 * math.tanh((k0 * fetch / 2.2e4) ** 0.4) ** (-0.75)  # eq. 37
    kp = k0 * omega_c**2

    def speed(kk):  # eq. 24, k_m = 370
        return math.sqrt(G / kk * (1.0 + (kk / 370.0) ** 2))

    c, cp = speed(k), speed(kp)
    big_omega = u10 / cp
    gamma = 1.7 + (6.0 * math.log10(omega_c) if omega_c >= 1.0 else 0.0)
    sigma = 0.08 * (1.0 + 4.0 / omega_c**3)
    jp = gamma ** math.exp(-((math.sqrt(k / kp) - 1.0) ** 2) / (2.0 * sigma * sigma))  # eq. 3
    lpm = math.exp(-5.0 / 4.0 * (kp / k) ** 2)  # eq. 2
    fp = lpm * jp * math.exp(-big_omega / math.sqrt(10.0) * (math.sqrt(k / kp) - 1.0))  # eq. 32
    bl = 0.5 * 6e-3 * math.sqrt(big_omega) * (cp / c) * fp  # eqs. 31, 34
    z0 = 3.7e-5 * u10**2 / G * big_omega**0.9  # eq. 66
    ustar = 0.41 * u10 / math.log(10.0 / z0)  # eq. 60
    if ustar <= 0.23:  # eq. 44
        alpha_m = 0.01 * (1.0 + math.log(ustar / 0.23))
    else:
        alpha_m = 0.01 * (1.0 + 3.0 * math.log(ustar / 0.23))
    fm = lpm * jp * math.exp(-0.25 * (k / 370.0 - 1.0) ** 2)  # eq. 41 with L_PM J_p
    bh = 0.5 * max(alpha_m, 0.0) * (0.23 / c) * fm  # eq. 40
    s = (bl + bh) / k**3  # eq. 30
    delta = math.tanh(math.log(2.0) / 4.0 + 4.0 * (c / cp) ** 2.5
                      + 0.13 * ustar / 0.23 * (0.23 / c) ** 2.5)  # eqs. 57, 59
    return s / k * (1.0 + delta * math.cos(2.0 * phi)) / (2.0 * math.pi)  # eqs. 49, 67


@pytest.mark.parametrize("u10, fetch", [(1.5, 1e6), (5.0, 20000.0), (10.0, 1e9), (13.0, 3000.0)])
def test_spectrum_matches_the_papers_formulas(u10, fetch):
    """The vectorised P(k_x, k_y) equals the formulas evaluated one point at a time (1e-12), from the
    peak's long waves to capillary ones, up-, cross- and down-wind, and in a turned wind."""
    rng = np.random.default_rng(1)
    k = np.exp(rng.uniform(math.log(0.02), math.log(3000.0), 300))
    phi = rng.uniform(-math.pi, math.pi, 300)
    wind_deg = 35.0
    p = elf.elfouhaily_spectrum(k * np.cos(phi), k * np.sin(phi), wind_speed_m_s=u10,
                                wind_direction_deg=wind_deg, fetch_m=fetch)
    ref = [paper_spectrum(kk, ph - math.radians(wind_deg), u10, fetch) for kk, ph in zip(k, phi)]
    # atol: values in float64's subnormal range (< 2e-308, far below any drawn amplitude) keep fewer digits
    np.testing.assert_allclose(p, ref, rtol=1e-12, atol=1e-300)
    assert elf.elfouhaily_spectrum(np.zeros(1), np.zeros(1), wind_speed_m_s=u10, wind_direction_deg=0.0,
                                   fetch_m=fetch)[0] == 0.0


def test_spreading_keeps_the_omnidirectional_variance():
    """∫P d²k over the plane (polar grid, P k dk dφ) equals ∫S dk of the omnidirectional spectrum
    (1e-9): Φ integrates to one at every k; and a wave age from the fetch that tends to 0.84."""
    u10, fetch = 7.0, 50000.0
    k = np.logspace(-3, 4, 20001)
    phi = np.linspace(-math.pi, math.pi, 721)[:-1]
    kk, pp = np.meshgrid(k, phi)
    p = elf.elfouhaily_spectrum(kk * np.cos(pp), kk * np.sin(pp), wind_speed_m_s=u10, wind_direction_deg=0.0,
                                fetch_m=fetch)
    plane = np.trapezoid(p.sum(axis=0) * (phi[1] - phi[0]) * k, k)
    bl, bh, _ = elf.curvature_spectra(k, u10, fetch)
    assert plane == pytest.approx(np.trapezoid((bl + bh) / k**3, k), rel=1e-9)
    assert elf.inverse_wave_age(u10, 1e12) == pytest.approx(0.84, rel=1e-9)


@pytest.mark.parametrize("u10", [3.0, 5.0, 7.0, 10.0, 14.0])
def test_slope_variance_follows_cox_and_munk(u10):
    """Mean square slopes of a fully developed sea (∫B d ln k: total; with the spreading, up- and
    cross-wind ∫B (½ ± Δ/4) d ln k) against Cox & Munk (1954)'s clean-surface fits,
    0.003 + 5.12e-3 W ± 0.004, 3.16e-3 W ± 0.004 and 0.003 + 1.92e-3 W ± 0.002, W the wind at
    12.5 m (from U₁₀ by the log profile of u* and z_0): each within two of its fit's ± (the scatter
    of their observations about the fit). Measured: ECKV lies above the total fit by 0.003-0.007
    (docs/physics.md); below 3 m/s its fully developed long waves alone exceed the fit."""
    k = np.logspace(-5, 5, 400001)
    bl, bh, delta = elf.curvature_spectra(k, u10, 1e12)
    b, ln_k = bl + bh, np.log(k)
    total = np.trapezoid(b, ln_k)
    up = np.trapezoid(b * (0.5 + delta / 4.0), ln_k)
    cross = np.trapezoid(b * (0.5 - delta / 4.0), ln_k)
    ustar = elf.friction_velocity(u10, u10 / float(elf.phase_speed(np.array(G / u10**2 * 0.84**2))))
    z0 = 10.0 / math.exp(elf.KARMAN * u10 / ustar)
    w = u10 * math.log(12.5 / z0) / math.log(10.0 / z0)
    assert total == pytest.approx(0.003 + 5.12e-3 * w, abs=2 * 0.004)
    assert up == pytest.approx(3.16e-3 * w, abs=2 * 0.004)
    assert cross == pytest.approx(0.003 + 1.92e-3 * w, abs=2 * 0.002)
    assert up > cross


def test_fft_ocean_draws_the_spectrum_and_its_slopes():
    """An FFT ocean of this spectrum (128² over 4 m, 3 cm cells) has, over 8 seeds, the slope
    variance Σ k² P Δk² of the grid's modes (3σ of the seeds' mean), its anisotropy with it."""
    import warpcaustics.water as water

    n, extent = 128, 4.0
    base = {"water.model": "fft", "water.spectrum": "elfouhaily", "water.wind_speed_m_s": 8.0,
            "water.fetch_m": 50000.0, "water.extent_m": extent, "water.resolution": n, "floor.depth_m": 50.0}
    k = water.wavenumbers(n, extent)
    kx, ky = np.meshgrid(k, k)
    p = water.ocean_spectrum(config_from_dict({}, base), kx, ky)
    p[n // 2, :] = 0.0
    p[:, n // 2] = 0.0
    dk2 = (2 * np.pi / extent) ** 2
    want = np.array([(kx**2 * p).sum(), (ky**2 * p).sum()]) * dk2
    got = []
    for seed in range(8):
        ocean = water.FFTOcean.from_config(config_from_dict({}, {**base, "water.seed": seed}), "cpu")
        nrm = ocean.at(0.7).normals.numpy().astype(np.float64)
        got.append([np.mean((nrm[..., 0] / nrm[..., 2]) ** 2), np.mean((nrm[..., 1] / nrm[..., 2]) ** 2)])
    got = np.array(got)
    sigma = got.std(axis=0, ddof=1) / math.sqrt(len(got))
    assert np.all(np.abs(got.mean(axis=0) - want) <= 3 * sigma)
    assert want[0] > 1.2 * want[1]  # up-wind slopes exceed cross-wind ones


def test_a_fetch_too_short_for_the_fits_is_refused():
    with pytest.raises(ConfigError, match="water.fetch_m = 100 .* at least 147.7 m"):
        config_from_dict({}, {"water.model": "fft", "water.spectrum": "elfouhaily",
                              "water.wind_speed_m_s": 5.0, "water.fetch_m": 100.0})
    assert elf.inverse_wave_age(5.0, elf.shortest_fetch_m(5.0)) == pytest.approx(5.0, rel=1e-12)


def test_the_config_s_45_degree_wind_gives_the_mean_slope_over_azimuths():
    """configs/field/gernez2009.toml puts the wind at 45° to the sun because the slope variance along
    an azimuth φ of the wind, Σ P (k·ê_φ)² Δk², is then the mean over all azimuths (up-wind +
    cross-wind)/2: checked on the config's own grid (5 m/s, 20 km, 2048² over 8 m) against the
    variance along 0° and 90° and along 36 azimuths (1e-9), with up-wind and cross-wind apart."""
    from warpcaustics import water
    from warpcaustics.scene import load_scene

    cfg = load_scene(__import__("pathlib").Path(__file__).resolve().parents[1]
                     / "configs/field/gernez2009.toml").config
    k = water.wavenumbers(cfg.water.resolution, cfg.water.extent_m)
    kx, ky = np.meshgrid(k, k)
    p = water.ocean_spectrum(cfg, kx, ky)
    wind = math.radians(cfg.water.wind_direction_deg)

    def along(phi):
        return float(np.sum(p * (kx * math.cos(phi) + ky * math.sin(phi)) ** 2))

    up, cross = along(wind), along(wind + math.pi / 2)
    sun = along(0.0)  # the sun's azimuth is 0 in the config
    assert cfg.sun.azimuth_deg == 0.0 and abs(cfg.water.wind_direction_deg) == 45.0
    assert up > 1.2 * cross
    assert sun == pytest.approx(0.5 * (up + cross), rel=1e-9)
    azimuths = np.linspace(0, np.pi, 36, endpoint=False)
    assert sun == pytest.approx(np.mean([along(a) for a in azimuths]), rel=1e-9)


def test_the_darecki_commands_frames_are_further_apart_than_the_peak_waves_period():
    """The Darecki commands' frames, 5 s apart by default, each draw a new realisation of the largest
    waves: the peak waves' period, 2π/√(g k_p) with k_p from eq. 37 written out here, is 2.6 s at the
    irradiance record's wind (5.25 m/s) and 2.1-3.0 s at the radiance panels' (3.6-7 m/s) over the
    configs' 20 km of fetch, as the commands' docstrings say; the module's Ω_c is the same."""
    import inspect
    from pathlib import Path

    from warpcaustics.batch.field import darecki2011, darecki2011_radiance
    from warpcaustics.config.loading import tomllib  # tomli on Python 3.10

    configs = Path(__file__).resolve().parents[1] / "configs" / "field"

    def peak_period(u10, fetch):
        omega_c = 0.84 * math.tanh((G * fetch / u10**2 / 2.2e4) ** 0.4) ** (-0.75)  # eq. 37
        assert elf.inverse_wave_age(u10, fetch) == pytest.approx(omega_c, rel=1e-12)
        return 2.0 * math.pi / math.sqrt(G * G / u10**2 * omega_c**2)

    water = tomllib.loads((configs / "darecki2011.toml").read_text())["water"]
    assert peak_period(water["wind_speed_m_s"], water["fetch_m"]) == pytest.approx(2.6, abs=0.05)
    fetch = tomllib.loads((configs / "darecki2011_radiance.toml").read_text())["water"]["fetch_m"]
    periods = [peak_period(float(darecki2011_radiance.record(p).wind_m_s), fetch) for p in "abc"]
    assert (min(periods), max(periods)) == pytest.approx((2.1, 3.0), abs=0.05)
    for run in (darecki2011.run_darecki2011, darecki2011_radiance.run_darecki2011_radiance):
        assert inspect.signature(run).parameters["frame_interval_s"].default > max(periods)
