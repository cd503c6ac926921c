"""The per-band Gernez & Antoine (2009) comparison (Fig. 10a): its record, its sky's shares per band,
and its bands rendered together against each band alone."""

import csv
import json
import math

import numpy as np
import pytest

from warpcaustics.cli import main
from warpcaustics.errors import ConfigError

from helpers import fresnel_t_angles

jerlov = pytest.importorskip("jerlov")
field = pytest.importorskip("warpcaustics.batch.field")
bands = pytest.importorskip("warpcaustics.batch.field.gernez2009_bands")


def _scene(tmp_path, water="model = 'flat'\nresolution = 8\nextent_m = 4.0\n"):
    scene = tmp_path / "scene.toml"
    scene.write_text(f"[water]\n{water}[floor]\ndepth_m = 3.2\n"
                     "[sky]\nmodel = 'uniform'\ndiffuse_fraction = 0.2\n"
                     "[optics]\nwater_type = 'jerlov_IB'\nwavelengths = [510.0]\n"
                     "[caustics]\nmap_resolution = 16\nmap_extent_m = 1.0\n[stats]\ncollector_mm = 8.0\n")
    return scene


def test_the_record_is_fig_10a_and_its_510_nm_line_is_fig_8a():
    """Six bands, 443-683 nm, at Fig. 8a's zeniths; the 510 nm line is Fig. 8a's medians (the
    package reads both figures apart, so they agree to a pixel or two of each)."""
    rec = bands.record()
    assert rec.wavelengths_nm.tolist() == [443.0, 490.0, 510.0, 560.0, 670.0, 683.0]
    by_zenith = jerlov.gernez2009_cv_by_sun_zenith()
    assert rec.x.tolist() == by_zenith.sun_zenith_deg.tolist()
    assert rec.cv[:, 2] == pytest.approx(by_zenith.cv, abs=3 * by_zenith.cv_reading)
    # the red keeps the most contrast at every zenith, the blue the least
    assert np.all(rec.cv[:, 4] > rec.cv[:, 2]) and np.all(rec.cv[:, 0] < rec.cv[:, 2])


def test_command_on_still_water_measures_no_fluctuation_per_band(tmp_path, capsys):
    """End to end (--quick: the first and last zenith): under still water every band's CV is 0,
    beside the record's values in its order; each band's sky share follows the sky's spectrum, bluer
    than the sun's, and over the six bands they hold the paper's diffuse share; at the sensor each
    band's sky share is that of a float64 quadrature of the uniform sky through the flat surface
    (Fresnel, the slant paths' attenuation; 2e-3); a rerun resumes."""
    pytest.importorskip("matplotlib")
    from warpcaustics.optics import spectra
    from warpcaustics.scene import load_scene

    out = tmp_path / "o"
    # --quick, but with 64 sky directions instead of its 2 (a quadrature of the sky: below)
    args = ["field", "gernez2009_bands", str(_scene(tmp_path)), "--out", str(out), "--quick", "--frames", "1",
            "--set", "sky.directions=64", "--device", "cpu", "--quiet"]
    assert main(args) == 0
    rows = list(csv.DictReader((out / "gernez2009_bands.csv").open()))
    rec = bands.record()
    assert [(float(r["sun_zenith_deg"]), float(r["wavelength_nm"])) for r in rows] == [
        (z, float(w)) for z in (20.0, 85.0) for w in rec.wavelengths_nm]
    assert all(float(r["model_cv"]) < 1e-5 for r in rows)
    assert [float(r["measured_cv"]) for r in rows[:6]] == pytest.approx(rec.cv[0].tolist(), abs=1e-4)
    assert float(rows[4]["measured_cv_over_510"]) == pytest.approx(rec.cv[0, 4] / rec.cv[0, 2], abs=1e-3)
    for z, rs in ((20.0, rows[:6]), (85.0, rows[6:])):
        share = np.array([float(r["sky_share"]) for r in rs])
        assert np.all(np.diff(share) <= 0.0)  # blue sky: each band's share falls towards the red
        # over the six bands the sky's light is the paper's share of the global light
        scene = load_scene(_scene(tmp_path), {**bands.band_overrides(rec), "sun.elevation_deg": 90.0 - z})
        bins = spectra.bins_for(scene.config.optics)
        beam = spectra.sun_irradiance(bins, scene.config.sun, scene.base_dir) * np.cos(np.radians(z))
        sky = beam * share / (1.0 - share)
        f = field.diffuse_fraction(z)
        assert float(np.sum(sky * bins.widths_nm) / np.sum((sky + beam) * bins.widths_nm)) == pytest.approx(
            f, abs=2e-4)
        # at the sensor: the sky's share after Fresnel and the slant paths, against a float64 quadrature
        optics = spectra.water_optics(scene.config.optics, bins)
        c = optics.absorption_per_m + optics.scattering_per_m
        ior = spectra.refractive_index(scene.config.optics, bins)
        below = [float(r["model_sky_share_at_depth"]) for r in rs]
        assert below == pytest.approx(_sky_share_at_depth(share, z, c, ior, 3.2).tolist(), abs=2e-3)
        # in the red the longer slant path loses more: the sky's at a high sun, the sun's at a low one
        assert (below[-1] < share[-1]) if z == 20.0 else (below[-1] > share[-1])
    assert (out / "gernez2009_bands.png").read_bytes()[:4] == b"\x89PNG"
    capsys.readouterr()
    assert main(args[:-1]) == 0
    assert "done 0, skipped 2" in capsys.readouterr().out


