"""What a sixth pass (2026-12-08, by hand: the commands' environment) found: two runs writing into one
folder at once, Ctrl-C that a sweep's workers took as their tasks' errors, a closed or broken stdout,
Warp's kernel cache where it cannot be written, an OSError blamed on --out, and a sweep that kept
the results of a file changed under the same name."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

import warpcaustics as wc
from warpcaustics import cli
from warpcaustics.batch.sweep import load_sweep, run_sweep, task_id
from warpcaustics.io.files import folder_lock

from helpers import CONFIGS

TINY = ["--device", "cpu", "--set", "water.resolution=16", "--set", "caustics.map_resolution=16", "--set",
        "optics.wavelengths=rgb"]


def _shell(command: str, **kwargs) -> subprocess.CompletedProcess:
    return subprocess.run(["bash", "-c", f"set -o pipefail; {command}"], capture_output=True, text=True,
                          timeout=600, **kwargs)


def _sweep_file(path: Path, depths: str, resolution: int = 16) -> Path:
    path.write_text(f'base = "{(CONFIGS / "ocean.toml").as_posix()}"\n[set]\n'
                    f'"water.resolution" = {resolution}\n"caustics.map_resolution" = {resolution}\n'
                    f'"optics.wavelengths" = "rgb"\n[grid]\n"floor.depth_m" = [{depths}]\n')
    return path


def test_a_second_run_into_a_folder_being_written_is_refused(tmp_path, capsys):
    """Two renders into one --out had deleted each other's frames (both exit 0), two sweeps had
    rendered the same tasks into the same temporary folders. While a run holds the folder's lock, a
    render and a sweep into it are refused in one line; once it is released both run."""
    out = tmp_path / "out"
    out.mkdir()
    sweep = load_sweep(_sweep_file(tmp_path / "s.toml", "2.0"))
    render = ["render", str(CONFIGS / "ocean.toml"), "--out", str(out), *TINY, "--quiet"]
    with folder_lock(out):
        assert cli.main(render) == 2
        assert "is being written by another warpcaustics run; wait for it to end, or give another --out" in \
            capsys.readouterr().err
        with pytest.raises(wc.WarpcausticsError, match="is being written by another warpcaustics run"):
            run_sweep(sweep, tmp_path / "out", device="cpu", quiet=True)
    assert list(out.iterdir()) == []  # nothing written, the lock's own file neither (it locks the folder)
    assert cli.main(render) == 0
    assert run_sweep(sweep, tmp_path / "sweep", device="cpu", quiet=True).done == 1


def test_ctrl_c_stops_a_sweep_s_workers_at_once_and_a_rerun_finishes(tmp_path):
    """SIGINT to the process group (as a terminal sends it) had been taken by each worker as its task's
    error, and the pool then ran every queued task before the driver could exit (a second Ctrl-C hung
    it). Now the workers ignore it and the driver ends them: exit 130 within seconds, and the rerun
    renders what is left."""
    sweep = _sweep_file(tmp_path / "s.toml", "2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0", resolution=256)
    out = tmp_path / "out"
    command = [sys.executable, "-m", "warpcaustics", "sweep", str(sweep), "--out", str(out), "--workers", "2",
               "--device", "cpu", "--quiet"]
    # as from a terminal: SIGINT at its default (a pytest-xdist worker ignores it, and an ignored
    # signal stays ignored in its children, so Python would install no KeyboardInterrupt for it)
    proc = subprocess.Popen(command, start_new_session=True, stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    deadline = time.monotonic() + 300
    while not (out.is_dir() and any(p.name.endswith(".tmp") for p in out.iterdir())):  # a task under way
        assert proc.poll() is None and time.monotonic() < deadline, proc.stderr.read()[-2000:]
        time.sleep(0.1)
    os.killpg(proc.pid, signal.SIGINT)
    asked = time.monotonic()
    assert proc.wait(timeout=60) == 130
    assert time.monotonic() - asked < 20  # measured 1.5 s; before, every queued task ran first
    assert "warpcaustics: interrupted" in proc.stderr.read()
    rerun = subprocess.run(command, capture_output=True, text=True, timeout=600)
    assert rerun.returncode == 0 and "failed 0" in rerun.stdout, rerun.stderr[-2000:]
    assert len({r["id"] for r in map(json.loads, (out / "manifest.jsonl").read_text().splitlines())
                if r["state"] == "done"}) == 8


def test_a_closed_or_broken_stdout_does_not_stop_a_render(tmp_path):
    """Started with stdout or stderr closed, a render had died in its progress line (AttributeError on
    None); piped into `head -1`, it had stopped at the second frame with a line blaming --out. Now
    it renders every frame and exits 0."""
    base = f"{sys.executable} -m warpcaustics render {CONFIGS / 'ocean.toml'} " + " ".join(TINY)
    for name, redirect in (("closed", ">&-"), ("no_stderr", "2>&-")):
        proc = _shell(f"{base} --out {tmp_path / name} {redirect}")
        assert proc.returncode == 0, proc.stderr[-2000:]
        assert json.loads((tmp_path / name / "run.json").read_text())["frames"][0]["frame"] == 0
    proc = _shell(f"{base} --out {tmp_path / 'piped'} --frames 4 | head -1")
    assert proc.returncode == 0 and proc.stdout.startswith("[1/4] frame 0000"), proc.stderr[-2000:]
    assert len(json.loads((tmp_path / "piped" / "run.json").read_text())["frames"]) == 4
    assert _shell(f"{sys.executable} -m warpcaustics info | head -1").returncode == 0


def test_warp_s_kernel_cache_that_cannot_be_made_is_named(tmp_path):
    """A read-only HOME had been reported as a write into --out that failed."""
    (tmp_path / "a_file").write_text("")
    env = {**os.environ, "WARP_CACHE_PATH": str(tmp_path / "a_file" / "cache")}
    command = [sys.executable, "-m", "warpcaustics", "render", str(CONFIGS / "ocean.toml"), "--out",
               str(tmp_path / "out"), *TINY]
    proc = subprocess.run(command, capture_output=True, text=True, env=env, timeout=600)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and len(lines) == 1, proc.stderr[-2000:]
    assert "Warp cannot start" in lines[0] and "set WARP_CACHE_PATH to a folder you can write to" in lines[0]
    assert not (tmp_path / "out").exists()


def test_an_os_error_names_out_only_where_the_file_is_in_it(tmp_path):
    out = tmp_path / "out"
    inside = cli._os_error_line(OSError(28, "No space left on device", str(out / "frame_0000.exr")), str(out))
    assert inside.endswith("free space in --out or give another --out (what was written is not marked a "
                           "finished run)")
    elsewhere = cli._os_error_line(OSError(24, "Too many open files", "/usr/lib/x.so"), str(out))
    assert elsewhere == "'/usr/lib/x.so': Too many open files"


def test_a_file_changed_under_the_same_name_is_a_new_task(tmp_path):
    """The task id hashed a config's file names, not the files: a lens.npy rewritten in place kept the
    old results ("skipped 2, finished before")."""
    heights = np.zeros((16, 16), np.float32)
    np.save(tmp_path / "h.npy", heights)
    (tmp_path / "scene.toml").write_text("[water]\nmodel = 'heightfield'\nfile = 'h.npy'\nresolution = 16\n"
                                        "extent_m = 4.0\n[caustics]\nmap_resolution = 16\n")
    sweep = tmp_path / "s.toml"
    sweep.write_text('base = "scene.toml"\n[grid]\n"floor.depth_m" = [1.0]\n')
    before = load_sweep(sweep).tasks[0].id
    assert load_sweep(sweep).tasks[0].id == before  # the same contents, the same id
    np.save(tmp_path / "h.npy", heights + 0.01)
    assert load_sweep(sweep).tasks[0].id != before
    flat = load_sweep(_sweep_file(tmp_path / "flat.toml", "2.0")).tasks[0]
    assert flat.id == task_id(flat.config, flat.times_s)  # a config without files keeps the id it had
