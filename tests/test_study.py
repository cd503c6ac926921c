"""The water-type study: its tables, and its effective attenuation against Beer–Lambert."""

import csv

import numpy as np
import pytest

from warpcaustics.cli import main

from helpers import CONFIGS


def test_study_on_still_water_recovers_the_beam_attenuation(tmp_path, capsys):
    """On still water the study's effective attenuation is exactly c(λ)/cosθ_t (Beer–Lambert along
    the refracted beam, 1e-4); study.csv has a row per combination with contrast 0 and a colour, and
    kd.csv sets Jerlov's Kd beside it for Jerlov types."""
    pytest.importorskip("matplotlib")
    scene = tmp_path / "flat.toml"
    scene.write_text("[water]\nmodel = 'flat'\nresolution = 8\nextent_m = 2.0\n"
                     "[caustics]\nmap_resolution = 8\n"
                     "[optics]\nwavelengths = { min_nm = 400.0, max_nm = 700.0, bins = 6 }\n")
    study = tmp_path / "study.toml"
    study.write_text("scene = 'flat.toml'\nwater_types = ['jerlov_II', 'clear_ocean']\n"
                     "depths_m = [1.0, 3.0, 9.0]\nsun_elevations_deg = [35.0, 70.0]\n")
    out = tmp_path / "out"
    assert main(["study", str(study), "--out", str(out), "--device", "cpu"]) == 0
    rows = list(csv.DictReader((out / "study.csv").open()))
    assert len(rows) == 2 * 3 * 2
    assert all(float(r["caustic_contrast"]) < 1e-5 and r["floor_colour_srgb"].startswith("#") for r in rows)
    kd = list(csv.DictReader((out / "kd.csv").open()))
    cos_t = np.sqrt(1 - (np.cos(np.radians(70.0)) / 1.333) ** 2)  # the highest sun is used
    for r in kd:
        assert float(r["K_eff_per_m"]) == pytest.approx(float(r["c_per_m"]) / cos_t, rel=1e-4)
        assert np.isfinite(float(r["Kd_jerlov1976_per_m"])) == (r["water_type"] == "jerlov_II")
    assert (out / "irradiance_vs_depth.png").read_bytes()[:4] == b"\x89PNG"


def test_bad_study_file_is_one_line(tmp_path, capsys):
    """A study naming an unknown water type stops with one line and writes nothing."""
    study = tmp_path / "study.toml"
    study.write_text("scene = 'x.toml'\nwater_types = ['muddy']\ndepths_m = [1.0, 2.0]\n"
                     "sun_elevations_deg = [60.0]\n")
    assert main(["study", str(study), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "'muddy' is not a water type" in err[0]
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(("body", "needle"), [
    ("water_types = []\ndepths_m = [1.0, 2.0]\nsun_elevations_deg = [60.0]\n", "non-empty list of names"),
    ("water_types = 'jerlov_I'\ndepths_m = [1.0, 2.0]\nsun_elevations_deg = [60.0]\n", "list of names"),
    ("water_types = ['none']\ndepths_m = [1, 'x']\nsun_elevations_deg = [60.0]\n", "list of numbers"),
    ("water_types = ['none']\ndepths_m = [1.0, 2.0]\nsun_elevations_deg = [true]\n", "list of numbers"),
    ("water_types = ['none']\ndepths_m = [1.0, 2.0]\nsun_elevations_deg = [60.0]\noverrides = 3\n", "table"),
])
def test_study_input_errors_are_one_line(tmp_path, capsys, body, needle):
    """Malformed study files stop before any render, with one line naming the key."""
    study = tmp_path / "study.toml"
    study.write_text("scene = 'x.toml'\n" + body)
    assert main(["study", str(study), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and needle in err[0], err
    assert not (tmp_path / "out").exists()


def test_nested_overrides_set_keys_not_sections(tmp_path):
    """[overrides.water] resolution = 32 changes one key and keeps the scene's other water keys."""
    import warpcaustics as wc
    from warpcaustics.batch.study import load_study

    study = tmp_path / "study.toml"
    study.write_text(f"scene = '{CONFIGS / 'ocean.toml'}'\nwater_types = ['none']\n"
                     "depths_m = [1.0, 2.0]\nsun_elevations_deg = [60.0]\n"
                     "[overrides.water]\nresolution = 32\n")
    loaded = load_study(study)
    assert loaded.overrides == {"water.resolution": 32}
    scene = wc.load_scene(loaded.scene, loaded.overrides)
    assert scene.config.water.resolution == 32 and scene.config.water.seed == 7  # the rest is kept
