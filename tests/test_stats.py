"""Irradiance statistics, PAR, collector averaging and the science outputs, on fields with known answers."""

import json
import math

import jerlov
import numpy as np
import pytest
from scipy import special

import warpcaustics as wc
from warpcaustics.batch import stats
from warpcaustics.errors import ConfigError

from helpers import CONFIGS


def _spectrum(wl):
    """A smooth made-up spectral irradiance [W m⁻² nm⁻¹] (a test input, not data)."""
    return 1.2 + 0.4 * np.sin(wl / 37.0) + 0.002 * (wl - 550.0)


@pytest.mark.parametrize(("bins", "rtol"), [(300, 1e-5), (16, 2e-3)])
def test_par_matches_jerlov(bins, rtol):
    """PAR of a floor map equals jerlov's photon integral of the same spectrum (its own constants
    and quadrature): to 1e-5 with 1 nm bins, to 2e-3 with 16 bins of bin averages."""
    fine = np.arange(400.0, 700.001, 0.05)
    reference = jerlov.par_profile(_spectrum(fine), fine, 0.0, kd=np.zeros_like(fine), unit="energy").par
    edges = np.linspace(400.0, 700.0, bins + 1)
    averages = np.array([_spectrum(np.linspace(a, b, 401)).mean() for a, b in zip(edges[:-1], edges[1:])])
    floor = np.broadcast_to(averages[:, None, None], (bins, 4, 4))
    np.testing.assert_allclose(stats.par_map(floor, edges), float(np.ravel(reference)[0]), rtol=rtol)


def test_par_counts_only_400_to_700_nm():
    """Bins outside 400–700 nm add nothing; a bin straddling 700 nm counts its part inside."""
    edges = np.array([350.0, 400.0, 650.0, 750.0])
    w = stats.par_weights(edges)
    assert w[0] == 0.0
    np.testing.assert_allclose(w[2] / w[1], (700.0**2 - 650.0**2) / (650.0**2 - 400.0**2))


def _sine_field(m, periods, amplitude):
    x = (np.arange(m) + 0.5) / m
    return np.tile(1.0 + amplitude * np.sin(2 * np.pi * periods * x), (m, 1))


def test_cv_flashes_and_pdf_of_a_sine():
    """E = 1 + a sin(kx) over whole periods: CV = a/√2, the fraction above 1.5 Ē is
    (π − 2 asin(0.5/a))/2π, and the density of E/Ē integrates to 1 with mean 1."""
    a = 0.8
    out = stats.field_statistics(_sine_field(1024, 8, a), 1.5)
    assert out["mean"] == pytest.approx(1.0, abs=1e-12)
    assert out["cv"] == pytest.approx(a / math.sqrt(2.0), rel=1e-6)
    # texels sample each period 128 times: each of its two crossings moves the count by < 1 texel
    expected_fraction = (math.pi - 2 * math.asin(0.5 / a)) / (2 * math.pi)
    assert out["flash_fraction"] == pytest.approx(expected_fraction, abs=1.0 / 128)
    pdf = np.asarray(out["pdf"])
    widths = np.diff(stats.PDF_EDGES)
    centres = 0.5 * (stats.PDF_EDGES[1:] + stats.PDF_EDGES[:-1])
    assert (pdf * widths).sum() == pytest.approx(1.0)
    assert (pdf * widths * centres).sum() == pytest.approx(1.0, abs=0.01)  # bin-centre quadrature


@pytest.mark.parametrize("diameter_texels", [3.0, 10.0, 21.5])
def test_collector_damps_a_sine_like_a_disc_should(diameter_texels):
    """Averaging a sine of wavenumber k over a disc of radius r multiplies its amplitude by
    2 J₁(kr)/(kr) (the disc's Fourier transform); the periodic convolution does so within 2e-3."""
    m, periods, a = 256, 6, 0.5
    texel = 1.0 / m
    field = _sine_field(m, periods, a)
    averaged = stats.collector_average(field, texel, diameter_texels * texel, periodic=True)
    k = 2 * np.pi * periods
    kr = k * 0.5 * diameter_texels * texel
    expected = a * 2 * special.j1(kr) / kr
    measured = (averaged.max() - averaged.min()) / 2
    assert measured == pytest.approx(expected, abs=2e-3 * a)
    assert averaged.mean() == pytest.approx(1.0, abs=1e-12)


def test_collector_on_an_open_map_keeps_a_uniform_field_uniform():
    """On a non-periodic map the disc is cut at the edges and renormalised: a constant stays constant."""
    out = stats.collector_average(np.full((40, 40), 3.0), 0.01, 0.13, periodic=False)
    np.testing.assert_allclose(out, 3.0, rtol=1e-12)


