"""Bad input a second fuzz (2026-12-07) found still crashing, hanging or leaving folders behind: the
commands' output folders, a damaged sweep summary, sweeps that list a task twice or far too many, a
config that is not a regular file, the Python API given the wrong types, and a water column too deep
for the small-angle transfer. Each is now one line (exit 2 from the CLI, a WarpcausticsError from
Python) before anything renders. The CLI runs in-process here (``cli.main``)."""

from __future__ import annotations

import json
import os

import numpy as np
import pytest

import warpcaustics as wc
from warpcaustics import cli
from warpcaustics.batch.sweep import MAX_SWEEP_FRAMES, load_sweep

from helpers import CONFIGS

TINY = ["--device", "cpu", "--set", "water.resolution=16", "--set", "caustics.map_resolution=16"]


def one_line_error(capsys, argv: list[str], *needles: str) -> str:
    """``cli.main(argv)`` exits 2 with one stderr line naming each of ``needles``."""
    assert cli.main(argv) == 2
    lines = [line for line in capsys.readouterr().err.splitlines() if line.startswith("warpcaustics:")]
    assert len(lines) == 1 and lines[0].startswith("warpcaustics: error: "), lines
    for needle in needles:
        assert needle in lines[0], lines[0]
    return lines[0]


@pytest.mark.parametrize("command", [["study", str(CONFIGS / "study.toml")],
                                     ["compare", str(CONFIGS / "ocean.toml"), *TINY]])
def test_an_output_folder_that_cannot_be_made_is_refused_before_rendering(tmp_path, capsys, command):
    """study and compare made their folder only after every render: a file in the way crashed them
    then. Now it is one line, before anything renders."""
    (tmp_path / "a_file").write_text("")
    out = tmp_path / "a_file" / "x"
    one_line_error(capsys, [*command, "--out", str(out)], "cannot be created", "Not a directory")


def test_a_failed_compare_leaves_no_folder(tmp_path, capsys):
    """A compare that fails after its folder was made removes it (nothing is left as if a result)."""
    out = tmp_path / "new" / "x"
    one_line_error(capsys, ["compare", str(CONFIGS / "ocean_floor.toml"), "--out", str(out), *TINY,
                            "--methods", "photons"], "floor.shape=flat", "camera.enabled=false")
    assert not (tmp_path / "new").exists()


@pytest.mark.parametrize("command", [["render", str(CONFIGS / "ocean.toml")],
                                     ["study", str(CONFIGS / "study.toml")],
                                     ["compare", str(CONFIGS / "ocean.toml")],
                                     ["field", "gernez2009", str(CONFIGS / "field" / "gernez2009.toml")]])
def test_an_empty_out_is_refused(tmp_path, capsys, command, monkeypatch):
    """``--out ""`` had written into the working folder."""
    monkeypatch.chdir(tmp_path)
    one_line_error(capsys, [*command, "--out", ""], "--out is empty")
    assert list(tmp_path.iterdir()) == []


def test_compare_with_no_methods_is_refused(tmp_path, capsys):
    one_line_error(capsys, ["compare", str(CONFIGS / "ocean.toml"), "--out", str(tmp_path / "c"),
                            "--methods", ",,"], "--methods", "names no method")


@pytest.mark.parametrize("content,needle", [
    (b"garbage\xff\n", "cannot be read as a sweep summary"),
    (b"id,frame,time_s,floor.depth_m,floor_w_m2\nx,0,0,1.0,abc\n", "floor_w_m2 = 'abc' is not a number"),
    (b"time_s\n0\n", "no 'id'"),
    (None, "Is a directory"),
])
def test_report_on_a_damaged_summary_is_one_line(tmp_path, capsys, content, needle):
    if content is None:
        (tmp_path / "summary.csv").mkdir()
    else:
        (tmp_path / "summary.csv").write_bytes(content)
    one_line_error(capsys, ["report", str(tmp_path)], needle, "rerun the sweep")


