"""Issue 31: the twelve causes a fuzz of 501 cases found, each now a one-line error (exit 2, naming
the key and the fix), a finite result, or a kept file. The CLI runs in a subprocess (its exit code
and its whole stderr), except where a failure has to be injected into a render."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import warpcaustics as wc
from warpcaustics import cli
from warpcaustics.errors import ConfigError

from helpers import CONFIGS

TINY = ["--set", "water.resolution=16", "--set", "caustics.map_resolution=16", "--set",
        "optics.wavelengths.bins=2"]


def run_cli(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "warpcaustics", *args], capture_output=True, text=True,
                          cwd=cwd, timeout=300)


def assert_one_line_error(proc: subprocess.CompletedProcess, *names: str) -> str:
    """Exit 2 and one stderr line, ``warpcaustics: error: …`` naming each of ``names``."""
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2, proc.stderr[-2000:]
    assert len(lines) == 1 and lines[0].startswith("warpcaustics: error: "), proc.stderr[-2000:]
    for name in names:
        assert name in lines[0], lines[0][:500]
    return lines[0]


def render_args(tmp_path: Path, *sets: str, config: Path = CONFIGS / "ocean.toml") -> list[str]:
    out = [a for s in sets for a in ("--set", s)]
    return ["render", str(config), "--out", str(tmp_path / "out"), "--device", "cpu", "--quiet", *TINY, *out]


# 1. An enum key given a list or a table --------------------------------------------------------

@pytest.mark.parametrize("key,value", [("optics.phase_function", '["henyey_greenstein"]'),
                                        ("output.colourspace", '["sRGB"]'),
                                        ("device", "{a = 1}"),
                                        ("sky.model", '["cie_clear"]')])
def test_an_enum_key_given_a_list_or_table_is_refused_by_name(key, value):
    with pytest.raises(ConfigError, match=key.replace(".", r"\.")):
        wc.load_scene(CONFIGS / "ocean.toml", {key: cli_value(value)})


def cli_value(text: str):
    from warpcaustics.config import parse_override

    return parse_override(f"k={text}")[1]


def test_an_enum_list_through_the_cli(tmp_path):
    assert_one_line_error(run_cli(*render_args(tmp_path, 'device=["auto"]')), "device")


# 2. Deep nesting -------------------------------------------------------------------------------

@pytest.mark.parametrize("text", [
    "[" + ".".join(["a"] * 3000) + "]\nx = 1\n",
    "a" + ".a" * 3000 + " = 1\n",
    "x = " + "[" * 3000 + "]" * 3000 + "\n",
    "x = " + "{a = " * 3000 + "1" + "}" * 3000 + "\n",
])
def test_deep_nesting_in_a_config_is_one_line(tmp_path, text):
    path = tmp_path / "deep.toml"
    path.write_text(text)
    proc = run_cli("render", str(path), "--out", str(tmp_path / "out"), "--device", "cpu")
    assert_one_line_error(proc, "deep.toml")
    assert not (tmp_path / "out").exists()


def test_deep_nesting_in_an_override_is_one_line(tmp_path):
    proc = run_cli(*render_args(tmp_path, "water.extent_m=" + "[" * 3000 + "]" * 3000))
    assert_one_line_error(proc, "water.extent_m")


def test_deeply_nested_dict_is_refused_before_any_recursion():
    table: dict = {}
    node = table
    for _ in range(5000):
        node["a"] = {}
        node = node["a"]
    with pytest.raises(ConfigError, match="more than 32 levels deep"):
        wc.config.config_from_dict(table)


# 3. A path too long for the file system ---------------------------------------------------------

def test_a_path_too_long_is_one_line(tmp_path):
    proc = run_cli(*render_args(tmp_path, "water.model=heightfield", "water.file=" + "x" * 5000 + ".npy"))
    assert_one_line_error(proc, "water.file")
    mesh = tmp_path / "mesh.toml"
    mesh.write_text(f'[caustics]\nmethod = "photons"\n[[receivers]]\nmesh = "{"m" * 100_000}.stl"\n')
    assert_one_line_error(run_cli("render", str(mesh), "--out", str(tmp_path / "o2"), "--device", "cpu"),
                          "receivers[0].mesh")
    for key in ("floor.albedo_file", "sun.file"):
        sets = [f"{key}={'y' * 5000}.csv"] + (["sun.spectrum=file"] if key == "sun.file" else [])
        assert_one_line_error(run_cli(*render_args(tmp_path, *sets)), key)


# 4. Physical bounds, and a frame that is not finite fails -----------------------------------------

def test_an_unphysical_extent_is_refused(tmp_path):
    assert_one_line_error(run_cli(*render_args(tmp_path, "water.extent_m=1e30")), "water.extent_m")


def test_a_frame_that_is_not_finite_fails_and_leaves_no_run_json(tmp_path, monkeypatch, capsys):
    """Whatever a scene's values, a floor map or camera image that holds NaN or inf is refused with
    one line, and the run is not marked complete."""
    from warpcaustics.caustics.fluxratio import FluxRatioStage

    real = FluxRatioStage.render

    def poisoned(self, frame):
        out = real(self, frame)
        out.floor[0, 0, 0] = np.nan
        return out

    monkeypatch.setattr(FluxRatioStage, "render", poisoned)
    code = cli.main(render_args(tmp_path))
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "not finite" in err[0], err
    assert not (tmp_path / "out" / "run.json").exists()


# 5. A number too long for Python's int conversion --------------------------------------------------

def test_an_override_of_100000_digits_is_one_line(tmp_path):
    proc = run_cli(*render_args(tmp_path, "sun.elevation_deg=" + "1" * 100_000))
    line = assert_one_line_error(proc, "sun.elevation_deg")
    assert len(line) < 400  # the value is not echoed whole


# 6. Memory: the host's post-processing is counted; an allocation that fails is one line -----------

def test_the_memory_estimate_counts_post_processing():
    """A 16384² map's colour conversion and read-backs (float64 on the host) are part of the estimate:
    it is not less than the K·M² float64 spectra that post-processing holds."""
    from warpcaustics.pipeline import host_bytes

    scene = wc.load_scene(CONFIGS / "ocean.toml", {"caustics.map_resolution": 16384})
    k = len(wc.optics.spectra.bins_for(scene.config.optics).centres_nm)
    assert host_bytes(scene) >= k * 16384**2 * 8


def test_a_failed_allocation_while_writing_is_one_line(tmp_path, monkeypatch, capsys):
    from warpcaustics.optics import colour

    def exhausted(*args, **kwargs):
        raise MemoryError("Unable to allocate 6.00 GiB for an array")

    monkeypatch.setattr(colour, "spectral_to_xyz", exhausted)
    code = cli.main(render_args(tmp_path))
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "memory" in err[0] and "caustics.map_resolution" in err[0], err
    assert not (tmp_path / "out" / "run.json").exists()


# 7. floor.albedo_file is checked whatever the method -------------------------------------------------

@pytest.mark.parametrize("rows", [None, "400,-1\n700,0.5\n", "400,0.5\n700,2\n"])
def test_the_floor_albedo_file_is_checked_for_the_flux_ratio_too(tmp_path, rows):
    path = tmp_path / "albedo.csv"
    if rows is not None:
        path.write_text("wavelength_nm,reflectance\n" + rows)
    assert_one_line_error(run_cli(*render_args(tmp_path, f"floor.albedo_file={path}")), "floor.albedo_file")


# 8. A sweep deletes only what it wrote -----------------------------------------------------------

def test_a_sweep_keeps_a_users_folder_that_looks_temporary(tmp_path):
    out = tmp_path / "out"
    photos = out / ".photos.tmp-2023"
    photos.mkdir(parents=True)
    (photos / "photo.jpg").write_bytes(b"\xff\xd8 a photo")
    stray = out / ".notes.tmp-7"
    stray.write_text("mine")
    sweep = tmp_path / "sweep.toml"
    sweep.write_text(f'base = "{CONFIGS / "ocean.toml"}"\n[set]\n"water.resolution" = 16\n'
                     '"caustics.map_resolution" = 16\n"optics.wavelengths.bins" = 2\n'
                     '[grid]\n"sun.elevation_deg" = [40.0]\n')
    proc = run_cli("sweep", str(sweep), "--out", str(out), "--device", "cpu", "--quiet")
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert (photos / "photo.jpg").read_bytes() == b"\xff\xd8 a photo" and stray.read_text() == "mine"


# 9. A sweep whose base config is missing ---------------------------------------------------------

def test_a_sweep_with_a_missing_base_exits_2_before_any_task(tmp_path):
    sweep = tmp_path / "sweep.toml"
    sweep.write_text('base = "nowhere.toml"\n[grid]\n"sun.elevation_deg" = [30.0, 60.0]\n')
    proc = run_cli("sweep", str(sweep), "--out", str(tmp_path / "out"), "--device", "cpu", "--quiet")
    assert_one_line_error(proc, "nowhere.toml")
    assert not (tmp_path / "out" / "manifest.jsonl").exists()


# 10. NaN under its own key -----------------------------------------------------------------------

@pytest.mark.parametrize("key", ["sun.latitude_deg", "sun.longitude_deg"])
def test_nan_in_the_suns_place_is_named(key):
    place = {"sun.datetime": "2009-07-14T11:30:00+02:00", "sun.latitude_deg": 43.7,
             "sun.longitude_deg": 7.3, key: float("nan")}
    with pytest.raises(ConfigError, match=key.replace(".", r"\.") + " = nan"):
        wc.load_scene(CONFIGS / "ocean.toml", place)


# 11. A reader's log does not leak ----------------------------------------------------------------

def test_an_empty_stl_prints_only_our_line(tmp_path):
    (tmp_path / "empty.stl").write_bytes(b"")
    scene = tmp_path / "scene.toml"
    scene.write_text('[caustics]\nmethod = "photons"\n[[receivers]]\nmesh = "empty.stl"\n')
    assert_one_line_error(run_cli("render", str(scene), "--out", str(tmp_path / "out"), "--device", "cpu"),
                          "receivers[0].mesh")


# 12. run.json always describes the files beside it -----------------------------------------------

def test_a_failed_rerun_does_not_leave_the_earlier_run_json(tmp_path, monkeypatch, capsys):
    assert cli.main(render_args(tmp_path)) == 0
    assert (tmp_path / "out" / "run.json").exists()
    from warpcaustics.io import frame

    def broken(*args, **kwargs):
        raise ConfigError("injected failure while writing")

    monkeypatch.setattr(frame, "save_frame", broken)
    assert cli.main(render_args(tmp_path, "sun.elevation_deg=30")) == 2
    capsys.readouterr()
    assert not (tmp_path / "out" / "run.json").exists()


# docs/config.md states every numeric key's range, from the metadata the checks read ---------------

def _numeric_keys() -> dict[str, str]:
    import dataclasses

    from warpcaustics.config import Config
    from warpcaustics.config.fields import range_doc
    from warpcaustics.config.loading import _hints, _is_section, _tuple_item

    out = {}

    def walk(cls, prefix):
        for f in dataclasses.fields(cls):
            tp = _hints(cls)[f.name]
            item = _tuple_item(tp)
            if item is not None or _is_section(tp):
                walk(item or tp, f"{prefix}{f.name}.")
            elif text := range_doc(tp, dict(f.metadata)):
                out[f"{prefix}{f.name}"] = text

    walk(Config, "")
    return out


def test_docs_give_every_numeric_key_the_range_the_code_checks():
    import re

    from helpers import ROOT

    rows = {}
    for line in (ROOT / "docs" / "config.md").read_text(encoding="utf-8").splitlines():
        m = re.match(r"^\| ((?:`[^`]+`(?:, )?)+) \|([^|]*)\|", line)
        if m:
            for key in re.findall(r"`([^`]+)`", m.group(1)):
                rows[key] = m.group(2).strip()
    keys = _numeric_keys()
    assert len(keys) > 80
    for key, text in keys.items():
        assert key in rows, f"docs/config.md has no row for {key}"
        doc = rows[key]
        if text.startswith("floats"):  # "3 floats −1e5…1e5": the count is the docs' own
            doc = re.sub(r"^(\d(?: or \d)? floats|list of floats)", "floats", doc)
        assert doc.startswith(text), f"{key}: docs say {rows[key]!r}, the code checks {text!r}"
