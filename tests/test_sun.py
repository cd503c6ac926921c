"""The sun's spectrum: ASTM G173 by default, D65, a blackbody or a CSV, scaled to an irradiance."""

import numpy as np
import pytest

import warpcaustics as wc
from warpcaustics.cli import main
from warpcaustics.config import config_from_dict
from warpcaustics.optics import spectra

BINS = spectra.SpectralBins.uniform(400.0, 700.0, 30)


def _sun(**kw):
    return config_from_dict({}, {f"sun.{k}": v for k, v in kw.items()}).sun


def test_astm_g173_is_the_shipped_table_and_sets_the_default_scale():
    """The default sun is ASTM G173 direct + circumsolar averaged over each bin; its integral over
    400–700 nm is the scale every other spectrum gets unless sun.irradiance_w_m2 is set."""
    wl, e = spectra.sun_table()
    e_sun = spectra.sun_irradiance(BINS, _sun())
    inside = (wl >= 400) & (wl <= 700)
    # the table is 0.5–1 nm apart here: its trapezoid integral and our bin averages agree to 1e-3
    assert np.sum(e_sun * BINS.widths_nm) == pytest.approx(np.trapezoid(e[inside], wl[inside]), rel=1e-3)
    for spectrum in ("d65", "blackbody"):
        other = spectra.sun_irradiance(BINS, _sun(spectrum=spectrum))
        assert np.sum(other * BINS.widths_nm) == pytest.approx(np.sum(e_sun * BINS.widths_nm), rel=1e-12)


def test_blackbody_shape_is_plancks_law():
    """The blackbody sun's bins follow Planck's law, B ∝ λ⁻⁵ / (exp(hc/λkT) − 1), computed here in
    float64 from the physical constants (CODATA 2018, exact SI values)."""
    h, c, k = 6.62607015e-34, 299792458.0, 1.380649e-23
    e_sun = spectra.sun_irradiance(BINS, _sun(spectrum="blackbody", temperature_k=4000.0))
    lam = BINS.centres_nm * 1e-9
    planck = lam**-5 / np.expm1(h * c / (lam * k * 4000.0))
    ratio = e_sun / planck
    np.testing.assert_allclose(ratio / ratio.mean(), 1.0, rtol=1e-4)  # bin average vs centre value


def test_irradiance_scale_and_csv_spectrum(tmp_path):
    """A CSV spectrum keeps its shape and is scaled so that Σ E Δλ = sun.irradiance_w_m2."""
    path = tmp_path / "sun.csv"
    path.write_text("wavelength_nm,irradiance\n380,1.0\n720,3.0\n")
    e_sun = spectra.sun_irradiance(BINS, _sun(spectrum="file", file=str(path), irradiance_w_m2=500.0))
    assert np.sum(e_sun * BINS.widths_nm) == pytest.approx(500.0, rel=1e-12)
    line = 1.0 + 2.0 * (BINS.centres_nm - 380.0) / 340.0  # a straight line averages to its centre value
    np.testing.assert_allclose(e_sun / e_sun.mean(), line / line.mean(), rtol=1e-9)


def test_bad_sun_file_is_one_line(capsys, tmp_path):
    """A sun CSV that is missing or malformed is a one-line error naming sun.file; nothing is written."""
    (tmp_path / "bad.csv").write_text("wavelength_nm,irradiance\n500,1\n400,2\n")
    for name, needle in (("missing.csv", "does not exist"), ("bad.csv", "strictly")):
        cfg = tmp_path / "scene.toml"
        cfg.write_text(f"[sun]\nspectrum = 'file'\nfile = '{name}'\n")
        assert main(["render", str(cfg), "--out", str(tmp_path / "out"), "--device", "cpu"]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and "sun.file" in err[0] and needle in err[0]
        assert not (tmp_path / "out").exists()


def test_floor_scales_with_the_sun():
    """Doubling sun.irradiance_w_m2 doubles the floor irradiance (the pipeline is linear in E_sun)."""
    base = {"water.resolution": 32, "caustics.map_resolution": 16, "optics.wavelengths.bins": 4}
    one = wc.render(wc.load_scene(None, {**base, "sun.irradiance_w_m2": 300.0}), device="cpu")
    two = wc.render(wc.load_scene(None, {**base, "sun.irradiance_w_m2": 600.0}), device="cpu")
    np.testing.assert_allclose(two.floor_irradiance, 2.0 * one.floor_irradiance, rtol=1e-6)


def test_d65_sun_has_the_d65_shape():
    """The d65 sun is colour-science's CIE D65 averaged over each bin, up to the overall scale."""
    d65 = spectra.colour_science().SDS_ILLUMINANTS["D65"]
    ours = spectra.sun_irradiance(BINS, _sun(spectrum="d65"))
    reference = BINS.average(d65.wavelengths, d65.values, "D65")
    np.testing.assert_allclose(ours / reference, (ours / reference).mean(), rtol=1e-12)