def sweep_file(tmp_path, body: str):
    path = tmp_path / "sweep.toml"
    path.write_text(f'base = "{(CONFIGS / "ocean.toml").as_posix()}"\n{body}')
    return path


@pytest.mark.parametrize("body,needle", [
    ('[grid]\n"floor.depth_m" = [1.0, 2.0, 1.0]\n', "lists 1.0 twice"),
    ('[grid]\n"floor.depth_m" = [1.0, 2.0]\n[zip]\n"floor.depth_m" = [3.0, 4.0]\n',
     "in both [grid] and [zip]"),
    ('[zip]\n"floor.depth_m" = [1.0, 2.0, 1.0]\n"sun.elevation_deg" = [40.0, 50.0, 40.0]\n',
     "entry 3 repeats entry 1"),
    (f'[grid]\n"floor.depth_m" = [1.0, 2.0]\n[frames]\ncount = {MAX_SWEEP_FRAMES}\n', "more than"),
])
def test_a_sweep_listing_a_task_twice_or_too_many_is_refused(tmp_path, body, needle):
    """The same task twice raced on one folder (raw FileNotFoundErrors); a hundred million frames
    hung while the tasks were listed."""
    with pytest.raises(wc.ConfigError, match=needle.replace("[", r"\[").replace("]", r"\]")):
        load_sweep(sweep_file(tmp_path, body))


def test_field_frames_past_the_bound_are_refused_at_once(tmp_path, capsys):
    one_line_error(capsys, ["field", "gernez2009", str(CONFIGS / "field" / "gernez2009.toml"), "--out",
                            str(tmp_path / "f"), "--frames", "100000000", "--quick"], "--frames = 100000000")


def test_a_pool_sweep_too_short_for_its_integration_fails_before_rendering(tmp_path):
    """The render command refuses it up front; a sweep's pool task now fails the same way, without
    rendering its frames and leaving a checkpoint to repeat them; a sweep of that task alone is
    refused as it loads (nothing of it would run)."""
    path = tmp_path / "sweep.toml"
    base = f'base = "{(CONFIGS / "pool.toml").as_posix()}"\n'
    path.write_text(base + '[grid]\n"stats.integration_s" = [10.0, 0.0]\n[frames]\ncount = 3\n')
    short, fine = load_sweep(path).tasks
    assert short.error is not None and "stats.integration_s = 10 needs frames.count" in short.error
    assert fine.error is None
    path.write_text(base + '[set]\n"stats.integration_s" = 10.0\n[frames]\ncount = 3\n')
    with pytest.raises(wc.ConfigError, match="every variant of sweep.toml fails the same way.*needs frames"):
        load_sweep(path)


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="no /dev/zero here")
def test_a_config_that_is_a_device_is_refused(capsys):
    """``config /dev/zero`` read forever (a pipe, as from a shell's process substitution, still reads)."""
    one_line_error(capsys, ["config", "/dev/zero"], "is a device")


def test_a_config_with_a_byte_order_mark_loads(tmp_path):
    path = tmp_path / "bom.toml"
    path.write_bytes(b"\xef\xbb\xbf[water]\nresolution = 32\n")
    assert wc.load_scene(path).config.water.resolution == 32


@pytest.fixture(scope="module")
def scene():
    return wc.load_scene(CONFIGS / "ocean.toml", {"water.resolution": 16, "caustics.map_resolution": 16})


@pytest.mark.parametrize("call,needle", [
    (lambda s: wc.load_scene(3), "load_scene() takes the path"),
    (lambda s: wc.load_scene(CONFIGS / "ocean.toml", "water.resolution=16"), "overrides must be a dict"),
    (lambda s: wc.render(str(CONFIGS / "ocean.toml")), "takes a Scene"),
    (lambda s: wc.Renderer("x"), "takes a Scene"),
    (lambda s: wc.render(s, time_s="0", device="cpu"), "time_s = '0' must be a number"),
    (lambda s: wc.render(s, time_s=None, device="cpu"), "time_s = None must be a number"),
    (lambda s: wc.render(s, device=1), "device = 1 must be a name"),
])
def test_the_python_api_names_a_wrong_type(scene, call, needle):
    """Wrong types had raised TypeError or AttributeError from inside the package."""
    with pytest.raises(wc.WarpcausticsError, match=needle.replace("(", r"\(").replace(")", r"\)")):
        call(scene)


