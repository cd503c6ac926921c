"""Bad input a fifth pass (2026-12-08, by hand: the Python API beside the commands) found: a result
saved as frame 5 whose run.json named frame 0's files, integers past a float's range, a receiver id
that is none, and the batch functions (studies, sweeps, comparisons, the field data sets) given the
wrong types, some failing only after every render had run. Each is now one line (a
WarpcausticsError naming the argument) before anything renders or is written."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

import warpcaustics as wc
from warpcaustics.batch import compare, field
from warpcaustics.batch.study import load_study, run_study
from warpcaustics.batch.sweep import load_sweep, run_sweep

from helpers import CONFIGS

TINY = {"water.resolution": 16, "caustics.map_resolution": 16, "optics.wavelengths": "rgb",
        "camera.enabled": False}


@pytest.fixture(scope="module")
def flat():
    return wc.render(wc.load_scene(CONFIGS / "flat.toml", TINY), device="cpu")


def test_a_frame_saved_as_frame_5_is_recorded_as_frame_5(flat, tmp_path):
    """run.json had listed frame 0 and frame_0000.* beside the frame_0005.* it wrote."""
    flat.save(tmp_path / "f", frame=np.int64(5))
    frames = json.loads((tmp_path / "f" / "run.json").read_text())["frames"]
    assert [f["frame"] for f in frames] == [5]
    assert frames[0]["files"] == ["frame_0005.exr", "frame_0005.png"]
    assert all((tmp_path / "f" / name).is_file() for name in frames[0]["files"])


@pytest.mark.parametrize("out", [None, 5, b"/tmp/x", "a\0b", ""])
def test_save_takes_a_folder_path(flat, out):
    with pytest.raises(wc.WarpcausticsError, match=r"^out_dir = .* must be a folder's path"):
        flat.save(out)


def test_a_receiver_id_the_render_lacks_is_named_with_the_ids_it_has():
    """(99), ('a'), (None), (2.5), (-1) had returned an empty array, (True) the walls, an array a
    broadcasting error."""
    r = wc.render(wc.load_scene(CONFIGS / "pool_pots.toml", {**TINY, "caustics.method": "photons"}),
                  device="cpu")
    assert r.receiver_irradiance(np.int64(2)).shape == (int(np.sum(r.face_receiver == 2)), 3)
    for bad in (99, "a", None, 2.5, -1, True, np.array([2, 3])):
        with pytest.raises(wc.WarpcausticsError, match=r"is not a receiver id of this render; its ids: "
                                                       r"1 \(walls\), 2 \(receivers\[0\]\)"):
            r.receiver_irradiance(bad)


@pytest.mark.parametrize("overrides", [{"sun.elevation_deg": 10**400}, {"floor.albedo": [10**400]},
                                       {"camera.position_m": [0, 0, -10**400]},
                                       {"sun.elevation_deg": 10**5000}])
def test_an_integer_past_a_floats_range_is_one_line(overrides):
    """float() of it had raised OverflowError from inside the config's checks (the CLI too: TOML reads
    a 400-digit number as an integer)."""
    with pytest.raises(wc.ConfigError, match=r"is beyond a float's range \(±1.8e308\)"):
        wc.load_scene(None, overrides)


def test_a_huge_integer_is_quoted_short_and_a_huge_time_refused(tmp_path):
    with pytest.raises(wc.ConfigError, match=r"^water.resolution = 1000.*0 \(401 characters\) is out of"):
        wc.load_scene(None, {"water.resolution": 10**400})
    scene = wc.load_scene(CONFIGS / "flat.toml", TINY)
    for t in (10**400, -10**400):
        with pytest.raises(wc.ConfigError, match=r"time_s = .*characters\) must be a finite number of"):
            wc.render(scene, time_s=t, device="cpu")


def test_a_scene_built_by_hand_is_validated_before_it_renders():
    """Scene(None) had raised AttributeError; a config changed past load_scene's checks (a zero
    resolution) had crashed the process in a kernel."""
    cfg = wc.load_scene(CONFIGS / "flat.toml", TINY).config
    with pytest.raises(wc.ConfigError, match=r"Scene\(config\) takes a Config; got NoneType"):
        wc.render(wc.Scene(None), device="cpu")
    zero = dataclasses.replace(cfg, water=dataclasses.replace(cfg.water, resolution=0))
    with pytest.raises(wc.ConfigError, match="not valid: water.resolution = 0 is out of range"):
        wc.render(wc.Scene(zero), device="cpu")
    assert wc.render(wc.Scene(cfg), device="cpu").floor_irradiance.shape == (3, 16, 16)


@pytest.fixture
def study_file(tmp_path):
    (tmp_path / "flat.toml").write_text("[water]\nmodel = 'flat'\nresolution = 8\nextent_m = 2.0\n"
                                        "[caustics]\nmap_resolution = 8\n[optics]\nwavelengths = 'rgb'\n")
    path = tmp_path / "study.toml"
    path.write_text("scene = 'flat.toml'\nwater_types = ['clear_ocean']\ndepths_m = [1.0, 3.0]\n"
                    "sun_elevations_deg = [60.0]\n")
    return path


def test_a_study_takes_a_str_folder_and_refuses_a_file_before_rendering(study_file, tmp_path, monkeypatch):
    """A str folder had failed with AttributeError after every render (and a file there with
    FileExistsError, also after them)."""
    pytest.importorskip("matplotlib")
    study = load_study(str(study_file))
    (tmp_path / "a_file").write_text("")
    renders = []
    monkeypatch.setattr(wc, "render", lambda *a, **k: renders.append(1))
    with pytest.raises(wc.WarpcausticsError, match="out_dir .*a_file' is a file; give a folder"):
        run_study(study, tmp_path / "a_file")
    with pytest.raises(wc.ConfigError, match=r"run_study\(\) takes a study from load_study"):
        run_study(wc.load_scene(CONFIGS / "flat.toml"), tmp_path / "o")
    assert renders == []
    monkeypatch.undo()
    paths = run_study(study, str(tmp_path / "o"), device="cpu")
    assert paths["study"].is_file()


@pytest.mark.parametrize("call, needle", [
    (lambda p: load_study(None), r"load_study\(\) path must be the path of a study's .toml file"),
    (lambda p: load_study(p, "x=1"), r"load_study\(\) overrides must be a dict"),
    (lambda p: load_study(p, {1: 2}), r"overrides key 1 must be a dotted config key"),
    (lambda p: load_sweep(None), r"load_sweep\(\) path must be the path of a sweep's .toml file"),
    (lambda p: load_sweep(CONFIGS / "sweeps/water_types.toml", [("a", 1)]), r"load_sweep\(\) overrides must"),
])
def test_the_study_and_sweep_loaders_name_a_wrong_argument(study_file, call, needle):
    with pytest.raises(wc.ConfigError, match=needle):
        call(study_file)


def test_run_sweep_names_a_wrong_argument_before_writing(tmp_path):
    sweep = load_sweep(CONFIGS / "sweeps/water_types.toml")
    out = tmp_path / "out"
    for workers, needle in (("2", "must be a whole number of processes"), (None, "must be a whole number"),
                            (1.5, "must be a whole number"), (True, "must be a whole number"),
                            (0, "must be at least 1")):
        with pytest.raises(wc.WarpcausticsError, match=f"--workers = .*{needle}"):
            run_sweep(sweep, out, workers=workers, device="cpu")
    for bad in (None, 5):
        with pytest.raises(wc.ConfigError, match=r"run_sweep\(\) out_dir must be the path of the output"):
            run_sweep(sweep, bad, device="cpu")
    with pytest.raises(wc.ConfigError, match=r"run_sweep\(\) takes a sweep from load_sweep"):
        run_sweep(wc.load_scene(None), out)
    assert not out.exists()


def test_the_comparison_names_a_wrong_argument(tmp_path):
    with pytest.raises(wc.ConfigError, match=r"compare_methods\(\) config must be the path"):
        compare.compare_methods(5, {}, 0.0, "cpu")
    with pytest.raises(wc.ConfigError, match=r"compare_methods\(\) overrides must be a dict"):
        compare.compare_methods(CONFIGS / "flat.toml", "x", 0.0, "cpu")
    for methods in ("sunmap", None):  # a bare string had been split into its letters
        with pytest.raises(wc.ConfigError, match=r"--methods = .* must be a list of names"):
            compare.compare_methods(CONFIGS / "flat.toml", {}, 0.0, "cpu", methods=methods)
    for comparison in ({}, "x"):
        with pytest.raises(wc.WarpcausticsError, match=r"write_comparison\(\) takes what compare_methods"):
            compare.write_comparison(tmp_path / "c", comparison, 0.0)
    good = {"rows": [], "results": {}}
    with pytest.raises(wc.ConfigError, match="time_s = 'zero' must be a number of seconds"):
        compare.write_comparison(tmp_path / "c", good, "zero")
    with pytest.raises(wc.ConfigError, match=r"write_comparison\(\) out must be the path"):
        compare.write_comparison(None, good, 0.0)
    assert not (tmp_path / "c").exists()


@pytest.mark.parametrize("name", sorted(field.DATASETS))
def test_every_field_data_set_names_a_wrong_argument(name, tmp_path):
    run, scene = field.DATASETS[name], CONFIGS / "field" / "gernez2009.toml"
    for kwargs, needle in (({"scene": None}, f"{name}\\(\\) scene must be the path of a scene's .toml"),
                           ({"out": 7}, f"{name}\\(\\) out must be the path of the output folder"),
                           ({"overrides": "x"}, f"{name}\\(\\) overrides must be a dict"),
                           ({"workers": "2"}, "--workers = '2' must be a whole number")):
        args = {"scene": scene, "out": tmp_path / "o", **kwargs}
        with pytest.raises(wc.WarpcausticsError, match=needle):
            run(args.pop("scene"), args.pop("out"), quick=True, **args)
    assert not (tmp_path / "o").exists()


def test_gernez_series_as_a_bare_string_is_refused():
    """``series="zenith"`` had been read as its letters ("--series 'z,e,n,i,t,h'")."""
    with pytest.raises(wc.ConfigError, match=r"--series = 'zenith' must be a list of names, e.g. \('zen"):
        field.run_gernez2009(CONFIGS / "field" / "gernez2009.toml", "o", series="zenith", quick=True)


def test_the_smaller_findings(tmp_path):
    """An empty device name had meant auto, an empty scene path the working folder ('.'), and a file
    key given as a pathlib.Path had been refused (load_scene takes Paths for its own file);
    --long-waves quoted a string as if it were a number."""
    scene = wc.load_scene(CONFIGS / "flat.toml", TINY)
    for name in ("", "  "):
        with pytest.raises(wc.DeviceError, match=r"device = '\s*' must be a name: auto, cpu, cuda or cuda:N"):
            wc.render(scene, device=name)
    with pytest.raises(wc.ConfigError, match=r"load_scene\(\) takes the path of a .toml file .*got str ''"):
        wc.load_scene("")
    np.save(tmp_path / "h.npy", np.zeros((16, 16), np.float32))
    from_path = wc.load_scene(None, {"water.model": "heightfield", "water.file": tmp_path / "h.npy",
                                     "water.resolution": 16})
    assert from_path.config.water.file == str(tmp_path / "h.npy") and from_path.heights.shape == (16, 16)
    with pytest.raises(wc.ConfigError, match=r"--long-waves = '128' must be a side in metres"):
        field.run_gernez2009(CONFIGS / "field" / "gernez2009.toml", tmp_path / "o", long_waves_m="128",
                             quick=True)