def test_time_series_flashes_and_spectrum():
    """E(t) = 1 + 0.8 sin(2π·2t) over 10 s at 20 Hz: 2 flashes per second above 1.5 Ē, the spectrum
    peaks at 2 Hz, CV = 0.8/√2."""
    t = np.arange(200) / 20.0
    e = 1.0 + 0.8 * np.sin(2 * np.pi * 2.0 * t + 0.3)
    out = stats.series_statistics(e[:, None], 0.05, 1.5)
    assert out["flash_frequency_hz"][0] == pytest.approx(2.0, abs=1.0 / 9.95)
    assert out["peak_frequency_hz"][0] == pytest.approx(2.0, abs=0.1)
    assert out["cv"][0] == pytest.approx(0.8 / math.sqrt(2.0), rel=1e-3)


def test_animation_writes_statistics_npz_and_netcdf(tmp_path):
    """A four-frame render: run.json has each frame's statistics (total irradiance, PAR, the 510 nm
    band) and the probes' time statistics; the .npz and .nc files read back with their coordinates
    and units, and PAR in them equals the statistics' mean."""
    import xarray as xr

    from warpcaustics.cli import main

    out = tmp_path / "anim"
    code = main(["render", str(CONFIGS / "ocean.toml"), "--out", str(out), "--frames", "4", "--fps", "10",
                 "--quiet",
                 "--set", "water.resolution=32", "--set", "caustics.map_resolution=32",
                 "--set", "stats.wavelength_nm=510", "--set", "stats.collector_mm=3000",
                 "--set", "output.npz=true", "--set", "output.netcdf=true"])
    assert code == 0
    run = json.loads((out / "run.json").read_text())
    first = run["frames"][0]["statistics"]
    assert {"irradiance_w_m2", "par_umol_m2_s", "band_503.125nm_w_m2_nm"} <= set(first)
    assert 0.0 < first["irradiance_w_m2"]["cv"] < 2.0
    series = run["time_statistics"]
    assert series["dt_s"] == pytest.approx(0.1) and len(series["cv"]) == 1
    npz = np.load(out / "frame_0002.npz")
    assert npz["floor_irradiance"].shape == (16, 32, 32)
    np.testing.assert_allclose(npz["x_m"][[0, -1]], [-7.75, 7.75])
    ds = xr.open_dataset(out / "frame_0002.nc", decode_times=False)  # seconds, as written
    assert ds["floor_irradiance"].dims == ("time", "wavelength", "y", "x")
    assert ds["floor_irradiance"].attrs["units"] == "W m-2 nm-1"
    assert ds["par"].attrs["units"] == "umol m-2 s-1"
    np.testing.assert_allclose(ds["wavelength"].values, npz["wavelength_nm"])
    assert float(ds["time"].values[0]) == pytest.approx(0.2)
    # run.json's PAR statistics are those of the written PAR map after the 3 m collector (6 texels)
    par = run["frames"][2]["statistics"]["par_umol_m2_s"]
    averaged = stats.collector_average(ds["par"].values[0], 0.5, 3.0, periodic=True)
    expected = stats.field_statistics(averaged, 1.5)
    assert par["mean"] == pytest.approx(expected["mean"], rel=1e-5)
    assert par["cv"] == pytest.approx(expected["cv"], rel=1e-4)
    assert par["cv"] < stats.field_statistics(ds["par"].values[0], 1.5)["cv"]
    ds.close()


def test_stats_config_errors(monkeypatch):
    """A probe off the map, and NetCDF without xarray, fail at load with one line naming the key."""
    with pytest.raises(ConfigError, match=r"stats.probes\[0\]"):
        wc.load_scene(CONFIGS / "ocean.toml", {"stats.probes": [{"x_m": 20.0, "y_m": 0.0}]})
    monkeypatch.setitem(__import__("sys").modules, "xarray", None)
    with pytest.raises(ConfigError, match="output.netcdf"):
        wc.load_scene(CONFIGS / "ocean.toml", {"output.netcdf": True})


def test_collector_wider_than_the_map_folds_onto_a_periodic_map():
    """A collector wider than a periodic map wraps around it (each texel's disc overlaps itself):
    the mean is kept and the field flattens; on an open map the cut disc is renormalised."""
    rng = np.random.default_rng(3)
    field = rng.random((40, 40))
    wide = stats.collector_average(field, 0.01, 0.395, periodic=True)
    assert wide.mean() == pytest.approx(field.mean(), rel=1e-12)
    assert wide.std() < 0.1 * field.std()
    np.testing.assert_allclose(stats.collector_average(np.ones((40, 40)), 0.01, 0.395, periodic=False), 1.0)