def _sky_share_at_depth(share, zenith_deg, c, ior, depth_m):
    """Under still water at ``depth_m``, per band: the uniform sky's share of the downwelling light,
    its horizontal irradiance above ``share``/(1 − ``share``) of the sun's beam's, the sky's below
    (1/π)∫ T(θ) cosθ e^{−c D/cosθ_w} dΩ of it, the sun's T(θ_s) e^{−c D/cosθ_ws}."""
    from scipy.integrate import quad

    out = []
    for s, ck, n in zip(share, c, ior):
        def slant(cos_i, ck=ck, n=n):
            cos_w = math.sqrt(1.0 - (1.0 - cos_i * cos_i) / (n * n))
            return float(fresnel_t_angles(math.acos(cos_i), 1.0, n)) * math.exp(-ck * depth_m / cos_w)

        sky = s / (1.0 - s) * 2.0 * quad(lambda u: slant(u) * u, 0.0, 1.0, epsabs=0, epsrel=1e-10)[0]
        sun = slant(math.cos(math.radians(zenith_deg)))
        out.append(sky / (sky + sun))
    return np.array(out)


def test_bands_rendered_together_are_each_band_rendered_alone(tmp_path):
    """On a rippled sea, a band's CV in the six-band render is that of a plain render of that band
    alone (``warpcaustics render``, no field code) under the band's own sky share: the bands do not
    mix, the share each gets is the one the CSV states, and each band's sky and direct parts are
    the band's own (the sky as a uniform background). (Single scattering: the map is the window
    alone, no coarse map of the patch beside it.)"""
    pytest.importorskip("matplotlib")
    water = "model = 'fft'\nresolution = 64\nextent_m = 4.0\nspectrum = 'jonswap'\n"
    scene = _scene(tmp_path, water)
    out = tmp_path / "o"
    field.run_gernez2009_bands(scene, out, zeniths=(20.0,), frames=1, quick=True, quiet=True, device="cpu",
                               long_waves_m=0.0)
    rows = list(csv.DictReader((out / "gernez2009_bands.csv").open()))
    assert len({float(r["model_cv"]) for r in rows}) == 6 and all(float(r["model_cv"]) > 0.01 for r in rows)
    for r in (rows[0], rows[4]):
        alone = tmp_path / f"alone_{r['wavelength_nm']}"
        sets = {**field.QUICK_OVERRIDES, "sun.elevation_deg": 70.0, "sky.diffuse_fraction": r["sky_share"],
                "optics.wavelengths": f"[{r['wavelength_nm']}]"}
        args = ["render", str(scene), "--out", str(alone), "--device", "cpu"]
        for key, value in sets.items():
            args += ["--set", f"{key}={value}"]
        assert main(args) == 0
        stats = json.loads((alone / "run.json").read_text())["frames"][0]["statistics"]
        total, direct, sky = (stats[f] for f in ("irradiance_w_m2", "direct_irradiance_w_m2",
                                                 "sky_irradiance_w_m2"))
        assert float(r["model_cv"]) == float(r["model_cv_window"]) == pytest.approx(total["cv"], rel=2e-3)
        # the sky as a uniform background: the direct part's variance over the whole mean
        uniform = field.pooled_statistics([(direct["mean"], direct["cv"])], [sky["mean"]])[1]
        assert float(r["model_cv_uniform_sky"]) == pytest.approx(uniform, rel=2e-3)


def test_bands_bad_input_is_one_line(tmp_path, capsys):
    """What the comparison sets at each point cannot be --set; a zenith the record lacks is named
    with those it holds; another data set's point flag is refused; nothing is written."""
    scene = _scene(tmp_path)
    for key, value in (("optics.wavelengths", [443.0]), ("sky.diffuse_fraction", 0.3),
                       ("stats.per_band", False), ("sun.elevation_deg", 30.0),
                       ("optics.wavelengths.bins", 4)):  # a key inside one had read "is a value, not a table"
        with pytest.raises(ConfigError, match=f"--set {key}: the comparison sets it"):
            field.run_gernez2009_bands(scene, tmp_path / "o", overrides={key: value}, quick=True)
    with pytest.raises(ConfigError, match=r"--zeniths: 21 is not a measured sun zenith \[deg\]; the record "
                                          r"holds 20, 25"):
        field.run_gernez2009_bands(scene, tmp_path / "o", zeniths=(21.0,), quick=True)
    with pytest.raises(ConfigError, match="is stateful"):
        field.run_gernez2009_bands(scene, tmp_path / "o", overrides={"water.model": "pool"}, quick=True)
    args = ["field", "gernez2009_bands", str(scene), "--out", str(tmp_path / "o"), "--sqrt-winds", "2"]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert "--sqrt-winds is not a flag of gernez2009_bands (its point flags: --zeniths)" in err
    assert not (tmp_path / "o").exists()
