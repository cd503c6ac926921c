"""A sweep's folder damaged between runs (a fuzz, 2026-12-07): manifest lines that are not task
records, a task's run.json that is not a run, a lost sweep.json, a file where a task's folder goes,
and a pool animation's checkpoint cut short or not this animation's. Each had raised from inside the
sweep on every rerun, or been skipped as done; now the damaged task renders again and the sweep ends
as an undamaged one does."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from warpcaustics.batch.sweep import MANIFEST, load_sweep, read_manifest, run_sweep
from warpcaustics.batch.worker import CHECKPOINT, CHECKPOINT_META, run_task

from helpers import CONFIGS

SWEEP = """base = "{base}"
[set]
"water.resolution" = 16
"caustics.map_resolution" = 16
"optics.wavelengths" = "rgb"
[grid]
"floor.depth_m" = [2.0, 5.0]
"""


@pytest.fixture
def swept(tmp_path):
    """A finished two-task sweep, and a function that reruns it (its report)."""
    path = tmp_path / "sweep.toml"
    path.write_text(SWEEP.format(base=(CONFIGS / "ocean.toml").as_posix()))
    sweep = load_sweep(path)
    out = tmp_path / "out"
    first = run_sweep(sweep, out, device="cpu", quiet=True)
    assert first.done == 2 and not first.failed
    return sweep, out, lambda: run_sweep(sweep, out, device="cpu", quiet=True)


def summary(out) -> list[dict]:
    """The summary's rows without their render times, which differ from run to run."""
    with open(out / "summary.csv", encoding="utf-8", newline="") as fh:
        return [{k: v for k, v in row.items() if k != "render_s"} for row in csv.DictReader(fh)]


def test_manifest_lines_that_are_not_records_are_skipped(swept):
    sweep, out, rerun = swept
    before = summary(out)
    task = sweep.tasks[0].id
    with open(out / MANIFEST, "ab") as fh:
        fh.write(b'{"id": [1], "state": "done"}\n')  # an id that is not a string
        fh.write(b'\xff\xfe not text\n')
        fh.write(json.dumps({"id": task, "state": "done", "rows": "abc"}).encode() + b"\n")
    assert set(read_manifest(out)) == {t.id for t in sweep.tasks}
    report = rerun()  # each task's last whole record stands: both are done
    assert not report.failed and report.skipped == 2
    assert summary(out) == before


def test_a_damaged_run_json_renders_its_task_again(swept):
    sweep, out, rerun = swept
    before = summary(out)
    (out / sweep.tasks[1].id / "run.json").write_text('{"frames": [')
    report = rerun()
    assert not report.failed and report.done == 1 and report.skipped == 1
    assert json.loads((out / sweep.tasks[1].id / "run.json").read_text())["frames"]
    assert summary(out) == before


def test_a_lost_sweep_json_is_the_same_sweep_resumed(swept):
    sweep, out, rerun = swept
    (out / "sweep.json").unlink()
    report = rerun()
    assert report.skipped == 2 and not report.failed
    assert (out / "sweep.json").exists()


def test_a_file_where_a_task_folder_goes_is_replaced(swept):
    sweep, out, rerun = swept
    import shutil

    shutil.rmtree(out / sweep.tasks[0].id)
    (out / sweep.tasks[0].id).write_text("not a folder")
    (out / f".{sweep.tasks[1].id}.tmp").write_text("not a folder either")
    lines = (out / MANIFEST).read_text().splitlines()
    (out / MANIFEST).write_text("\n".join(line for line in lines if sweep.tasks[0].id not in line) + "\n")
    report = rerun()
    assert not report.failed and report.done == 1
    assert (out / sweep.tasks[0].id / "run.json").exists()


POOL = """base = "{base}"
[set]
"water.resolution" = 16
"caustics.map_resolution" = 16
"optics.wavelengths" = "rgb"
[frames]
count = 4
fps = 4.0
"""


