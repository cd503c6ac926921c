"""The sun's position from date, time and place (pvlib's NREL SPA), and its config rules."""

import ast
import importlib.util
from datetime import datetime, timedelta, timezone
from pathlib import Path

import pytest

import warpcaustics as wc
from warpcaustics.errors import ConfigError
from warpcaustics.optics.solar import sun_position

from helpers import CONFIGS


def _spa_example() -> dict:
    """The expected values of the NREL SPA example as pvlib ships them
    (pvlib/spa_c_files/spa_py_example.py, the EXPECTED dict), read without running that file."""
    root = Path(importlib.util.find_spec("pvlib").submodule_search_locations[0])
    tree = ast.parse((root / "spa_c_files" / "spa_py_example.py").read_text())
    for node in tree.body:
        if isinstance(node, ast.Assign) and getattr(node.targets[0], "id", "") == "EXPECTED":
            return ast.literal_eval(node.value)
    raise AssertionError("EXPECTED not found in pvlib's SPA example")


def test_sun_position_matches_the_spa_reference_example():
    """The SPA example (Golden, Colorado, 17 October at 12:30:30 local time, UTC−7): apparent zenith
    and azimuth within 0.01° of the expected values, the azimuth turned to ours (90° − clockwise
    from north)."""
    e = _spa_example()
    when = datetime(e["year"], e["month"], e["day"], e["hour"], e["minute"], int(e["second"]),
                    tzinfo=timezone(timedelta(hours=e["time_zone"])))
    elevation, azimuth = sun_position(when, e["latitude"], e["longitude"], altitude_m=e["elevation"],
                                      pressure_hpa=e["pressure"], temperature_c=e["temperature"],
                                      delta_t_s=e["delta_t"])
    assert elevation == pytest.approx(90.0 - e["zenith"], abs=0.01)
    assert azimuth == pytest.approx(90.0 - e["azimuth"], abs=0.01)


def test_config_takes_a_date_time_and_place():
    """sun.datetime with latitude and longitude resolves into elevation and azimuth in the config
    (overrides replace the file's angles); in the morning the sun is east of south (+x, −y)."""
    scene = wc.load_scene(CONFIGS / "ocean.toml", {"sun.datetime": "2009-07-14T09:00:00+00:00",
                                                 "sun.latitude_deg": 43.7, "sun.longitude_deg": 7.3})
    sun = scene.config.sun
    assert 20.0 < sun.elevation_deg < 60.0
    assert -90.0 < sun.azimuth_deg < 0.0
    assert scene.sun_direction[0] > 0 and scene.sun_direction[1] < 0


@pytest.mark.parametrize(("overrides", "needle"), [
    ({"sun.datetime": "2009-07-14T09:00:00+00:00"}, "sun.latitude_deg"),
    ({"sun.datetime": "2009-07-14T09:00:00", "sun.latitude_deg": 43.7, "sun.longitude_deg": 7.3},
     "UTC offset"),
    ({"sun.datetime": "noon", "sun.latitude_deg": 43.7, "sun.longitude_deg": 7.3}, "ISO 8601"),
    ({"sun.datetime": "2009-07-14T23:00:00+00:00", "sun.latitude_deg": 43.7, "sun.longitude_deg": 7.3},
     "below the horizon"),
    ({"sun.datetime": "2009-07-14T09:00:00+00:00", "sun.latitude_deg": 43.7, "sun.longitude_deg": 7.3,
      "sun.elevation_deg": 50.0}, "both set"),
])
def test_sun_position_errors_are_one_line(overrides, needle):
    """A missing coordinate, a time without offset or not a time, a night sun and two ways of
    setting the sun at once are refused with one line naming the key."""
    with pytest.raises(ConfigError, match=needle) as err:
        wc.load_scene(None, overrides)
    assert "\n" not in str(err.value)


def test_a_toml_date_time_literal_is_taken_too():
    """An unquoted TOML date-time (as ``--set sun.datetime=2009-07-14T09:00:00+00:00`` gives) is the
    same as the quoted string."""
    place = {"sun.latitude_deg": 43.7, "sun.longitude_deg": 7.3}
    literal = datetime(2009, 7, 14, 9, 0, tzinfo=timezone.utc)
    a = wc.load_scene(None, {**place, "sun.datetime": literal}).config.sun
    b = wc.load_scene(None, {**place, "sun.datetime": "2009-07-14T09:00:00+00:00"}).config.sun
    assert (a.elevation_deg, a.azimuth_deg) == (b.elevation_deg, b.azimuth_deg)


def test_resolved_config_reads_back_and_overrides_win_either_way(tmp_path):
    """run.json's resolved config (the place and the angles it gave) reads back unchanged; over a
    file that gives a place, overridden angles win (a sweep over elevation), and the "Z" suffix
    means UTC."""
    from warpcaustics.config import config_from_dict, config_to_dict

    place = {"sun.datetime": "2009-07-14T09:00:00Z", "sun.latitude_deg": 43.7, "sun.longitude_deg": 7.3}
    cfg = wc.load_scene(None, place).config
    assert config_from_dict(config_to_dict(cfg)).sun == cfg.sun
    toml = tmp_path / "placed.toml"
    toml.write_text('[sun]\ndatetime = "2009-07-14T09:00:00+00:00"\n'
                    "latitude_deg = 43.7\nlongitude_deg = 7.3\n")
    assert wc.load_scene(toml).config.sun.elevation_deg == pytest.approx(cfg.sun.elevation_deg)
    sun = wc.load_scene(toml, {"sun.elevation_deg": 30.0}).config.sun
    assert sun.elevation_deg == 30.0 and sun.datetime is None