def test_a_numpy_time_still_renders(scene):
    assert np.isfinite(wc.render(scene, time_s=np.float32(0.5), device="cpu").floor_irradiance).all()


def test_saving_and_receivers_of_a_result_fail_in_one_line(scene, tmp_path):
    result = wc.render(scene, device="cpu")
    (tmp_path / "a_file").write_text("")
    with pytest.raises(wc.WarpcausticsError, match="cannot save into"):
        result.save(tmp_path / "a_file")
    for frame in (-1, 1.5, True):  # -1 had written frame_-001.exr
        with pytest.raises(wc.WarpcausticsError, match="must be a whole number from 0"):
            result.save(tmp_path / "f", frame=frame)
    assert not (tmp_path / "f").exists()
    with pytest.raises(wc.WarpcausticsError, match="needs caustics.method = 'photons' or 'beams'"):
        result.receiver_irradiance(0)


def test_cuda_minus_one_is_refused():
    from warpcaustics.device import _cuda_index
    from warpcaustics.errors import DeviceError

    assert _cuda_index("cuda:1") == 1
    with pytest.raises(DeviceError, match="cuda:-1"):
        _cuda_index("cuda:-1")


@pytest.mark.parametrize("name", ["cuda:x", "cuda:-1", "cuda:"])
def test_a_malformed_cuda_name_is_told_its_form_with_or_without_a_gpu(name):
    """The name's fix does not depend on the machine: it had been told 'no CUDA device' without one."""
    from warpcaustics.device import resolve_device
    from warpcaustics.errors import DeviceError

    with pytest.raises(DeviceError, match=f"device = '{name}' is not allowed; use cuda:N"):
        resolve_device(name)


def test_a_column_too_deep_for_the_small_angle_transfer_is_refused_before_rendering(tmp_path, capsys):
    """Turbid water 100 m deep: the unscattered map underflows float32 and the transfer had printed
    overflow warnings, then walked its spread for minutes or ended in 'not finite'."""
    one_line_error(capsys, ["render", str(CONFIGS / "ocean.toml"), "--out", str(tmp_path / "r"), *TINY,
                            "--set", "optics.scattering=small_angle",
                            "--set", "optics.water_type=turbid_harbor",
                            "--set", "floor.depth_m=100"], "floor.depth_m = 100", "attenuation lengths",
                   "optics.scattering = 'multiple'")
    assert not (tmp_path / "r").exists()


@pytest.mark.parametrize("overrides,needle", [
    ({"caustics.method": "wave3d", "caustics.wave3d_resolution": 16}, "to at least 48"),
    ({"sun.datetime": "2009-07-14", "sun.latitude_deg": 43.0, "sun.longitude_deg": 7.0}, "no time of day"),
    ({"sun.datetime": "2009-07-14Z", "sun.latitude_deg": 43.0, "sun.longitude_deg": 7.0}, "no time of day"),
])
def test_a_hint_gives_a_value_that_is_accepted(overrides, needle):
    """The wave3d hint had asked for a value below the key's own minimum, and the datetime hint for
    '2009-07-14+00:00', which it then refused too."""
    with pytest.raises(wc.ConfigError, match=needle):
        wc.load_scene(CONFIGS / "ocean.toml", overrides)


def test_heights_in_a_file_are_bounded_as_other_lengths(tmp_path):
    path = tmp_path / "h.npy"
    np.save(path, np.full((16, 16), 1e30, np.float32))
    with pytest.raises(wc.ConfigError, match="within ±100000 m"):
        wc.load_scene(CONFIGS / "ocean.toml", {"water.model": "heightfield", "water.file": str(path),
                                               "water.resolution": 16})


