"""Sweeps: tasks and ids, a local process pool, failures, resume after SIGKILL, the study table."""

import csv
import json
import os
import signal
import subprocess
import sys
import time

import pytest

from warpcaustics.batch.sweep import load_sweep, read_manifest, run_sweep
from warpcaustics.errors import ConfigError

from helpers import CONFIGS, ROOT

TINY = """
base = "{base}"
[set]
"water.resolution" = 16
"caustics.map_resolution" = 16
"optics.wavelengths" = "rgb"
[grid]
"floor.depth_m" = [2.0, 4.0]
"optics.water_type" = [{types}]
[zip]
"sun.elevation_deg" = [40.0, 80.0]
"sun.azimuth_deg" = [0.0, 45.0]
[frames]
count = {frames}
fps = 4.0
"""


def _sweep(tmp_path, types='"pure", "clear_ocean"', frames=1, name="sweep.toml"):
    path = tmp_path / name
    path.write_text(
        TINY.format(base=(CONFIGS / "ocean.toml").as_posix(), types=types, frames=frames)
    )
    return path


def _csv_rows(out):
    with open(out / "summary.csv", encoding="utf-8") as fh:
        return list(csv.DictReader(fh))


def test_sweep_expands_grid_and_zip_into_stable_ids(tmp_path):
    """2 depths × 2 water types × 2 zipped suns = 8 variants; ids are stable and distinct, and a
    frame range multiplies stateless variants into one task per frame."""
    sweep = load_sweep(_sweep(tmp_path))
    assert len(sweep.tasks) == 8 and len({t.id for t in sweep.tasks}) == 8
    assert [t.id for t in load_sweep(_sweep(tmp_path)).tasks] == [t.id for t in sweep.tasks]
    zipped = {(t.overrides["sun.elevation_deg"], t.overrides["sun.azimuth_deg"]) for t in sweep.tasks}
    assert zipped == {(40.0, 0.0), (80.0, 45.0)}  # zipped, not crossed
    assert len(load_sweep(_sweep(tmp_path, frames=3, name="anim.toml")).tasks) == 24
    bad = tmp_path / "bad.toml"
    bad.write_text('base = "x.toml"\n[zip]\n"a" = [1]\n"b" = [1, 2]\n')
    with pytest.raises(ConfigError, match="equal lengths"):
        load_sweep(bad)


def test_local_sweep_runs_every_task_and_resumes(tmp_path):
    """8 tiny tasks on 2 workers: 8 folders with run.json, a CSV of 8 rows; a rerun skips them all."""
    out = tmp_path / "out"
    sweep = load_sweep(_sweep(tmp_path))
    report = run_sweep(sweep, out, workers=2, device="cpu", quiet=True)
    assert (report.done, report.skipped, report.failed) == (8, 0, [])
    rows = _csv_rows(out)
    assert len(rows) == 8 and {r["id"] for r in rows} == {t.id for t in sweep.tasks}
    assert all(
        (out / t.id / "run.json").exists() and (out / t.id / "frame_0000.exr").exists() for t in sweep.tasks
    )
    # Deeper water of the same type and sun gives a darker floor (a sanity check of the rows).
    by_key = {
        (r["optics.water_type"], r["floor.depth_m"], r["sun.elevation_deg"]): float(r["floor_w_m2"])
        for r in rows
    }
    assert by_key[("clear_ocean", "4.0", "80.0")] < by_key[("clear_ocean", "2.0", "80.0")]
    again = run_sweep(sweep, out, workers=2, device="cpu", quiet=True)
    assert (again.done, again.skipped) == (0, 8)
    from warpcaustics import __version__
    from warpcaustics.batch.sweep import task_id

    for rec in read_manifest(out).values():  # the manifest holds what the id hashes
        assert rec["version"] == __version__ and rec["config"]["water"]["resolution"] == 16
        assert task_id(rec["config"], tuple(rec["times_s"])) == rec["id"]


def test_a_stateless_frames_run_json_names_its_own_files(tmp_path):
    """A stateless animation runs one task per frame: each task's run.json numbers its frame as
    its files are numbered (frame k in frame_000k.*), so the record points at files that exist."""
    path = tmp_path / "anim.toml"
    path.write_text(
        f'base = "{(CONFIGS / "ocean.toml").as_posix()}"\n[set]\n"water.resolution" = 16\n'
        '"caustics.map_resolution" = 16\n"optics.wavelengths" = "rgb"\n[frames]\ncount = 2\nfps = 4.0\n'
    )
    sweep = load_sweep(path)
    out = tmp_path / "out"
    report = run_sweep(sweep, out, workers=1, device="cpu", quiet=True)
    assert report.done == 2
    for task in sweep.tasks:
        (entry,) = json.loads((out / task.id / "run.json").read_text(encoding="utf-8"))["frames"]
        assert entry["frame"] == task.frame_start
        assert all((out / task.id / name).exists() for name in entry["files"])
    assert sorted(t.frame_start for t in sweep.tasks) == [0, 1]