def test_periodogram_keeps_the_power_for_odd_and_even_lengths():
    """The one-sided spectrum integrates to the variance of E/Ē − 1 (Parseval, up to the Hann
    window's leakage) for records of even and odd length."""
    for t in (200, 201):
        time = np.arange(t) / 20.0
        e = 1.0 + 0.5 * np.sin(2 * np.pi * 7.3 * time + 0.4)
        out = stats.series_statistics(e[:, None], 0.05, 1.5)
        df = out["frequencies_hz"][1] - out["frequencies_hz"][0]
        power = np.sum(out["power_spectrum"][0]) * df
        assert power == pytest.approx(np.var(e / e.mean() - 1.0), rel=0.05)


def test_sky_and_direct_parts_have_their_own_statistics():
    """With a sky, the statistics also hold the direct sun's part and the sky's alone: their means
    add up to the total's (1e-9) and the sky's is the mean of RenderResult.sky_floor_irradiance."""
    import warpcaustics as wc
    from warpcaustics.batch.stats import band_integrated, frame_statistics

    scene = wc.load_scene(CONFIGS / "ocean.toml", {"water.resolution": 32, "caustics.map_resolution": 32,
                                                 "sky.model": "uniform", "sky.diffuse_fraction": 0.3,
                                                 "sky.directions": 4, "stats.collector_mm": 300.0})
    r = wc.render(scene, device="cpu")
    s = frame_statistics(r, scene.config.stats)
    total, direct, sky = (s[k]["mean"] for k in ("irradiance_w_m2", "direct_irradiance_w_m2",
                                                  "sky_irradiance_w_m2"))
    assert direct + sky == pytest.approx(total, rel=1e-9)
    assert sky == pytest.approx(band_integrated(r.sky_floor_irradiance, r.bin_widths_nm).mean(), rel=1e-9)
    assert 0.0 < s["direct_irradiance_w_m2"]["cv"] and s["sky_irradiance_w_m2"]["cv"] > 0.0


def test_per_band_statistics_are_each_bands_own():
    """stats.per_band: each band's statistics after the collector; the band holding
    stats.wavelength_nm equals the one reported for it, and each band's mean and CV are numpy's
    over that band's map (collector 0: the texels themselves)."""
    import warpcaustics as wc
    from warpcaustics.batch.stats import frame_statistics

    scene = wc.load_scene(CONFIGS / "ocean.toml", {"water.resolution": 32, "caustics.map_resolution": 32,
                                                 "optics.wavelengths": [443.0, 532.0, 670.0],
                                                 "stats.per_band": True, "stats.wavelength_nm": 532.0})
    r = wc.render(scene, device="cpu")
    s = frame_statistics(r, scene.config.stats)
    assert list(s["bands"]) == ["443nm_w_m2_nm", "532nm_w_m2_nm", "670nm_w_m2_nm"]
    assert s["bands"]["532nm_w_m2_nm"] == s["band_532nm_w_m2_nm"]
    for k, key in enumerate(s["bands"]):
        band = np.asarray(r.floor_irradiance[k], np.float64)
        assert s["bands"][key]["mean"] == pytest.approx(band.mean(), rel=1e-9)
        assert s["bands"][key]["cv"] == pytest.approx(band.std() / band.mean(), rel=1e-9)
    assert "bands" not in frame_statistics(r, wc.load_scene(CONFIGS / "ocean.toml").config.stats)


@pytest.mark.parametrize("integration_s", [0.05, 1.0 / 6.0, 0.37, 1.0])
def test_integration_of_a_sinusoid_is_its_sinc(integration_s):
    """E(t) = 1 + A sin(2πft) (f = 2 Hz) sampled at 200 Hz, averaged over the last T before each
    sample: the exact running mean of the sinusoid is 1 + A sinc(fT) sin(2πf(t − T/2)) (sinc(x) =
    sin(πx)/(πx)), so the integrated CV is A |sinc(fT)|/√2 — within 3e-4 of every sample (the
    piecewise-linear integral's error, A (2πf dt)²/12 = 2.6e-4 at 100 samples per period), and the
    CV within 1e-3; T = 0 keeps the series."""
    dt, f, a = 1.0 / 200.0, 2.0, 0.8
    first = int(math.ceil(integration_s / dt - 1e-9))
    t = np.arange(2000 + first) * dt  # the integrated series: 2000 samples, 20 whole periods
    e = 1.0 + a * np.sin(2 * np.pi * f * t)
    out = stats.integrate_series(e[:, None], dt, integration_s)[:, 0]
    assert len(out) == 2000
    exact = 1.0 + a * np.sinc(f * integration_s) * np.sin(2 * np.pi * f * (t[first:] - integration_s / 2))
    np.testing.assert_allclose(out, exact, atol=3e-4)
    cv = stats.series_statistics(out[:, None], dt, 1.5)["cv"][0]
    assert cv == pytest.approx(a * abs(np.sinc(f * integration_s)) / math.sqrt(2.0), rel=1e-3, abs=1e-4)
    np.testing.assert_array_equal(stats.integrate_series(e[:, None], dt, 0.0)[:, 0], e)