@pytest.mark.parametrize("body,needle", [
    ("depths_m = [1.0, 1.0]", "two different depths"),
    ("depths_m = [1.0, 2.0, 1.0]", "lists 1.0 twice"),
    ('depths_m = [1.0, 2.0]\n[overrides]\n"floor.depth_m" = 3.0', "sets floor.depth_m, which the study sets"),
])
def test_a_study_that_could_only_write_nonsense_is_refused(tmp_path, body, needle):
    """Two equal depths had fitted an attenuation over nothing (a RankWarning, then a number), and an
    override of a key the study sets was silently replaced."""
    from warpcaustics.batch.study import load_study

    path = tmp_path / "study.toml"
    path.write_text(f'scene = "{(CONFIGS / "ocean.toml").as_posix()}"\nwater_types = ["jerlov_IB"]\n'
                    f"sun_elevations_deg = [40.0]\n{body}\n")
    with pytest.raises(wc.ConfigError, match=needle):
        load_study(path)


def test_preview_names_its_output_problem_not_pyvista(tmp_path, capsys):
    """A folder named like the PNG, or one that cannot be written, had been reported as pyvista
    failing to render off screen, after the render."""
    (tmp_path / "dir.png").mkdir()
    one_line_error(capsys, ["preview", str(CONFIGS / "ocean.toml"), "--out", str(tmp_path / "dir.png"),
                            *TINY], "is a folder")


def test_preview_keeps_vtk_s_own_warnings_off_the_terminal(tmp_path, capfd, monkeypatch):
    """Without an X server VTK logged "bad X server connection" from C++ before every preview,
    though the picture was drawn; its warnings stay off stderr now."""
    monkeypatch.delenv("DISPLAY", raising=False)
    assert cli.main(["preview", str(CONFIGS / "ocean.toml"), "--out", str(tmp_path / "p.png"), *TINY]) == 0
    err = capfd.readouterr().err
    assert (tmp_path / "p.png").stat().st_size > 0
    assert "bad X server connection" not in err and "WARN|" not in err


def test_a_ray_address_without_the_ray_executor_is_refused(tmp_path, capsys):
    one_line_error(capsys, ["sweep", str(CONFIGS / "sweeps" / "water_types.toml"), "--out",
                            str(tmp_path / "s"), "--address", "auto"], "--executor ray")


def test_a_spectrum_file_without_a_header_keeps_its_first_row(tmp_path):
    """The first line was skipped as a header even when it was data."""
    from warpcaustics.optics.spectra import read_spectrum_csv

    (tmp_path / "bare.csv").write_text("400,1.0\n500,1.2\n700,0.9\n")
    (tmp_path / "headed.csv").write_text("wavelength_nm,irradiance\n400,1.0\n500,1.2\n700,0.9\n")
    for name in ("bare.csv", "headed.csv"):
        nm, values = read_spectrum_csv(name, tmp_path)
        assert nm.tolist() == [400.0, 500.0, 700.0] and values.tolist() == [1.0, 1.2, 0.9]


def test_a_spectrum_of_1e308_is_refused_before_it_overflows(tmp_path):
    (tmp_path / "big.csv").write_text("nm,w\n400,1e308\n700,1e308\n")
    with pytest.raises(wc.ConfigError, match="sun.file .* at most 1e\\+30"):
        wc.load_scene(CONFIGS / "ocean.toml", {"sun.spectrum": "file", "sun.file": str(tmp_path / "big.csv")})


def test_a_spectrum_file_of_several_columns_is_refused_not_read_by_its_first(tmp_path):
    """A third column (ASTM G173's layout: three spectra) had been ignored without a word."""
    path = tmp_path / "g173.csv"
    path.write_text("nm,etr,global,direct\n380,1.1,0.4,0.3\n780,1.2,1.0,0.9\n")
    with pytest.raises(wc.ConfigError, match="sun.file = .* has 4 columns; it needs two, wavelength_nm,"):
        wc.load_scene(CONFIGS / "ocean.toml", {"sun.spectrum": "file", "sun.file": str(path)})


