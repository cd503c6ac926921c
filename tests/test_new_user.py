"""Issue 28: what a new user trips over. The CLI runs in a subprocess: exit codes and messages."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import warpcaustics as wc
from warpcaustics.config.loading import tomllib  # tomli on Python 3.10

from helpers import CONFIGS

TINY = ["--set", "water.resolution=16", "--set", "caustics.map_resolution=16", "--set",
        "optics.wavelengths.bins=2"]


def run_cli(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "warpcaustics", *args], capture_output=True, text=True,
                          timeout=600)


def one_line_error(proc: subprocess.CompletedProcess, *names: str) -> str:
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1, proc.stderr[-2000:]
    for name in names:
        assert name in lines[0], lines[0]
    return lines[0]


def write_sweep(path: Path, extra: str = "", grid: str = '"sun.elevation_deg" = [40.0]') -> Path:
    path.write_text(f'base = "{CONFIGS / "ocean.toml"}"\n{extra}\n[set]\n"water.resolution" = 16\n'
                    '"caustics.map_resolution" = 16\n"optics.wavelengths.bins" = 2\n'
                    f"[grid]\n{grid}\n")
    return path


# Sweeps check everything before the first task ---------------------------------------------------

def test_a_misspelt_frames_key_fails_the_sweep_at_once(tmp_path):
    sweep = write_sweep(tmp_path / "s.toml", "[frames]\ncont = 2")
    one_line_error(run_cli("sweep", str(sweep), "--out", str(tmp_path / "out"), "--device", "cpu"),
                   "'cont'", "'count'")
    assert not (tmp_path / "out" / "manifest.jsonl").exists()


def test_a_misspelt_grid_key_fails_the_sweep_at_once(tmp_path):
    sweep = write_sweep(tmp_path / "s.toml", grid='"floor.depht_m" = [2.0, 3.0]')
    one_line_error(run_cli("sweep", str(sweep), "--out", str(tmp_path / "out"), "--device", "cpu"),
                   "floor.depht_m", "floor.depth_m")
    assert not (tmp_path / "out" / "manifest.jsonl").exists()


def test_sweep_and_study_take_set(tmp_path):
    sweep = write_sweep(tmp_path / "s.toml")
    out = tmp_path / "out"
    proc = run_cli("sweep", str(sweep), "--out", str(out), "--device", "cpu", "--quiet",
                   "--set", "floor.depth_m=2.5")
    assert proc.returncode == 0, proc.stderr[-2000:]
    (task,) = [p for p in out.iterdir() if p.is_dir() and not p.name.startswith(".")]
    import json

    assert json.loads((task / "run.json").read_text())["config"]["floor"]["depth_m"] == 2.5
    one_line_error(run_cli("sweep", str(sweep), "--out", str(tmp_path / "o2"), "--device", "cpu",
                           "--set", "floor.depht_m=2.5"), "floor.depht_m", "floor.depth_m")
    one_line_error(run_cli("study", str(CONFIGS / "study.toml"), "--out", str(tmp_path / "o3"), "--device",
                           "cpu", "--set", "sun.elevatoin_deg=30"), "sun.elevatoin_deg", "sun.elevation_deg")


# warpcaustics config ------------------------------------------------------------------------------

def test_config_prints_the_resolved_configuration_as_toml(tmp_path):
    proc = run_cli("config", str(CONFIGS / "pool_pots.toml"), "--set", "sun.elevation_deg=33")
    assert proc.returncode == 0, proc.stderr
    printed = tmp_path / "printed.toml"
    printed.write_text(proc.stdout)
    table = tomllib.loads(proc.stdout)
    assert table["sun"]["elevation_deg"] == 33.0 and len(table["receivers"]) >= 1
    # every key with its value: read back, it is the same scene
    again = wc.load_scene(printed).config
    assert again == wc.load_scene(CONFIGS / "pool_pots.toml", {"sun.elevation_deg": 33.0}).config
    one_line_error(run_cli("config", str(CONFIGS / "ocean.toml"), "--set", "water.extnt_m=3"),
                   "water.extnt_m", "water.extent_m")


@pytest.mark.parametrize(("argv", "names"), [
    (("render", "configs/ocean.toml", "--out", "o", "--frames", "1e3"), ("--frames", "'1e3'",
                                                                         "warpcaustics render --help")),
    (("rendr",), ("invalid choice: 'rendr'", "warpcaustics --help")),
    ((), ("COMMAND", "warpcaustics --help")),
    (("field", "gernez2009"), ("SCENE, --out", "warpcaustics field --help")),
])
def test_a_command_line_argparse_refuses_is_one_line(argv, names):
    """A flag's value of the wrong type, a misspelt command, a missing argument: argparse's usage
    (up to five lines) no longer comes before the error; the line points to --help instead."""
    one_line_error(run_cli(*argv), *names)


def test_the_printed_config_loads_from_another_folder(tmp_path):
    """A file the config names relative to its own folder (lens.toml's ``water.file = "lens.npy"``)
    is printed as an absolute path: the printed config, saved elsewhere, is the same scene."""
    proc = run_cli("config", str(CONFIGS / "lens.toml"))
    assert proc.returncode == 0, proc.stderr
    assert tomllib.loads(proc.stdout)["water"]["file"] == str(CONFIGS.resolve() / "lens.npy")
    printed = tmp_path / "printed.toml"
    printed.write_text(proc.stdout)
    again, original = wc.load_scene(printed), wc.load_scene(CONFIGS / "lens.toml")
    assert np.array_equal(again.heights, original.heights)
    assert again.config.water.file == str(CONFIGS.resolve() / "lens.npy")


# No stale outputs --------------------------------------------------------------------------------

def test_a_rerun_removes_the_earlier_runs_files_and_only_those(tmp_path):
    out = tmp_path / "out"
    render = ["render", str(CONFIGS / "ocean.toml"), "--out", str(out), "--device", "cpu", "--quiet", *TINY]
    assert run_cli(*render, "--set", "output.npz=true", "--set", "output.vtk=true").returncode == 0
    assert (out / "frame_0000.npz").exists() and (out / "floor_0000.vti").exists()
    (out / "notes.txt").write_text("mine")
    assert run_cli(*render).returncode == 0
    assert not (out / "frame_0000.npz").exists() and not (out / "floor_0000.vti").exists()
    assert (out / "frame_0000.exr").exists() and (out / "run.json").exists()
    assert (out / "notes.txt").read_text() == "mine"


def test_outputs_no_run_recorded_are_refused_without_force(tmp_path):
    out = tmp_path / "out"
    out.mkdir()
    (out / "frame_0000.exr").write_bytes(b"someone else's")
    render = ["render", str(CONFIGS / "ocean.toml"), "--out", str(out), "--device", "cpu", "--quiet", *TINY]
    one_line_error(run_cli(*render), "--force")
    assert (out / "frame_0000.exr").read_bytes() == b"someone else's"
    assert run_cli(*render, "--force").returncode == 0
    assert (out / "run.json").exists()


def test_a_folder_holding_another_sweep_is_refused_and_the_same_sweep_resumes(tmp_path):
    out = tmp_path / "out"
    first = write_sweep(tmp_path / "a.toml")
    base = ["--out", str(out), "--device", "cpu", "--quiet"]
    assert run_cli("sweep", str(first), *base).returncode == 0
    again = run_cli("sweep", str(first), *base)
    assert again.returncode == 0 and "skipped 1" in again.stdout, again.stdout
    other = write_sweep(tmp_path / "b.toml", grid='"sun.elevation_deg" = [50.0]')
    one_line_error(run_cli("sweep", str(other), *base), "another sweep", "--force")
    assert run_cli("sweep", str(other), *base, "--force").returncode == 0


# Public API, licence, citation -------------------------------------------------------------------

def test_the_public_names_are_discoverable():
    import warpcaustics

    names = dir(warpcaustics)
    for name in ("load_scene", "render", "Renderer", "RenderResult", "Scene", "ConfigError", "DeviceError",
                 "WarpcausticsError"):
        assert name in names and getattr(warpcaustics, name) is not None
    assert issubclass(warpcaustics.ConfigError, warpcaustics.WarpcausticsError)


def test_licence_and_citation_are_there():
    from helpers import ROOT

    licence = (ROOT / "LICENSE").read_text(encoding="utf-8")
    assert "Apache License" in licence and "Version 2.0, January 2004" in licence
    pyproject = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    assert pyproject["project"]["license"]["text"] == "Apache-2.0"
    citation = (ROOT / "CITATION.cff").read_text(encoding="utf-8")
    assert "cff-version: 1.2.0" in citation and f'version: "{wc.__version__}"' in citation
    assert (ROOT / "CHANGELOG.md").exists()


# EXR colour metadata ------------------------------------------------------------------------------

def test_rgb_exrs_carry_the_chromaticities_of_their_colour_space(tmp_path):
    """Rec. 709 primaries and D65 for sRGB; AP1 and the ACES white for ACEScg. The code takes them from
    colour-science; the test's values are the published ones (ITU-R BT.709-6 items 1.3–1.4; the
    Academy's ACEScg specification S-2014-004, AP1 and the ACES white point)."""
    import OpenEXR
    import pytest

    expected = {"sRGB": (0.64, 0.33, 0.30, 0.60, 0.15, 0.06, 0.3127, 0.3290),
                "ACEScg": (0.713, 0.293, 0.165, 0.830, 0.128, 0.044, 0.32168, 0.33767)}
    for space, xy in expected.items():
        scene = wc.load_scene(CONFIGS / "ocean.toml", {"water.resolution": 16, "caustics.map_resolution": 16,
                                                       "optics.wavelengths.bins": 2,
                                                       "output.colourspace": space})
        paths = wc.render(scene, 0.0, "cpu").save(tmp_path / space)
        with OpenEXR.File(str(paths["exr"])) as exr:
            assert exr.header()["chromaticities"] == pytest.approx(xy, abs=1e-6)


# Reports and progress -----------------------------------------------------------------------------

def test_sweep_progress_names_the_variant_and_summary_cells_are_toml(tmp_path):
    sweep = write_sweep(tmp_path / "s.toml",
                        grid='"water.model" = ["pool"]\n"water.drops" = [[{ x_m = 0.25, y_m = 0.0 }]]')
    out = tmp_path / "out"
    proc = run_cli("sweep", str(sweep), "--out", str(out), "--device", "cpu")
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert 'water.model="pool"' in proc.stdout + proc.stderr
    import csv

    with open(out / "summary.csv", encoding="utf-8") as fh:
        (row,) = list(csv.DictReader(fh))
    assert row["water.drops"] == "[{ x_m = 0.25, y_m = 0.0 }]" and row["water.model"] == "pool"
    report = run_cli("report", str(out))
    assert report.returncode == 0 and (out / "summary.png").exists(), report.stderr


def test_report_labels_the_variants_by_the_keys_that_vary_not_by_the_bands():
    """A band whose wavelength is not whole (16 bins from 400 nm: 409.375 nm) has a dot in its
    columns' names (``mean_409.375nm``) as a config key has: the plot's labels are the keys alone
    (the README's water-types sweep had been labelled by every band's figures)."""
    from warpcaustics.batch.report import varied_keys

    rows = [{"id": "a", "frame": "0", "floor.depth_m": "2.0", "optics.water_type": water,
             "mean_409.375nm": mean, "max_409.375nm": peak, "contrast": "0.1"}
            for water, mean, peak in (("clear_ocean", "1.5", "3.0"), ("coastal_ocean", "1.2", "2.5"))]
    assert varied_keys(rows) == ["optics.water_type"]


def test_the_no_cuda_notice_is_said_once_per_sweep(tmp_path):
    """Two workers, the device left to "auto" on a machine without CUDA: one notice, not one each."""
    import pytest
    import warp as wp

    if wp.get_cuda_device_count() > 0:
        pytest.skip("a CUDA device is present: no notice to count")
    sweep = write_sweep(tmp_path / "s.toml", grid='"sun.elevation_deg" = [30.0, 50.0, 70.0]')
    proc = run_cli("sweep", str(sweep), "--out", str(tmp_path / "out"), "--workers", "2", "--quiet")
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stderr.count("no CUDA device found") == 1, proc.stderr


# NetCDF follows CF-1.10 ------------------------------------------------------------------------

def test_netcdf_follows_cf(tmp_path):
    """Read back with xarray: Conventions, axes that cf_xarray finds, standard names of the
    coordinates, time in "seconds since" the scene's date, the bin edges as bounds."""
    import numpy as np
    import pytest

    xr = pytest.importorskip("xarray")
    pytest.importorskip("cf_xarray")
    place = {"sun.datetime": "2009-07-14T11:30:00+02:00", "sun.latitude_deg": 43.7, "sun.longitude_deg": 7.3}
    small = {"water.resolution": 16, "caustics.map_resolution": 16, "optics.wavelengths.bins": 3}
    scene = wc.load_scene(CONFIGS / "ocean.toml", {**small, "output.netcdf": True, **place})
    result = wc.render(scene, 0.25, "cpu")
    path = result.save(tmp_path)["netcdf"]
    with xr.open_dataset(path) as ds:
        assert ds.attrs["Conventions"] == "CF-1.10"
        assert ds.cf.axes == {"X": ["x"], "Y": ["y"], "T": ["time"]}
        assert {"projection_x_coordinate", "projection_y_coordinate", "time", "radiation_wavelength"} <= \
            set(ds.cf.standard_names)
        assert ds["time"].values[0] == np.datetime64("2009-07-14T09:30:00.250")  # 11:30 at +02:00, + 0.25 s
        bounds = ds[ds["wavelength"].attrs["bounds"]].values
        np.testing.assert_allclose(bounds[:, 0], result.bins.edges_nm[:-1])
        np.testing.assert_allclose(bounds[:, 1], result.bins.edges_nm[1:])
        floor = ds["floor_irradiance"].attrs
        assert "long_name" in floor and floor["units"] == "W m-2 nm-1"
    with xr.open_dataset(path, decode_times=False) as raw:
        assert raw["time"].attrs["units"] == "seconds since 2009-07-14 09:30:00"


# PNG through Pillow ------------------------------------------------------------------------------

def test_png_previews_read_back_exactly(tmp_path):
    """The preview's 8-bit pixels come back from Pillow's reader as written, rows top first."""
    import numpy as np
    from PIL import Image

    from warpcaustics.io.png import write_png

    rgb8 = np.random.default_rng(28).integers(0, 256, (7, 11, 3), dtype=np.uint8)
    write_png(tmp_path / "p.png", rgb8)
    with Image.open(tmp_path / "p.png") as image:
        assert image.format == "PNG" and image.mode == "RGB"
        np.testing.assert_array_equal(np.asarray(image), rgb8)


# Ray client addresses --------------------------------------------------------------------------

def test_a_ray_client_address_without_the_client_is_one_line(tmp_path, monkeypatch, capsys):
    """Without Ray's client (grpc), ``--address ray://…`` names the extra instead of a traceback."""
    import importlib.util

    import pytest

    pytest.importorskip("ray")
    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec",
                        lambda name, *a: None if name == "grpc" else real(name, *a))
    from warpcaustics import cli

    sweep = write_sweep(tmp_path / "s.toml")
    code = cli.main(["sweep", str(sweep), "--out", str(tmp_path / "out"), "--executor", "ray",
                     "--address", "ray://127.0.0.1:1", "--quiet"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "warpcaustics[ray]" in err[0] and "ray[client]" in err[0], err


def test_info_lists_the_extras():
    from warpcaustics.config.loading import tomllib as toml

    from helpers import ROOT

    proc = run_cli("info")
    assert proc.returncode == 0, proc.stderr
    project = toml.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    declared = project["optional-dependencies"]
    listed = proc.stdout.split("extras:")[1].split("devices:")[0]
    for extra in declared:
        assert extra in listed


def test_config_docs_tables_are_whole_and_say_what_the_defaults_do():
    from helpers import ROOT

    text = (ROOT / "docs" / "config.md").read_text(encoding="utf-8")
    assert "|\n\n| `" not in text  # a blank line inside a table splits it in two on render
    assert "The sun is a point" not in text  # the default disk is 0.53°
    assert "no stage uses it yet" not in text  # optics.phase_function drives the shafts and the walk
