"""Darecki et al. (2011)'s Fig. 15 as a field data set (``warpcaustics field darecki2011_radiance``):
its scene, its points, its command end to end and its bad input."""

import csv
import math
from pathlib import Path

import numpy as np
import pytest

from warpcaustics.cli import main
from warpcaustics.errors import ConfigError

jerlov = pytest.importorskip("jerlov")
field = pytest.importorskip("warpcaustics.batch.field")

ROOT = Path(__file__).resolve().parents[1]
RADIANCE = ROOT / "configs/field/darecki2011_radiance.toml"


def test_config_and_panels_hold_the_records_conditions():
    """configs/field/darecki2011_radiance.toml has the record's band and field of view; each panel's
    overrides give its depth, sun and wind, and a water whose c(555) is the panel's to 0.5 %."""
    import warpcaustics as wc
    from warpcaustics.batch.field import darecki2011, darecki2011_radiance

    cfg = wc.load_scene(RADIANCE).config
    for panel in jerlov.DARECKI2011_PANELS:
        rec = darecki2011_radiance.record(panel)
        darecki2011_radiance.check_scene(cfg, rec)
        assert cfg.optics.wavelengths.list_nm == (rec.wavelength_nm,)
        assert cfg.floor.view_fov_deg == rec.field_of_view_deg
        over = darecki2011_radiance.panel_conditions(cfg, rec)
        at = wc.load_scene(RADIANCE, over).config
        assert at.floor.depth_m == rec.depth_m and at.water.wind_speed_m_s == rec.wind_m_s
        assert 90.0 - at.sun.elevation_deg == pytest.approx(rec.sun_zenith_deg)
        assert darecki2011.beam_attenuation(at, 555.0) == pytest.approx(rec.beam_attenuation_555, rel=5e-3)


def test_the_sensor_turns_to_each_signed_zenith_in_the_suns_plane():
    """Positive zeniths look towards the sun (azimuth 0, the scene's sun's), negative away from it;
    the axis is the one the renderer builds from them."""
    from warpcaustics.batch.field.darecki2011_radiance import view
    from warpcaustics.caustics.view import view_axis

    for zenith in (-30.0, 0.0, 25.0, 40.0):
        v = view(zenith)
        axis = view_axis(v["floor.view_zenith_deg"], v["floor.view_azimuth_deg"])
        t = math.radians(zenith)
        assert axis == pytest.approx([math.sin(t), 0.0, math.cos(t)], abs=1e-12)


def test_command_on_still_water_sees_the_sun_only_in_its_refracted_direction(tmp_path):
    """End to end (--quick, panel a) under still water: looking at 25°, whose 4.5° cone holds the
    refracted sun (Snell's law: 23.97°), every texel sees the sun and the sky is a small share of the
    light; looking 30° away from it none sees the sun and the light is the sky's alone. The map is
    uniform either way (CV 0, with the scattered light too), beside the record's values; a plot is
    written."""
    pytest.importorskip("matplotlib")
    flat = tmp_path / "flat.toml"
    flat.write_text(RADIANCE.read_text().replace('model = "fft"', 'model = "flat"'))
    out = tmp_path / "o"
    assert main(["field", "darecki2011_radiance", str(flat), "--out", str(out), "--quick", "--frames", "1",
                 "--view-zeniths", "-30,25", "--panels", "a", "--device", "cpu", "--quiet"]) == 0
    rows = list(csv.DictReader((out / "darecki2011_radiance.csv").open()))
    rec = jerlov.darecki2011_radiance_cv("a")
    refracted = math.degrees(math.asin(math.sin(math.radians(rec.sun_zenith_deg)) / 1.336))
    assert abs(refracted - 25.0) < 0.5 * rec.field_of_view_deg
    assert [(r["panel"], float(r["zenith_deg"])) for r in rows] == [("a", -30.0), ("a", 25.0)]
    assert all(float(r["model_cv"]) < 1e-5 and float(r["model_cv_scattered_smooth"]) < 1e-5 for r in rows)
    away, towards = rows
    # the light scattered into the cone by more than 3°: a share of the sky's view, little beside the sun
    assert 0.01 < float(away["model_scattered_share"]) < 0.9
    assert 0.0 < float(towards["model_scattered_share"]) < 0.01
    assert float(away["model_sun_in_view"]) == 0.0 and float(away["model_sky_share"]) == 1.0
    assert float(towards["model_sun_in_view"]) == 1.0 and float(towards["model_sky_share"]) < 0.05
    assert [float(r["measured_cv"]) for r in rows] == pytest.approx(
        [rec.cv[list(rec.zenith_deg).index(z)] for z in (-30.0, 25.0)], abs=1e-4)
    assert (out / "darecki2011_radiance.png").stat().st_size > 0