def interrupted_animation(tmp_path, monkeypatch, config: str):
    """A pool animation of 4 frames rendered whole (its rows), then again into ``tmp_path/out``
    stopped during its third frame, and a function that reruns it there and returns its rows and the
    times it rendered."""
    from warpcaustics import pipeline

    path = tmp_path / "anim.toml"
    path.write_text(POOL.format(base=(CONFIGS / config).as_posix()))
    task = load_sweep(path).tasks[0]
    assert task.stateful and len(task.times_s) == 4
    base = str(CONFIGS / config)
    clean = run_task(base, task, str(tmp_path / "clean"), "cpu")["rows"]
    real_render = pipeline.Renderer.render
    calls = []

    def counted(self, time_s):
        calls.append(time_s)
        if len(calls) == 3 and stop:
            raise KeyboardInterrupt
        return real_render(self, time_s)

    stop = True
    monkeypatch.setattr(pipeline.Renderer, "render", counted)
    out = tmp_path / "out"
    out.mkdir()
    with pytest.raises(KeyboardInterrupt):
        run_task(base, task, str(out), "cpu")

    def rerun():
        nonlocal stop
        stop = False
        calls.clear()
        return run_task(base, task, str(out), "cpu")["rows"], list(calls)

    return task, clean, out / f".{task.id}.partial", rerun


@pytest.mark.parametrize("damage", ["cut npz", "list json", "one entry", "other time", "nan state"])
def test_a_damaged_pool_checkpoint_starts_the_animation_again(tmp_path, monkeypatch, damage):
    """Cut short, not the pair written together, or a state that is not this animation's at its last
    frame: the checkpoint is dropped and the animation rendered from frame 0, to the same frames as
    an uninterrupted run (it had failed the task on every rerun, or resumed into wrong frames)."""
    task, clean, partial, rerun = interrupted_animation(tmp_path, monkeypatch, "pool.toml")
    npz, meta = partial / CHECKPOINT, partial / CHECKPOINT_META
    if damage == "cut npz":
        npz.write_bytes(npz.read_bytes()[:100])
    elif damage == "list json":
        meta.write_text("[1]")
    elif damage == "one entry":  # frames_done still 2: the resume would have numbered frames 1, 1, 2, 3
        record = json.loads(meta.read_text())
        record["entries"] = record["entries"][:1]
        meta.write_text(json.dumps(record))
    else:
        with np.load(npz) as data:
            state = {k: data[k] for k in data.files}
        if damage == "other time":
            state["time_s"] = np.float64(-5.0)
        else:
            state["h"] = np.full_like(state["h"], np.nan)
        np.savez(npz, **state)
    rows, rendered = rerun()
    assert rendered == list(task.times_s)  # from frame 0
    assert [r["frame"] for r in rows] == [0, 1, 2, 3]
    assert [r["floor_w_m2"] for r in rows] == [r["floor_w_m2"] for r in clean]


def test_a_wave_pool_resumes_from_a_clean_checkpoint(tmp_path, monkeypatch):
    """The wave pool stops at the last of its fixed steps before a frame's time, so its saved time is
    up to a step early: a clean checkpoint must still resume (only the frames after it render)."""
    task, clean, _, rerun = interrupted_animation(tmp_path, monkeypatch, "wavepool.toml")
    rows, rendered = rerun()
    assert rendered == list(task.times_s[2:])
    assert [r["floor_w_m2"] for r in rows] == [r["floor_w_m2"] for r in clean]


def test_a_pool_task_replaces_a_file_where_its_folder_goes(tmp_path):
    path = tmp_path / "pool.toml"
    path.write_text(POOL.format(base=(CONFIGS / "pool.toml").as_posix()))
    task = load_sweep(path).tasks[0]
    (tmp_path / task.id).write_text("not a folder")
    run_task(str(CONFIGS / "pool.toml"), task, str(tmp_path), "cpu")
    assert (tmp_path / task.id / "run.json").exists()


def test_a_record_whose_rows_hold_lists_is_a_record():
    """A resumed pool animation's earlier rows come back from its checkpoint with arrays as JSON lists
    (photon tallies with bounces); such a record is whole, not damaged."""
    from warpcaustics.batch.sweep import _is_record

    row = {"id": "a", "frame": 0, "time_s": 0.0, "floor_w_m2": 1.0, "contrast": 0.1, "cv": 0.1,
           "render_s": 0.5, "photons_reflected_w_nm": [0.1, 0.2]}
    assert _is_record({"id": "a", "state": "done", "rows": [row]})
    assert not _is_record({"id": "a", "state": "done", "rows": [{**row, "cv": "x"}]})


def test_a_finished_sweep_reruns_without_its_device(swept, monkeypatch):
    """Rerunning a finished sweep (to write its summary again) renders nothing, so it needs no device:
    one configured for CUDA reruns on a machine without one."""
    sweep, out, rerun = swept
    monkeypatch.setenv("WARPCAUSTICS_DEVICE", "cuda:7")
    report = run_sweep(sweep, out, quiet=True)
    assert report.skipped == 2 and not report.failed