def test_integration_longer_than_the_animation_is_refused():
    with pytest.raises(ValueError, match="stats.integration_s"):
        stats.integrate_series(np.ones((5, 1)), 0.1, 1.0)


def test_a_point_time_series_sees_the_spatial_statistics_of_a_frozen_field():
    """A stationary field carried past the probe (E(x − vt), a random periodic field of 256 texels,
    one texel per frame): over one period the probe's time series holds every texel once, so its CV
    is the field's spatial CV exactly (1e-12); over 10 frames, shorter than the field's correlation
    length (~20 texels), it sees a fraction of the contrast (the two agree only for series long
    against the field's correlation time)."""
    rng = np.random.default_rng(3)
    low_pass = np.exp(-((np.fft.fftfreq(256) * 20) ** 2))
    smooth = np.real(np.fft.ifft(np.fft.fft(rng.normal(size=256)) * low_pass))
    field = np.exp(0.5 * smooth / smooth.std())
    series = np.array([np.roll(field, k)[0] for k in range(256)])
    spatial = field.std() / field.mean()
    assert stats.series_statistics(series[:, None], 0.1, 1.5)["cv"][0] == pytest.approx(spatial, rel=1e-12)
    short = stats.series_statistics(series[:10, None], 0.1, 1.5)["cv"][0]
    assert short < 0.5 * spatial


def test_an_animation_reports_its_probes_integrated(tmp_path):
    """stats.integration_s over a six-frame animation at 10 fps: run.json's time statistics hold
    the integrated series' statistics (four samples with 0.15 s behind them), whose CV is lower
    than the instantaneous samples' — the running mean of the same series (checked against
    integrate_series on the frames' probe values)."""
    from warpcaustics.cli import main

    out = tmp_path / "anim"
    code = main(["render", str(CONFIGS / "ocean.toml"), "--out", str(out), "--frames", "6", "--fps", "10",
                 "--quiet", "--set", "water.resolution=32", "--set", "caustics.map_resolution=32",
                 "--set", "stats.integration_s=0.15"])
    assert code == 0
    run = json.loads((out / "run.json").read_text())
    series = np.array([f["statistics"]["probe_irradiance_w_m2"] for f in run["frames"]])
    integrated = run["time_statistics"]["integrated"]
    assert integrated["integration_s"] == 0.15 and integrated["samples"] == 4
    expected = stats.integrate_series(series, 0.1, 0.15)
    assert integrated["mean"] == pytest.approx(expected.mean(axis=0).tolist(), rel=1e-9)
    assert integrated["cv"][0] < run["time_statistics"]["cv"][0]


def test_window_means_share_the_texels_a_window_edge_crosses():
    """``window_means`` of a coarse map whose texels the windows do not divide (20 windows on 32
    texels: 1.6 a window) equals the means of the same map upsampled 5× (each texel a constant
    block, so 8 fine texels a window) taken window by window (1e-12); with whole texels a window it
    is the plain block mean."""
    rng = np.random.default_rng(3)
    coarse = rng.uniform(0.5, 2.0, (32, 32))
    fine = np.kron(coarse, np.ones((5, 5)))
    exact = fine.reshape(20, 8, 20, 8).mean(axis=(1, 3))
    got = stats.window_means(coarse, 20)
    assert got["count"] == 400
    assert got["mean"] == pytest.approx(coarse.mean(), rel=1e-12)
    assert got["cv"] == pytest.approx(exact.std() / exact.mean(), rel=1e-12)
    blocks = coarse.reshape(8, 4, 8, 4).mean(axis=(1, 3))
    assert stats.window_means(coarse, 8)["cv"] == pytest.approx(blocks.std() / blocks.mean(), rel=1e-12)


