"""Bad input gives one clear line and no output; good input writes complete, readable files."""

import json
import os
import subprocess
import sys

import numpy as np
import pytest

import warpcaustics as wc
from warpcaustics.cli import main
from warpcaustics.errors import ConfigError

from helpers import CONFIGS, ROOT

SMALL = ["--set", "water.resolution=32", "--set", "caustics.map_resolution=32",
         "--set", "optics.wavelengths.bins=4"]


def _fails_cleanly(capsys, tmp_path, args, *needles):
    out_dir = tmp_path / "out"
    code = main(["render", *args, "--out", str(out_dir), "--device", "cpu"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert len(err) == 1 and err[0].startswith("warpcaustics: error: "), err
    assert "Traceback" not in err[0]
    for needle in needles:
        assert needle in err[0], err[0]
    assert not out_dir.exists(), "a failed run must leave no output behind"
    return err[0]


def _write(tmp_path, text):
    path = tmp_path / "scene.toml"
    path.write_text(text)
    return str(path)


def test_malformed_toml(capsys, tmp_path):
    """A file that is not TOML names the file and the parse position."""
    _fails_cleanly(capsys, tmp_path, [_write(tmp_path, "[water\nmodel = 'fft'\n")], "not valid TOML",
                   "line 1")


def test_missing_file(capsys, tmp_path):
    """A config path that does not exist says so."""
    _fails_cleanly(capsys, tmp_path, [str(tmp_path / "nope.toml")], "does not exist")


def test_unknown_key_names_nearest(capsys, tmp_path):
    """An unknown key is named with its value and the nearest valid key."""
    _fails_cleanly(capsys, tmp_path, [_write(tmp_path, "[sun]\nelevaton_deg = 30\n")],
                   "sun.elevaton_deg", "nearest valid key: 'sun.elevation_deg'")


def test_unknown_key_in_override(capsys, tmp_path):
    """The same check applies to --set overrides."""
    _fails_cleanly(capsys, tmp_path, [str(CONFIGS / "ocean.toml"), "--set", "floor.dept_m=3"],
                   "floor.dept_m", "'floor.depth_m'")


def test_wrong_type(capsys, tmp_path):
    """A value of the wrong type names the key, the value and the expected type."""
    _fails_cleanly(capsys, tmp_path, [_write(tmp_path, "[floor]\ndepth_m = \"deep\"\n")],
                   "floor.depth_m", "'deep'", "expected a number")


def test_out_of_range(capsys, tmp_path):
    """An out-of-range value names the key, the value and the allowed range."""
    _fails_cleanly(capsys, tmp_path, [str(CONFIGS / "ocean.toml"), "--set", "sun.elevation_deg=95"],
                   "sun.elevation_deg = 95.0", "1e-06 <= value <= 90.0")


def test_bad_enum_value(capsys, tmp_path):
    """A value outside a closed set lists what is allowed."""
    _fails_cleanly(capsys, tmp_path, [str(CONFIGS / "ocean.toml"), "--set", "water.model=wavy"],
                   "water.model = 'wavy'", "flat, heightfield, fft")


def test_heightfield_resolution_disagreement(capsys, tmp_path):
    """water.resolution that disagrees with water.file names both numbers."""
    np.save(tmp_path / "h.npy", np.zeros((16, 16)))
    cfg = _write(tmp_path, "[water]\nmodel = 'heightfield'\nfile = 'h.npy'\nresolution = 32\n")
    _fails_cleanly(capsys, tmp_path, [cfg], "water.resolution = 32", "16×16")


@pytest.mark.parametrize(("array", "needle"), [(np.zeros((8, 12)), "square"),
                                              (np.full((8, 8), np.nan), "finite")])
def test_heightfield_bad_arrays(capsys, tmp_path, array, needle):
    """Non-square or non-finite height files are rejected naming water.file."""
    np.save(tmp_path / "h.npy", array)
    cfg = _write(tmp_path, "[water]\nmodel = 'heightfield'\nfile = 'h.npy'\n")
    _fails_cleanly(capsys, tmp_path, [cfg], "water.file", needle)


def test_scene_too_big_for_memory(capsys, tmp_path):
    """A scene that cannot fit says how much it needs and which keys to lower."""
    _fails_cleanly(capsys, tmp_path, [str(CONFIGS / "ocean.toml"),
                                      "--set", "caustics.map_resolution=16384",
                                      "--set", "optics.wavelengths.bins=400"],
                   "the scene needs", "GiB", "caustics.map_resolution")


def test_host_memory_is_what_the_kernel_and_the_container_leave(tmp_path, monkeypatch):
    """The memory check's host figure: /proc/meminfo's MemAvailable (free pages and reclaimable
    cache; free pages alone had refused runs on machines whose memory was mostly page cache), within
    a cgroup's limit less its working set (usage but the inactive file cache), v2 or v1."""
    from warpcaustics import device as devices

    meminfo = tmp_path / "meminfo"
    meminfo.write_text("MemTotal:       32000000 kB\nMemFree:         1000000 kB\n"
                       "MemAvailable:   20000000 kB\n")
    monkeypatch.setattr(devices, "MEMINFO", str(meminfo))
    monkeypatch.setattr(devices, "CGROUPS", ())
    assert devices.host_available_bytes() == 20_000_000 * 1024
    v2 = tmp_path / "v2"
    v2.mkdir()
    (v2 / "memory.max").write_text("8000000000\n")
    (v2 / "memory.current").write_text("3000000000\n")
    (v2 / "memory.stat").write_text("anon 1000000000\ninactive_file 1000000000\nactive_file 5\n")
    cgroup = (str(v2 / "memory.max"), str(v2 / "memory.current"), str(v2 / "memory.stat"), "inactive_file")
    missing = ("/nonexistent/a", "/nonexistent/b", "/nonexistent/c", "x")  # v2 absent, v1 read
    monkeypatch.setattr(devices, "CGROUPS", (missing, cgroup))
    assert devices.host_available_bytes() == 8_000_000_000 - (3_000_000_000 - 1_000_000_000)
    (v2 / "memory.max").write_text("max\n")  # no limit: the kernel's figure
    assert devices.host_available_bytes() == 20_000_000 * 1024
    monkeypatch.setattr(devices, "MEMINFO", str(tmp_path / "none"))  # no meminfo: free pages
    assert devices.host_available_bytes() > 0


def test_cuda_requested_without_cuda(capsys, tmp_path):
    """Asking for CUDA where there is none is a one-line error, not a Warp traceback."""
    import warp as wp

    if wp.get_cuda_device_count() > 0:
        pytest.skip("this machine has CUDA")
    out_dir = tmp_path / "out"
    code = main(["render", str(CONFIGS / "ocean.toml"), *SMALL, "--out", str(out_dir),
                 "--device", "cuda"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and len(err) == 1 and "no CUDA device is available" in err[0]
    assert not out_dir.exists()


def test_python_overrides_and_errors():
    """Python overrides use the same dotted keys and raise ConfigError with the same message."""
    scene = wc.load_scene(CONFIGS / "ocean.toml", overrides={"sun.elevation_deg": 45.0})
    assert scene.config.sun.elevation_deg == 45.0
    with pytest.raises(ConfigError, match="nearest valid key: 'sun.elevation_deg'"):
        wc.load_scene(CONFIGS / "ocean.toml", overrides={"sun.elevation": 45.0})
    with pytest.raises(ConfigError, match="must be a dotted name"):
        wc.load_scene(CONFIGS / "ocean.toml", overrides={1: 2})


def test_numpy_values_in_python_overrides_are_their_python_numbers():
    """np.int64(64), np.float32(0.2) and np.array([450., 550.]) from a numpy script load as 64, 0.2 and
    [450, 550] (they had been refused as 'the wrong type; expected an integer')."""
    scene = wc.load_scene(None, {"sky.model": "uniform", "sky.sampling": "cones",
                                 "sky.surface_resolution": np.int64(64),
                                 "sky.diffuse_fraction": np.float32(0.25),
                                 "optics.wavelengths": np.array([450.0, 550.0])})
    assert scene.config.sky.surface_resolution == 64 and type(scene.config.sky.surface_resolution) is int
    assert scene.config.sky.diffuse_fraction == 0.25
    assert scene.config.optics.wavelengths.list_nm == (450.0, 550.0)


def test_a_run_that_fails_before_its_first_frame_leaves_no_folder(capsys, tmp_path):
    """A floor the waves reach is found as the first frame renders, after the folder was made: the
    folder goes with the error (an empty one had been left behind)."""
    _fails_cleanly(capsys, tmp_path, [str(CONFIGS / "ocean.toml"), *SMALL, "--set", "floor.depth_m=1e-6"],
                   "floor.depth_m = 1e-06 is too shallow")
    nested = tmp_path / "made" / "by" / "the run"  # the folders above it that the run made go too
    assert main(["render", str(CONFIGS / "ocean.toml"), *SMALL, "--set", "floor.depth_m=1e-6",
                 "--out", str(nested), "--device", "cpu"]) == 2
    assert not (tmp_path / "made").exists()


def test_a_render_and_a_sweep_do_not_share_a_folder_unasked(capsys, tmp_path):
    """A render into a sweep's folder, or a sweep into a render's, is one line naming --force (each had
    checked for its own kind of outputs only and written beside the other's)."""
    from warpcaustics.batch.sweep import load_sweep, run_sweep

    sweep_dir, render_dir = tmp_path / "sweep", tmp_path / "render"
    sweep_dir.mkdir()
    (sweep_dir / "sweep.json").write_text("{}")
    render = ["render", str(CONFIGS / "ocean.toml"), *SMALL, "--device", "cpu"]
    assert main([*render, "--out", str(sweep_dir)]) == 2
    assert "holds a sweep's results" in capsys.readouterr().err
    assert sorted(p.name for p in sweep_dir.iterdir()) == ["sweep.json"]
    assert main([*render, "--out", str(render_dir), "--quiet"]) == 0
    path = tmp_path / "s.toml"
    path.write_text(f'base = "{(CONFIGS / "ocean.toml").as_posix()}"\n[set]\n"water.resolution" = 32\n')
    with pytest.raises(wc.WarpcausticsError, match="holds a render's outputs"):
        run_sweep(load_sweep(path), render_dir, workers=1, device="cpu", quiet=True)


def test_a_table_override_merges_into_the_table():
    """``--set 'water={wind_speed_m_s=3.0}'`` changes that key alone, as ``water.wind_speed_m_s=3.0``
    does (it had put every other [water] key back to its default), and the caller's dict is left as
    it was."""
    dotted = wc.load_scene(CONFIGS / "ocean.toml", {"water.wind_speed_m_s": 3.0}).config
    given = {"water": {"wind_speed_m_s": 3.0}}
    table = wc.load_scene(CONFIGS / "ocean.toml", {**given, "water.seed": 7}).config
    assert table == dotted
    assert table.water.resolution == 256 and table.water.extent_m == 16.0  # the file's, not the defaults
    assert given == {"water": {"wind_speed_m_s": 3.0}}
    place = {"datetime": "2009-07-14T11:30:00+02:00", "latitude_deg": 43.7, "longitude_deg": 7.3}
    by_table = wc.load_scene(CONFIGS / "ocean.toml", {"sun": place}).config.sun  # replaces the file's angles
    by_keys = wc.load_scene(CONFIGS / "ocean.toml", {f"sun.{k}": v for k, v in place.items()}).config.sun
    assert by_table == by_keys


def test_a_wavelengths_table_replaces_the_bins_of_a_resolved_config():
    """optics.wavelengths is one value: a table given for it replaces a resolved config's (whose
    list_nm would otherwise win over the new bins, in silence)."""
    from warpcaustics.config import config_to_dict
    from warpcaustics.config.loading import config_from_dict

    resolved = config_to_dict(wc.load_scene(ROOT / "configs/field/darecki2011.toml").config)
    assert resolved["optics"]["wavelengths"]["list_nm"] == [443.0, 532.0, 670.0]
    cfg = config_from_dict(resolved, {"optics.wavelengths": {"min_nm": 400.0, "max_nm": 700.0, "bins": 8}})
    assert cfg.optics.wavelengths.list_nm == () and cfg.optics.wavelengths.bins == 8


def test_run_json_refuses_an_integration_its_frames_cannot_hold():
    """A sweep's or the API's animation too short for stats.integration_s (⌈T/dt⌉ + 3 frames) is one
    WarpcausticsError from the writer (the render command refuses it before rendering), not the
    integrated statistics left out in silence."""
    from types import SimpleNamespace

    from warpcaustics.io.run_json import time_statistics

    stats = wc.load_scene(None, {"stats.integration_s": 0.1}).config.stats
    scene = SimpleNamespace(config=SimpleNamespace(stats=stats))
    first = SimpleNamespace(scene=scene, map_center_m=(0.0, 0.0))
    frames = [{"time_s": i / 30.0, "statistics": {"probe_irradiance_w_m2": [1.0 + 0.1 * (i % 2)]}}
              for i in range(8)]
    with pytest.raises(wc.WarpcausticsError, match="needs 6 frames"):
        time_statistics(frames[:5], first)
    assert time_statistics(frames[:6], first)["integrated"]["samples"] == 3


def test_render_writes_complete_outputs(tmp_path, capsys):
    """render writes an EXR whose bands are the floor map (image row 0 = largest y), a PNG, run.json
    and the manifest of what it wrote."""
    import OpenEXR

    out = tmp_path / "out"
    assert main(["render", str(CONFIGS / "ocean.toml"), *SMALL, "--out", str(out),
                 "--device", "cpu"]) == 0
    assert sorted(p.name for p in out.iterdir()) == ["frame_0000.exr", "frame_0000.png", "outputs.json",
                                                     "run.json"]
    assert json.loads((out / "outputs.json").read_text())["files"] == ["frame_0000.exr", "frame_0000.png",
                                                                       "run.json"]
    run = json.loads((out / "run.json").read_text())
    assert run["config"]["water"]["resolution"] == 32 and run["device"] == "cpu"
    assert {"warp-lang", "numpy", "warpcaustics"} <= set(run["versions"])
    assert {"water", "refraction", "floor_caustics"} <= set(run["frames"][0]["timings_s"])

    scene = wc.load_scene(CONFIGS / "ocean.toml", {"water.resolution": 32,
                                                        "caustics.map_resolution": 32,
                                                        "optics.wavelengths.bins": 4})
    result = wc.render(scene, device="cpu")
    with OpenEXR.File(str(out / "frame_0000.exr"), separate_channels=True) as exr:
        channels = {name: np.array(ch.pixels) for name, ch in exr.channels().items()}
        header = dict(exr.header())
    names = [f"S0.{w:.6f}".replace(".", ",").replace("S0,", "S0.") + "nm" for w in result.wavelengths_nm]
    assert names[0] == "S0.437,500000nm"
    assert {"R", "G", "B", *names} <= set(channels)
    assert header["spectralLayoutVersion"] == "1.0"
    for k, name in enumerate(names):
        np.testing.assert_allclose(channels[name], result.floor_irradiance[k, ::-1], rtol=1e-6)
    assert (out / "frame_0000.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_device_environment_variable(tmp_path, monkeypatch):
    """$WARPCAUSTICS_DEVICE picks the device when --device is not given."""
    monkeypatch.setenv("WARPCAUSTICS_DEVICE", "cpu")
    scene = wc.load_scene(CONFIGS / "ocean.toml", {"water.resolution": 32,
                                                        "caustics.map_resolution": 16,
                                                        "optics.wavelengths.bins": 2})
    assert wc.render(scene).device == "cpu"
    monkeypatch.setenv("WARPCAUSTICS_DEVICE", "tpu")
    with pytest.raises(wc.WarpcausticsError, match="WARPCAUSTICS_DEVICE"):
        wc.render(scene)


def test_cli_help_and_entry_point():
    """The installed console script answers --help for itself and each command."""
    for args in ([], ["render"], ["info"]):
        proc = subprocess.run([sys.executable, "-m", "warpcaustics", *args, "--help"],
                              capture_output=True, text=True, cwd=ROOT, env=os.environ.copy())
        assert proc.returncode == 0 and "usage:" in proc.stdout


def test_import_is_light():
    """``import warpcaustics`` does not pull in Warp, colour-science, OpenEXR or pyvista."""
    code = ("import sys, warpcaustics; heavy = {'warp', 'colour', 'OpenEXR', 'pyvista'} & set(sys.modules);"
            "print(sorted(heavy))")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert proc.stdout.strip() == "[]"


def test_animation_writes_numbered_frames(tmp_path):
    """--frames N --fps F writes N numbered frames at t = k/F and lists them in run.json."""
    out = tmp_path / "anim"
    assert main(["render", str(CONFIGS / "ocean.toml"), *SMALL, "--out", str(out),
                 "--device", "cpu", "--frames", "3", "--fps", "4"]) == 0
    run = json.loads((out / "run.json").read_text())
    assert [f["time_s"] for f in run["frames"]] == [0.0, 0.25, 0.5]
    assert {f"frame_{k:04d}.exr" for k in range(3)} <= {p.name for p in out.iterdir()}
    # The ocean moves: consecutive frames differ.
    assert (out / "frame_0000.png").read_bytes() != (out / "frame_0001.png").read_bytes()


def test_failed_write_leaves_nothing(tmp_path):
    """A write that fails half-way leaves neither the file nor its temporary behind."""
    from warpcaustics.io.files import atomic_path

    target = tmp_path / "frame_0000.exr"
    with pytest.raises(RuntimeError), atomic_path(target) as tmp:
        tmp.write_bytes(b"half")
        raise RuntimeError("disk full")
    assert list(tmp_path.iterdir()) == []


def _npz_named_npy(path):
    np.savez(path.with_suffix(".npz"), a=np.zeros((8, 8)))
    path.with_suffix(".npz").rename(path)


@pytest.mark.parametrize(("writer", "needle"), [
    (lambda p: p.write_bytes(b""), "not a readable .npy"),
    (_npz_named_npy, ".npz"),
    (lambda p: np.save(p, np.zeros((8, 8), complex)), "real numbers"),
])
def test_heightfield_unreadable_files(capsys, tmp_path, writer, needle):
    """An empty file, an .npz archive or complex heights are one-line errors, not tracebacks."""
    writer(tmp_path / "h.npy")
    cfg = _write(tmp_path, "[water]\nmodel = 'heightfield'\nfile = 'h.npy'\n")
    _fails_cleanly(capsys, tmp_path, [cfg], "water.file", needle)


@pytest.mark.parametrize("time_args", [["--time", "nan"], ["--time", "inf"], ["--time", "1e39"],
                                       ["--frames", "2", "--fps", "1e-308"]])
def test_non_finite_time_is_refused(capsys, tmp_path, time_args):
    """--time (and the animation's last frame) must be a finite number of seconds within ±1e9: past
    float32's range the surface's sweep overflowed inside the render, after the folder was made."""
    _fails_cleanly(capsys, tmp_path, [str(CONFIGS / "ocean.toml"), *SMALL, *time_args], "--time")


@pytest.mark.parametrize(("integration", "frames"), [("10", "3"), ("0.05", "3")])
def test_an_integration_the_animation_cannot_hold_is_refused_before_rendering(capsys, tmp_path, integration,
                                                                               frames):
    """stats.integration_s over a 3-frame animation at 30 fps: 10 s raised inside run.json's writer after
    every frame was written, 0.05 s left the integrated statistics out in silence; both are one line
    naming the frames needed (⌈T·fps⌉ + 3), before any output."""
    needed = "303" if integration == "10" else "5"
    _fails_cleanly(capsys, tmp_path, [str(CONFIGS / "ocean.toml"), *SMALL, "--frames", frames,
                                      "--set", f"stats.integration_s={integration}"],
                   "stats.integration_s", f"--frames ≥ {needed}")


def test_the_walked_spreads_photons_are_counted_and_named_in_the_memory_check(monkeypatch):
    """The walked beam spread's photons are in the host memory the check asks for (a render with 2²⁶
    of them had failed for lack of memory blaming the map's keys, "needs 0.00 GiB"): the estimate a
    photon is at least the walk's own peak, measured here by tracemalloc (b·D ≈ 4, 3 bands), and not
    above twice it; a render that does not fit is refused before anything runs, naming
    optics.beam_spread_photons."""
    import tracemalloc

    from warpcaustics import device as devices
    from warpcaustics.config import PhaseFunctionKind
    from warpcaustics.optics.beam_spread import walk_column
    from warpcaustics.optics.phase import phase_quadrature
    from warpcaustics.pipeline import HOST_BYTES_PER_SPREAD_PHOTON, Renderer, host_bytes, memory_fix

    theta, weight = phase_quadrature(PhaseFunctionKind.PETZOLD, None, "HAOCE 11")
    photons = 1 << 15
    tracemalloc.start()
    walk_column(theta, weight, np.array([0.02, 0.05, 0.4]), np.array([0.6, 0.57, 0.54]), 0.9, 6.73, 1.34,
                photons, 1)
    peak = tracemalloc.get_traced_memory()[1] / photons
    tracemalloc.stop()
    assert peak <= HOST_BYTES_PER_SPREAD_PHOTON <= 2 * peak, peak

    walked = {"optics.scattering": "small_angle", "optics.beam_spread": "walk", "optics.wavelengths": "rgb",
              "water.resolution": 32, "caustics.map_resolution": 32}
    few = wc.load_scene(CONFIGS / "ocean.toml", {**walked, "optics.beam_spread_photons": 1024})
    many = wc.load_scene(CONFIGS / "ocean.toml", {**walked, "optics.beam_spread_photons": 1 << 26})
    assert host_bytes(many) - host_bytes(few) > ((1 << 26) - 1024) * HOST_BYTES_PER_SPREAD_PHOTON
    assert "optics.beam_spread_photons" in memory_fix(many.config)
    wells = wc.load_scene(CONFIGS / "ocean.toml", {**walked, "optics.beam_spread": "wells"})
    assert "beam_spread_photons" not in memory_fix(wells.config) and host_bytes(wells) < host_bytes(few)
    monkeypatch.setattr(devices, "free_bytes", lambda device: host_bytes(few) + (1 << 30))
    Renderer(few, "cpu")  # fits
    with pytest.raises(wc.DeviceError, match="lower optics.beam_spread_photons"):
        Renderer(many, "cpu")


def test_wavelengths_outside_the_data_fail_at_load():
    """Bins beyond the optical data's range are refused when the scene is loaded, naming the range."""
    with pytest.raises(ConfigError, match="outside the Pope & Fry 1997 absorption data"):
        wc.load_scene(None, {"optics.wavelengths.max_nm": 760.0})


def test_results_of_earlier_frames_stay_intact():
    """A Renderer reuses its device buffers; results already returned must not change with the next
    frame (on the CPU, Warp's .numpy() is a view)."""
    scene = wc.load_scene(CONFIGS / "ocean.toml", {"water.resolution": 32, "caustics.map_resolution": 16,
                                                        "optics.wavelengths.bins": 2})
    renderer = wc.Renderer(scene, "cpu")
    first = renderer.render(0.0)
    kept = first.floor_irradiance.copy()
    renderer.render(1.0)
    np.testing.assert_array_equal(first.floor_irradiance, kept)


def test_spectral_exr_reads_back_through_colour_science_fichet_reader(tmp_path):
    """The spectral EXR is a valid Fichet et al. (2021) file: colour-science's reader (needs the
    openimageio test extra) returns our wavelengths, emissive units and the floor map, image row 0
    being the largest y."""
    pytest.importorskip("OpenImageIO")
    import colour

    scene = wc.load_scene(CONFIGS / "ocean.toml", {"water.resolution": 32, "caustics.map_resolution": 16,
                                                        "optics.wavelengths.bins": 4})
    result = wc.render(scene, device="cpu")
    result.save(tmp_path)
    components, spec = colour.io.read_spectral_image_Fichet2021(tmp_path / "frame_0000.exr",
                                                                additional_data=True)
    wavelengths, values = components["S0"]
    assert spec.is_emissive and not spec.is_polarised
    np.testing.assert_allclose(wavelengths, result.wavelengths_nm)
    np.testing.assert_allclose(np.moveaxis(values, -1, 0), result.floor_irradiance[:, ::-1], rtol=1e-6)


def test_merged_key_is_refused_naming_its_successor(capsys, tmp_path):
    """caustics.sunmap_disk_deg, merged into sun.angular_diameter_deg, is refused in a file and in an
    override with one line that names the key to set instead."""
    message = "caustics.sunmap_disk_deg was merged into sun.angular_diameter_deg; set that instead"
    _fails_cleanly(capsys, tmp_path, [_write(tmp_path, "[caustics]\nsunmap_disk_deg = 0.53\n")], message)
    _fails_cleanly(capsys, tmp_path, [str(CONFIGS / "ocean.toml"), "--set", "caustics.sunmap_disk_deg=1"],
                   message)
    with pytest.raises(ConfigError, match="sun.angular_diameter_deg"):
        wc.load_scene(None, {"caustics.method": "sunmap", "caustics.sunmap_disk_deg": 2.0})


@pytest.mark.parametrize("diameter_deg", [0.0, 0.53, 2.0])
def test_sun_map_draws_the_suns_disk(diameter_deg):
    """The sun map's disk (full brightness inside, the halo's fall-off starting at its edge) is the
    sun's, sun.angular_diameter_deg: its kernel parameters hold that angular radius (float32)."""
    import math

    from warpcaustics.caustics.sunmap import SunMapCaustics

    scene = wc.load_scene(None, {"caustics.method": "sunmap", "caustics.map_resolution": 8,
                                 "sun.angular_diameter_deg": diameter_deg})
    params = SunMapCaustics(scene.config, scene.sun_direction, 1.333, "cpu", periodic=True).params
    radius = 0.5 * math.radians(diameter_deg)
    # the struct stores float32: one rounding of the radius and of its cosine
    assert params.disk_rad == pytest.approx(radius, rel=1e-7, abs=1e-12)
    assert params.cos_disk == pytest.approx(math.cos(radius), rel=1e-7)
    assert params.halo_rad == pytest.approx(0.5 * math.radians(5.3), rel=1e-7)