def test_a_failing_task_is_reported_and_the_rest_finish(tmp_path):
    """A variant whose override is invalid fails with its one-line error; the other tasks finish."""
    sweep = load_sweep(_sweep(tmp_path, types='"pure", "no_such_water"'))
    report = run_sweep(sweep, tmp_path / "out", workers=1, device="cpu", quiet=True)
    assert report.done == 4 and len(report.failed) == 4
    assert all("optics.water_type = 'no_such_water' is not allowed" in msg for _, msg in report.failed)
    assert len(_csv_rows(tmp_path / "out")) == 4


def test_a_base_every_variant_fails_with_is_refused_as_the_sweep_loads(tmp_path):
    """A base that is no scene (here the sweep file itself) had failed each task with the same error
    (exit 1, a folder of failures); the same error in every variant is now the sweep's, at once."""
    path = tmp_path / "s.toml"
    path.write_text('base = "s.toml"\n[grid]\n"floor.depth_m" = [1.0, 2.0]\n')
    with pytest.raises(ConfigError, match="every variant of s.toml fails the same way.*unknown key 'base'"):
        load_sweep(path)
    bad = tmp_path / "one.toml"  # one variant, bad: nothing would run either
    bad.write_text(f'base = "{(CONFIGS / "ocean.toml").as_posix()}"\n[grid]\n"floor.depth_m" = [-1.0]\n')
    with pytest.raises(ConfigError, match="floor.depth_m = -1.0 is out of range"):
        load_sweep(bad)


def test_a_bad_device_or_out_folder_is_one_error_before_any_output(tmp_path):
    """An explicit device that cannot be had fails once, before the folder is made (every task had
    failed with it, one line each); an --out that cannot be made is one line, not mkdir's traceback."""
    from warpcaustics.errors import DeviceError, WarpcausticsError

    sweep = load_sweep(_sweep(tmp_path))
    with pytest.raises(DeviceError, match="device = 'bogus' is not allowed"):
        run_sweep(sweep, tmp_path / "out", workers=1, device="bogus", quiet=True)
    assert not (tmp_path / "out").exists()
    (tmp_path / "afile").write_text("")
    with pytest.raises(WarpcausticsError, match="cannot be created"):
        run_sweep(sweep, tmp_path / "afile" / "out", workers=1, device="cpu", quiet=True)


def test_more_workers_than_the_host_memory_holds_are_refused_before_any_output(tmp_path, monkeypatch):
    """Eight tasks on eight workers with 1 GiB free: each worker's process (400 MiB) and scene would
    not fit eight times over; refused in one line naming --workers and how many fit, before the
    folder is made. Two workers fit and run; the tasks carry what pipeline.scene_bytes says."""
    import warpcaustics.device as devices
    from warpcaustics.batch.executors import WORKER_PROCESS_BYTES
    from warpcaustics.errors import WarpcausticsError
    from warpcaustics.pipeline import host_bytes, scene_bytes
    from warpcaustics.scene import load_scene

    sweep = load_sweep(_sweep(tmp_path))
    task = sweep.tasks[0]
    scene = load_scene(CONFIGS / "ocean.toml", task.overrides)
    assert task.memory == (scene_bytes(scene, "cuda"), scene_bytes(scene, "cpu"), host_bytes(scene))
    each = WORKER_PROCESS_BYTES + max(t.memory[1] + t.memory[2] for t in sweep.tasks)
    monkeypatch.setattr(devices, "host_available_bytes", lambda: 2**30)
    fit = 2**30 // each
    with pytest.raises(WarpcausticsError, match=rf"^--workers 8: 8 renders at once need about "
                                                rf"[0-9.]+ GiB of host memory but 1.0 GiB is free; "
                                                rf"use --workers {fit} or fewer$"):
        run_sweep(sweep, tmp_path / "out", workers=8, device="cpu", quiet=True)
    assert not (tmp_path / "out").exists()
    with pytest.raises(WarpcausticsError, match="8 renders at once"):  # more workers than tasks: 8
        run_sweep(sweep, tmp_path / "out", workers=1000, device="cpu", quiet=True)
    report = run_sweep(load_sweep(_sweep(tmp_path, types='"pure"')), tmp_path / "out", workers=fit,
                       device="cpu", quiet=True)
    assert report.done == 4 and not report.failed


