"""The frame writers' registry (``warpcaustics.io.frame.WRITERS``): save_frame runs exactly the
writers a frame enables, in the registry's order, and a writer added to it is called like the rest."""

from __future__ import annotations

import os

import pytest

import warpcaustics as wc
from warpcaustics.io import frame as frame_io
from warpcaustics.io.frame import WRITERS, FrameWriter, save_frame

from helpers import CONFIGS


@pytest.fixture(scope="module")
def result():
    """A small flux-ratio frame of the default ocean with the .npz switch on (VTK, NetCDF off)."""
    scene = wc.load_scene(CONFIGS / "ocean.toml", {"water.resolution": 16, "caustics.map_resolution": 16,
                                                        "optics.wavelengths.bins": 4, "output.npz": True})
    return wc.render(scene, device="cpu")


def test_save_frame_runs_the_enabled_writers_in_registry_order(result, tmp_path, monkeypatch):
    """Only enabled writers run, in registry order; the files on disk are exactly the paths returned."""
    calls = []
    for name, writer in list(WRITERS.items()):
        def spy(r, out_dir, *, frame, _name=name, _write=writer.write):
            calls.append(_name)
            return _write(r, out_dir, frame=frame)
        monkeypatch.setitem(WRITERS, name, FrameWriter(spy, writer.enabled))
    paths = save_frame(result, tmp_path, frame=3)
    assert calls == ["floor", "npz"]  # no camera, no comparison; vtk and netcdf switched off
    assert list(paths) == ["exr", "png", "npz"]
    assert sorted(p.name for p in paths.values()) == sorted(os.listdir(tmp_path))
    assert paths["npz"].name == "frame_0003.npz"


def test_a_registered_writer_is_called_and_its_files_returned(result, tmp_path, monkeypatch):
    """A writer added with one registry line runs after the built-in ones; a disabled one does not."""
    def write_note(r, out_dir, *, frame):
        path = out_dir / f"note_{frame:04d}.txt"
        path.write_text(f"{r.time_s:g}\n")
        return {"note": path}

    def refuse(r, out_dir, *, frame):
        raise AssertionError("a disabled writer ran")

    monkeypatch.setitem(WRITERS, "note", FrameWriter(write_note, frame_io.always))
    monkeypatch.setitem(WRITERS, "off", FrameWriter(refuse, lambda r: False))
    paths = save_frame(result, tmp_path)
    assert list(paths)[-1] == "note" and paths["note"].read_text() == "0\n"
    assert "off" not in paths