def test_sun_in_view_is_the_share_of_texels_whose_sun_passes_a_tenth_of_the_skys_mean():
    """The statistic ``sun_in_view`` of a radiance sensor's frame: on a wavy sea, the share of texels
    whose direct part (the map less the traced sky's) exceeds a tenth of the sky's mean, counted
    here from the result's own maps."""
    import warpcaustics as wc
    from warpcaustics.batch.field.darecki2011_radiance import QUICK_OVERRIDES, view
    from warpcaustics.batch.stats import frame_statistics

    scene = wc.load_scene(RADIANCE, {**QUICK_OVERRIDES, "sun.elevation_deg": 57.0, **view(15.0)})
    r = wc.Renderer(scene, device="cpu").render(0.0)
    total, sky = (np.asarray(m[0], np.float64) for m in (r.floor_irradiance, r.sky_floor_irradiance))
    share = float(np.mean(total - sky > 0.1 * sky.mean()))
    assert 0.0 < share < 1.0  # the tilted sea sends the sun into some cones and not others
    stats = frame_statistics(r, scene.config.stats)
    assert stats["bands_direct"]["532nm_w_m2_nm"]["sun_in_view"] == pytest.approx(share, abs=1e-9)
    assert "sun_in_view" not in stats["bands"]["532nm_w_m2_nm"]


def test_bad_input_is_one_line(tmp_path, capsys):
    """Panels and zeniths the record lacks, a --set of a key the points set, and a scene that is not
    the record's sensor: each a one-line error naming the fix, before anything renders."""
    run = field.run_darecki2011_radiance
    with pytest.raises(ConfigError, match="--panels: 'd' is not a panel of Fig. 15; the record holds a, b"):
        run(RADIANCE, tmp_path / "o", panels=("d",), quick=True)
    with pytest.raises(ConfigError, match=r"--view-zeniths: 60 is not a measured zenith inside Snell's"):
        run(RADIANCE, tmp_path / "o", view_zeniths=(60.0,), quick=True)
    with pytest.raises(ConfigError, match="--set floor.view_zenith_deg: the comparison sets it at each"):
        run(RADIANCE, tmp_path / "o", overrides={"floor.view_zenith_deg": 10.0}, quick=True)
    for overrides, fix in (({"optics.wavelengths": [443.0]}, r"optics.wavelengths = \[532\]"),
                           ({"floor.view_fov_deg": 10.0}, "floor.view_fov_deg = 4.5"),
                           ({"stats.per_band": False}, "stats.per_band = true"),
                           ({"sun.azimuth_deg": 90.0}, "sun.azimuth_deg = 0"),
                           ({"sky.model": "none", "sky.diffuse_fraction": 0.0}, "sky.model = 'cie_clear'"),
                           ({"optics.scattering": "small_angle"}, 'optics.scattering = "single"'),
                           ({"caustics.map_extent_m": 1.0}, "set caustics.map_extent_m = 0")):
        with pytest.raises(ConfigError, match=fix):
            run(RADIANCE, tmp_path / "o", overrides=overrides, quick=True)
    assert main(["field", "darecki2011_radiance", str(RADIANCE), "--out", str(tmp_path / "o"),
                 "--winds", "3.9"]) == 2
    assert ("--winds is not a flag of darecki2011_radiance (its point flags: --panels, --view-zeniths)"
            in capsys.readouterr().err)
    assert main(["field", "darecki2011", str(ROOT / "configs/field/darecki2011.toml"), "--out",
                 str(tmp_path / "o"), "--panels", "a"]) == 2
    assert "--panels is not a flag of darecki2011" in capsys.readouterr().err
    assert main(["field", "darecki2011_radiance", str(RADIANCE), "--out", str(tmp_path / "o"),
                 "--panels", "a", "--view-zeniths", "x"]) == 2
    err = capsys.readouterr().err
    assert "--view-zeniths 'x' must be comma-separated numbers" in err and len(err.strip().splitlines()) == 1
    assert not (tmp_path / "o").exists()