def test_every_band_has_its_patch_windows():
    """A 0.4 m window of an 8 m periodic sea under the small-angle transfer (configs/field/darecki2011.toml,
    three bands, stats.per_band): each band's ``patch_windows`` are its own coarse map's 20 × 20
    window means (``RenderResult.coarse_floor_irradiance[k]``, 1.6 coarse texels a window, compared on
    the map upsampled to whole texels a window, 1e-9), and the bands' means weighted by their widths
    add up to the band-integrated irradiance's (1e-9)."""
    from warpcaustics.batch.stats import frame_statistics

    scene = wc.load_scene(CONFIGS / "field" / "darecki2011.toml", {
        "water.resolution": 64, "water.extent_m": 8.0, "caustics.map_resolution": 40,
        "sun.disk_samples": 2, "sky.directions": 2, "optics.beam_spread": "wells"})
    r = wc.render(scene, device="cpu")
    s = frame_statistics(r, scene.config.stats)
    coarse = np.asarray(r.coarse_floor_irradiance, np.float64)
    assert coarse.shape[-1] == 32
    total = 0.0
    for k, (key, band) in enumerate(s["bands"].items()):
        fine = np.kron(coarse[k], np.ones((5, 5))).reshape(20, 8, 20, 8).mean(axis=(1, 3))
        windows = band["patch_windows"]
        assert windows["count"] == 400, key
        assert windows["mean"] == pytest.approx(fine.mean(), rel=1e-9), key
        assert windows["cv"] == pytest.approx(fine.std() / fine.mean(), rel=1e-9), key
        total += windows["mean"] * r.bin_widths_nm[k]
    assert total == pytest.approx(s["irradiance_w_m2"]["patch_windows"]["mean"], rel=1e-9)


def test_every_band_has_its_sky_and_direct_parts():
    """stats.per_band under a sky: each band's sky part (``bands_sky``) and direct sun's
    (``bands_direct``) have statistics of their own, whose means add up to the band's (1e-9), the
    sky's being the mean of that band of RenderResult.sky_floor_irradiance after the collector
    (numpy, 1e-9); and so do their ``patch_windows``, the sky's from the coarse sky map."""
    from warpcaustics.batch.stats import collector_average, frame_statistics

    scene = wc.load_scene(CONFIGS / "field" / "darecki2011.toml", {
        "water.resolution": 64, "water.extent_m": 8.0, "caustics.map_resolution": 40,
        "sun.disk_samples": 2, "sky.directions": 2, "optics.beam_spread": "wells"})
    r = wc.render(scene, device="cpu")
    s = frame_statistics(r, scene.config.stats)
    assert list(s["bands_sky"]) == list(s["bands_direct"]) == list(s["bands"])
    texel = r.map_extent_m / r.floor_irradiance.shape[-1]
    for k, key in enumerate(s["bands"]):
        band, sky, direct = s["bands"][key], s["bands_sky"][key], s["bands_direct"][key]
        assert sky["mean"] + direct["mean"] == pytest.approx(band["mean"], rel=1e-9), key
        own = collector_average(np.asarray(r.sky_floor_irradiance[k], np.float64), texel,
                                scene.config.stats.collector_mm * 1e-3, periodic=r.map_periodic)
        assert sky["mean"] == pytest.approx(own.mean(), rel=1e-9) and sky["cv"] == pytest.approx(
            own.std() / own.mean(), rel=1e-6), key
        assert 0.0 < sky["cv"] and 0.0 < direct["cv"], key
        windows = [part["patch_windows"]["mean"] for part in (sky, direct, band)]
        assert windows[0] + windows[1] == pytest.approx(windows[2], rel=1e-9), key
        assert windows[0] == pytest.approx(float(np.mean(r.coarse_sky_floor_irradiance[k], dtype=np.float64)),
                                           rel=1e-6), key


@pytest.mark.parametrize("integration_s", [1e-300, 1e-12, 1e-6])
def test_a_window_a_sliver_of_a_spacing_is_the_instantaneous_sample(integration_s):
    """Over a window far shorter than the samples' spacing the running mean is the sample itself (to
    the window's share of the slope). It had been a difference of two running integrals divided by
    the window, which cancelled: -4e301 and an infinite CV for a window of 1e-300 s."""
    e = 1.0 + np.random.default_rng(3).random((40, 2))
    out = stats.integrate_series(e, 0.2, integration_s)
    assert np.all(np.isfinite(out))
    np.testing.assert_allclose(out, e[len(e) - len(out):], rtol=0, atol=10 * integration_s / 0.2 + 1e-15)