def receiver_scene(mesh):
    return {"caustics.method": "photons", "receivers": [{"mesh": str(mesh), "translate_m": [0.0, 0.0, -1.0]}]}


@pytest.mark.parametrize("name,content,needle", [
    ("faces.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n" + "f 1 2 1000\n" * 50,
     "refer to vertex 1000, but it holds 3"),
    ("nan.obj", "v nan 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "not finite"),
    ("far.obj", "v 1e30 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "within ±100000 m"),
    ("cut.stl", b"\0" * 80 + (50_000_000).to_bytes(4, "little") + b"\0" * 50, "declares 50000000 triangles"),
    ("picture.stl", b"\x89PNG\r\n\x1a\n" + bytes(range(256)) * 2,
     "not a whole binary STL .cut short, or not a"),
])
def test_a_broken_receiver_mesh_is_one_line(tmp_path, name, content, needle):
    """Faces naming vertices the file lacks had crashed the process in VTK (a segfault) or raised an
    IndexError; a binary STL cut short, NaN and far vertices had rendered."""
    path = tmp_path / name
    path.write_bytes(content if isinstance(content, bytes) else content.encode())
    with pytest.raises(wc.ConfigError, match=r"receivers\[0\].mesh = .*" + needle):
        wc.load_scene(CONFIGS / "ocean.toml", receiver_scene(path))


@pytest.mark.parametrize("suffix", [".stl", ".obj"])
def test_a_mesh_file_with_a_byte_order_mark_reads_as_without(tmp_path, suffix):
    """VTK's STL reader read nothing of an ASCII STL an editor had saved with a UTF-8 BOM ("has no
    triangles"); its OBJ reader drops the line the BOM sits on (here the first vertex)."""
    import pyvista as pv

    from warpcaustics.config import ReceiverConfig
    from warpcaustics.scene.receivers import load_receiver_mesh

    sphere = pv.Sphere(theta_resolution=8, phi_resolution=6).triangulate()
    plain = tmp_path / f"plain{suffix}"
    sphere.save(plain, binary=False) if suffix == ".stl" else sphere.save(plain)
    text = plain.read_bytes()
    if suffix == ".obj":
        text = b"".join(line for line in text.splitlines(keepends=True) if not line.startswith(b"#"))
        plain.write_bytes(text)
    assert text[:1] in (b"s", b"v")  # the BOM goes on the line that matters
    bom = tmp_path / f"bom{suffix}"
    bom.write_bytes(b"\xef\xbb\xbf" + text)
    a = load_receiver_mesh(ReceiverConfig(mesh=str(plain)), tmp_path, "receivers[0]")
    b = load_receiver_mesh(ReceiverConfig(mesh=str(bom)), tmp_path, "receivers[0]")
    assert len(a.triangles) == sphere.n_cells
    np.testing.assert_array_equal(a.triangles, b.triangles)
    np.testing.assert_array_equal(a.points, b.points)


def test_a_binary_stl_whose_header_starts_with_the_mark_is_left_whole(tmp_path):
    """A binary STL's 80-byte header is any bytes, "solid" included: it must not lose three of them."""
    import pyvista as pv

    from warpcaustics.config import ReceiverConfig
    from warpcaustics.scene.receivers import load_receiver_mesh

    sphere = pv.Sphere(theta_resolution=8, phi_resolution=6).triangulate()
    plain = tmp_path / "plain.stl"
    sphere.save(plain, binary=True)
    data = plain.read_bytes()
    marked = tmp_path / "marked.stl"
    marked.write_bytes(b"\xef\xbb\xbfsolid from an exporter".ljust(80, b" ") + data[80:])
    a = load_receiver_mesh(ReceiverConfig(mesh=str(plain)), tmp_path, "receivers[0]")
    b = load_receiver_mesh(ReceiverConfig(mesh=str(marked)), tmp_path, "receivers[0]")
    assert len(b.triangles) == sphere.n_cells
    np.testing.assert_array_equal(a.points, b.points)


def test_a_file_that_is_no_mesh_says_so(tmp_path):
    path = tmp_path / "picture.obj"
    path.write_bytes(b"\x89PNG\r\n\x1a\n" + bytes(range(256)))
    with pytest.raises(wc.ConfigError, match="no triangles: an empty mesh, or a file pyvista could not make "
                                             "sense of"):
        wc.load_scene(CONFIGS / "ocean.toml", receiver_scene(path))


@pytest.mark.parametrize("content,needle", [(b"", "EOFError"), (None, ".npz archive")])
def test_a_floor_relief_file_numpy_cannot_read_is_one_line(tmp_path, content, needle):
    path = tmp_path / "relief.npy"
    if content is None:
        path = tmp_path / "relief.npz"
        np.savez(path, a=np.zeros((16, 16)))
    else:
        path.write_bytes(content)
    with pytest.raises(wc.ConfigError, match=f"floor.file = .*{needle}"):
        wc.load_scene(CONFIGS / "ocean_floor.toml", {"floor.shape": "file", "floor.file": str(path),
                                                     "camera.enabled": False})


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="no /dev/zero here")
def test_a_spectrum_file_that_is_a_device_is_refused_not_read_forever(tmp_path):
    with pytest.raises(wc.ConfigError, match="floor.albedo_file = '/dev/zero' is not a regular file"):
        wc.load_scene(CONFIGS / "ocean.toml", {"floor.albedo_file": "/dev/zero"})
    with pytest.raises(wc.ConfigError, match="is a folder"):
        wc.load_scene(CONFIGS / "ocean.toml", {"floor.albedo_file": str(tmp_path)})


def test_a_camera_up_float32_cannot_hold_is_refused():
    with pytest.raises(wc.ConfigError, match="camera.up .* too short"):
        wc.load_scene(CONFIGS / "ocean_floor.toml", {"camera.up": [0.0, 0.0, 1e-200]})


def test_a_sweep_refuses_its_configured_device_before_making_its_folder(tmp_path, monkeypatch):
    monkeypatch.setenv("WARPCAUSTICS_DEVICE", "garbage")
    path = tmp_path / "sweep.toml"
    path.write_text(f'base = "{(CONFIGS / "ocean.toml").as_posix()}"\n')
    from warpcaustics.batch.sweep import run_sweep

    with pytest.raises(wc.WarpcausticsError, match="device = 'garbage'"):
        run_sweep(load_sweep(path), tmp_path / "out", quiet=True)
    assert not (tmp_path / "out").exists()


def test_a_floor_relief_above_the_water_is_refused(tmp_path):
    """A 1e4 m spike in floor.file had asked for a floor mesh reaching 4e4 m beyond the patch, refused
    as 'needs about 0.00 GiB' of memory."""
    relief = np.zeros((16, 16))
    relief[0, 0] = 1e4
    np.save(tmp_path / "spike.npy", relief)
    with pytest.raises(wc.ConfigError, match="relief rises to z = .* above the water"):
        wc.Renderer(wc.load_scene(CONFIGS / "ocean_floor.toml", {
            "floor.shape": "file", "floor.file": str(tmp_path / "spike.npy"), "camera.enabled": False,
            "water.resolution": 16, "caustics.map_resolution": 16}), "cpu")


def test_a_summary_row_short_of_cells_is_one_line(tmp_path, capsys):
    (tmp_path / "summary.csv").write_text("id,frame,time_s,floor_w_m2\nabc,0,0.0,101.0\nabd,1,0.5\n")
    one_line_error(capsys, ["report", str(tmp_path)], "other length than the header")


@pytest.mark.parametrize("text", ["0,1\n400,0.2\n500,0.3\n700,0.4\n",  # pandas' unnamed columns
                                  "\ufeff400,0.2\n500,0.3\n700,0.4\n",  # a byte-order mark
                                  "\ufeffwavelength_nm,reflectance\n400,0.2\n500,0.3\n700,0.4\n"])
def test_a_spectrum_header_is_told_from_data(tmp_path, text):
    from warpcaustics.optics.spectra import read_spectrum_csv

    (tmp_path / "a.csv").write_text(text, encoding="utf-8")
    nm, values = read_spectrum_csv("a.csv", tmp_path, "floor.albedo_file", "reflectance", 1.0)
    assert nm.tolist() == [400.0, 500.0, 700.0] and values.tolist() == [0.2, 0.3, 0.4]


def test_a_mesh_in_millimetres_scaled_to_metres_loads(tmp_path):
    """The scene's ±1e5 m bound applies once the mesh is scaled: a 150 m object saved in mm loads."""
    (tmp_path / "mm.obj").write_text("v 0 0 0\nv 150000 0 0\nv 0 150000 0\nf 1 2 3\n")
    scene = wc.load_scene(CONFIGS / "ocean.toml", {"caustics.method": "photons", "receivers": [
        {"mesh": str(tmp_path / "mm.obj"), "scale": [0.001], "translate_m": [0.0, 0.0, -2.0]}]})
    assert scene.config.receivers[0].scale == (0.001,)


def test_info_tells_the_device_a_render_would_take(capsys, monkeypatch):
    """`info` had printed "default device: cpu" for a $WARPCAUSTICS_DEVICE that every render refuses,
    and a blank value had been refused as device = '' where an empty one means auto."""
    monkeypatch.setenv("WARPCAUSTICS_DEVICE", "garbage")
    assert cli.main(["info"]) == 0
    assert "default device: none: device = 'garbage' is not allowed" in capsys.readouterr().out
    monkeypatch.setenv("WARPCAUSTICS_DEVICE", "   ")
    assert cli.main(["info"]) == 0
    assert "default device: " in capsys.readouterr().out
    from warpcaustics.device import resolve_device

    assert resolve_device(None, config_value="cpu") == "cpu"


# A third fuzz (2026-12-08): folders that cannot be written, writes that fail midway ---------------

UNWRITABLE = "/proc/self"
"""A folder no one can create a file in, root included (Linux)."""


@pytest.mark.skipif(not os.path.isdir(UNWRITABLE), reason="no /proc here")
@pytest.mark.parametrize("command", [["render", str(CONFIGS / "ocean.toml"), *TINY],
                                     ["study", str(CONFIGS / "study.toml"), "--device", "cpu"],
                                     ["compare", str(CONFIGS / "ocean.toml"), *TINY],
                                     ["sweep", str(CONFIGS / "sweeps" / "water_types.toml"), *TINY],
                                     ["field", "gernez2009", str(CONFIGS / "field" / "gernez2009.toml"),
                                      "--quick", "--device", "cpu"]])
def test_an_out_folder_that_cannot_be_written_is_refused_before_rendering(capsys, command):
    """An existing --out that cannot be written (read-only, no permission) had given a traceback from
    the first file written (render's claim, OpenEXR's, the sweep's state, after every render of a
    study): now one line, before anything renders."""
    one_line_error(capsys, [*command, "--out", UNWRITABLE], f"--out {UNWRITABLE!r} cannot be written")


def test_a_write_that_fails_midway_is_one_line_and_no_finished_run(tmp_path, capsys, monkeypatch):
    """A full disk as OpenEXR reports it (a RuntimeError, which had escaped as a traceback) fails the
    render in one line naming the frame and --out, and no run.json marks the folder's files a
    finished run."""
    import OpenEXR

    class FullDisk:
        def __init__(self, *args):
            pass

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            return False

        def write(self, name):
            raise RuntimeError(f"Failed to write pixel data to image file \"{name}\".\n"
                               "No space left on device")

    monkeypatch.setattr(OpenEXR, "File", FullDisk)
    out = tmp_path / "r"
    one_line_error(capsys, ["render", str(CONFIGS / "ocean.toml"), "--out", str(out), *TINY],
                   "cannot write frame 0 into --out", "No space left on device")
    assert not (out / "run.json").exists()
    assert not list(out.glob(".*tmp*")), list(out.iterdir())  # no temporary file left either


@pytest.mark.parametrize("files", [[5], [["a"]], ["\u0000"], "frame_0000.exr"])
def test_an_outputs_list_that_is_not_file_names_is_one_line(tmp_path, capsys, files):
    """A damaged outputs.json (entries that are not names, a NUL byte, a string for the list) had
    given a TypeError or ValueError from inside the claim of the folder."""
    out = tmp_path / "r"
    out.mkdir()
    (out / "outputs.json").write_text(json.dumps({"files": files}))
    one_line_error(capsys, ["render", str(CONFIGS / "ocean.toml"), "--out", str(out), *TINY],
                   "outputs.json cannot be read")


def test_a_sweep_whose_state_cannot_be_written_midway_is_one_line(tmp_path, capsys, monkeypatch):
    """A write of the sweep's own state that fails as it goes (a disk that fills) had been a
    traceback from the driver: now one line naming the file and the reason."""
    import errno

    from warpcaustics.batch import sweep

    def full(out_dir, record):
        raise OSError(errno.ENOSPC, "No space left on device", str(out_dir / sweep.MANIFEST))

    monkeypatch.setattr(sweep, "_append", full)
    one = tmp_path / "one.toml"
    one.write_text(f'base = "{(CONFIGS / "ocean.toml").as_posix()}"\n[grid]\n"floor.depth_m" = [1.0]\n')
    one_line_error(capsys, ["sweep", str(one), "--out", str(tmp_path / "s"), "--quiet", *TINY],
                   "manifest.jsonl': No space left on device", "--out")


def test_compare_s_hint_for_a_scene_with_receivers_is_one_that_works(tmp_path, capsys):
    """compare's advice for a scene the flux-ratio reference cannot take had left out the receivers,
    so following it gave the same error again; with the whole advice the comparison runs."""
    line = one_line_error(capsys, ["compare", str(CONFIGS / "pool_pots.toml"), "--out", str(tmp_path / "a"),
                                   *TINY, "--methods", "sunmap"], "receivers=[]")
    fix = line[line.index("--set floor.shape"):].rstrip(")").split()
    sets = [s.strip("'") for s in fix if s != "--set"]
    argv = ["compare", str(CONFIGS / "pool_pots.toml"), "--out", str(tmp_path / "b"), *TINY, "--methods",
            "sunmap", *[a for s in sets for a in ("--set", s)]]
    assert cli.main(argv) == 0, capsys.readouterr().err


def test_compare_keeps_out_of_a_renders_folder_and_drops_its_own_stale_methods(tmp_path, capsys):
    """compare had written its files among a render's (or a sweep's), and a second comparison with
    other --methods left the first one's method folders beside its table."""
    render = tmp_path / "r"
    assert cli.main(["render", str(CONFIGS / "ocean.toml"), "--out", str(render), *TINY, "--quiet"]) == 0
    one_line_error(capsys, ["compare", str(CONFIGS / "ocean.toml"), "--out", str(render), *TINY,
                            "--methods", "sunmap"], "holds a render's or a sweep's results")
    assert not (render / "compare.csv").exists()
    out = tmp_path / "c"
    for methods in ("sunmap", "photons"):
        assert cli.main(["compare", str(CONFIGS / "ocean.toml"), "--out", str(out), *TINY,
                         "--methods", methods]) == 0
    assert sorted(p.name for p in out.iterdir() if p.is_dir()) == ["fluxratio", "photons"]