def test_a_dead_worker_says_to_use_fewer_workers():
    """A worker killed under memory pressure breaks the pool: each task it took fails with the
    pool's words, which name no cause; the line says what to do."""
    from concurrent.futures.process import BrokenProcessPool

    from warpcaustics.batch.sweep import _error_line

    line = _error_line(BrokenProcessPool("A process in the process pool was terminated abruptly while "
                                         "the future was running or pending."))
    assert line.startswith("BrokenProcessPool: a worker process died") and "fewer --workers" in line


def test_sweep_frame_times_past_the_renderers_range_are_refused(tmp_path):
    """A sweep's [frames] whose times overflow (or a start that is no number) are refused as the sweep
    loads, not by every task."""
    from warpcaustics.errors import WarpcausticsError

    base = (CONFIGS / "ocean.toml").as_posix()
    for frames, needle in (("start_s = 1e300", "start_s"), ("start_s = 'noon'", "start_s"),
                           ("count = 3\nfps = 1e-300", "last time")):
        path = tmp_path / "s.toml"
        path.write_text(f'base = "{base}"\n[frames]\n{frames}\n')
        with pytest.raises(WarpcausticsError, match=needle):
            load_sweep(path)


def test_sigkill_midway_then_rerun_finishes_each_task_once(tmp_path):
    """SIGKILL the sweep's driver after its first task: its workers die with it (nothing is left
    writing), a rerun completes the rest, every task is recorded done exactly once, and no
    temporary folder is left."""
    sweep_file = _sweep(tmp_path, frames=3)  # 24 tasks
    out = tmp_path / "out"
    cmd = [
        sys.executable,
        "-m",
        "warpcaustics",
        "sweep",
        str(sweep_file),
        "--out",
        str(out),
        "--workers",
        "2",
        "--device",
        "cpu",
        "--quiet",
    ]
    proc = subprocess.Popen(
        cmd, cwd=ROOT, start_new_session=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
    )
    deadline = time.time() + 120
    while time.time() < deadline and not any(
        r.get("state") == "done" for r in read_manifest(out).values() if out.exists()
    ):
        time.sleep(0.05)
    os.kill(proc.pid, signal.SIGKILL)  # the driver only
    proc.wait()
    deadline = time.time() + 10
    while time.time() < deadline:
        try:
            os.killpg(proc.pid, 0)  # any process of the sweep's group still alive?
        except ProcessLookupError:
            break
        time.sleep(0.1)
    else:
        os.killpg(proc.pid, signal.SIGKILL)
        pytest.fail("the workers outlived their driver")
    first = read_manifest(out)
    assert 0 < len(first) < 24, "the kill must land midway"
    subprocess.run(cmd, cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
    lines, cut = [], 0
    for x in (out / "manifest.jsonl").read_text().splitlines():
        try:
            lines.append(json.loads(x))
        except json.JSONDecodeError:  # the record the kill cut mid-write, if it landed there
            cut += 1
    assert cut <= 1
    done = [rec["id"] for rec in lines if rec["state"] == "done"]
    assert sorted(done) == sorted({t.id for t in load_sweep(sweep_file).tasks})  # each once
    assert not list(out.glob(".*.tmp-*"))
    assert len(_csv_rows(out)) == 24


def test_a_record_after_a_cut_line_stands_on_its_own(tmp_path):
    """A driver killed mid-write leaves the manifest's last line cut, without its newline: the next
    record goes on a line of its own (not merged into the cut one, where it would be lost too), and
    the manifest reads the records before and after it, skipping the cut line."""
    from warpcaustics.batch.sweep import MANIFEST, _append

    _append(tmp_path, {"id": "a", "state": "done", "rows": [{"frame": 0}]})
    with open(tmp_path / MANIFEST, "a", encoding="utf-8") as fh:
        fh.write('{"id": "b", "sta')  # the kill's cut
    _append(tmp_path, {"id": "c", "state": "done", "rows": [{"frame": 0}]})
    _append(tmp_path, {"id": "d", "state": "failed"})
    lines = (tmp_path / MANIFEST).read_text(encoding="utf-8").splitlines()
    assert lines[1] == '{"id": "b", "sta'
    states = {k: r["state"] for k, r in read_manifest(tmp_path).items()}
    assert states == {"a": "done", "c": "done", "d": "failed"}


@pytest.mark.parametrize("path", sorted((CONFIGS / "sweeps").glob("*.toml")), ids=lambda p: p.name)
def test_shipped_sweeps_expand(path):
    """Each sweep in configs/sweeps/ loads, and every one of its variants is a valid scene."""
    sweep = load_sweep(path)
    assert sweep.tasks and all(t.error is None for t in sweep.tasks)


POOL = """
base = "{base}"
[set]
"water.resolution" = 24
"caustics.map_resolution" = 24
"optics.wavelengths" = "rgb"
[grid]
"floor.depth_m" = [1.5]
[frames]
count = 4
fps = 4.0
"""


def test_interrupted_pool_animation_resumes_from_its_checkpoint(tmp_path, monkeypatch):
    """A pool animation is one task. Interrupted after 2 of its 4 frames, a rerun continues from the
    checkpoint (only frames 3 and 4 are rendered again) and its frames equal an uninterrupted run's."""
    import numpy as np

    from warpcaustics import pipeline
    from warpcaustics.batch.worker import run_task

    path = tmp_path / "pool.toml"
    path.write_text(POOL.format(base=(CONFIGS / "pool.toml").as_posix()))
    sweep = load_sweep(path)
    assert len(sweep.tasks) == 1 and sweep.tasks[0].stateful and len(sweep.tasks[0].times_s) == 4
    task = sweep.tasks[0]
    clean = run_task(str(sweep.base), task, str(tmp_path / "clean"), "cpu")

    real_render = pipeline.Renderer.render
    calls = []

    def interrupted(self, time_s):
        calls.append(time_s)
        if len(calls) == 3:
            raise KeyboardInterrupt  # the sweep is stopped during frame 3
        return real_render(self, time_s)

    monkeypatch.setattr(pipeline.Renderer, "render", interrupted)
    out = tmp_path / "resumed"
    out.mkdir()
    with pytest.raises(KeyboardInterrupt):
        run_task(str(sweep.base), task, str(out), "cpu")
    assert (out / f".{task.id}.partial" / "checkpoint.npz").exists() and not (out / task.id).exists()
    calls.clear()
    monkeypatch.setattr(
        pipeline.Renderer, "render", lambda self, t: (calls.append(t), real_render(self, t))[1]
    )
    resumed = run_task(str(sweep.base), task, str(out), "cpu")
    assert calls == list(task.times_s[2:])  # frames 1-2 were not simulated again
    assert [r["floor_w_m2"] for r in resumed["rows"]] == [r["floor_w_m2"] for r in clean["rows"]]
    import OpenEXR

    for k in range(4):
        a = (
            OpenEXR.File(str(tmp_path / "clean" / task.id / f"frame_{k:04d}.exr"))
            .channels()["S0.550,000000nm"]
            .pixels
        )
        b = OpenEXR.File(str(out / task.id / f"frame_{k:04d}.exr")).channels()["S0.550,000000nm"].pixels
        np.testing.assert_array_equal(a, b)
    run = json.loads((out / task.id / "run.json").read_text())
    assert [f["frame"] for f in run["frames"]] == [0, 1, 2, 3]
    assert not (out / f".{task.id}.partial").exists()


def test_ray_executor_gives_the_local_results(tmp_path):
    """The same 8-task sweep on a local Ray instance (2 CPUs, started and stopped by the sweep) gives
    the same CSV values as the local process pool (timings aside)."""
    pytest.importorskip("ray", reason="pip install 'warpcaustics[ray]'")
    sweep = load_sweep(_sweep(tmp_path))
    run_sweep(sweep, tmp_path / "local", workers=2, device="cpu", quiet=True)
    report = run_sweep(sweep, tmp_path / "ray", workers=2, device="cpu", quiet=True, executor="ray")
    assert (report.done, report.failed) == (8, [])
    local = {r["id"]: r for r in _csv_rows(tmp_path / "local")}
    on_ray = {r["id"]: r for r in _csv_rows(tmp_path / "ray")}
    assert local.keys() == on_ray.keys()
    for task_id, row in local.items():
        assert {k: v for k, v in row.items() if k != "render_s"} == {
            k: v for k, v in on_ray[task_id].items() if k != "render_s"
        }


def test_workers_get_one_blas_thread_unless_the_user_chose(monkeypatch):
    """While the local pool runs, the variables that size numpy's BLAS thread pool read 1 for the
    workers it spawns, except one the user set; afterwards the environment is as it was."""
    from warpcaustics.batch.threads import NUMERIC_THREADS, one_blas_thread_per_worker

    for var in NUMERIC_THREADS:
        monkeypatch.delenv(var, raising=False)
    monkeypatch.setenv("MKL_NUM_THREADS", "3")
    with one_blas_thread_per_worker():
        assert os.environ["OPENBLAS_NUM_THREADS"] == "1" and os.environ["OMP_NUM_THREADS"] == "1"
        assert os.environ["MKL_NUM_THREADS"] == "3"
    assert "OPENBLAS_NUM_THREADS" not in os.environ and "OMP_NUM_THREADS" not in os.environ
    assert os.environ["MKL_NUM_THREADS"] == "3"
