"""What a worker does with one sweep task: render its frames into ``DIR/<id>/`` through a
temporary folder (a pool animation through a checkpointed ``DIR/.<id>.partial/``), and return the
summary rows the driver records in the manifest."""

from __future__ import annotations

import json
import os
import shutil
import time
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from warpcaustics.io.comparison import relative_l1
from warpcaustics.io.files import atomic_path, write_json
from warpcaustics.io.frame import save_frame
from warpcaustics.io.run_json import frame_entry, write_run_json

if TYPE_CHECKING:
    from warpcaustics.batch.sweep import Task


def task_tmp_dir(out_dir: str | Path, task_id: str) -> Path:
    """The one temporary folder a task renders into, ``DIR/.<id>.tmp``: named by the task's id alone,
    so the sweep that owns the task can remove it after a killed run without touching anything else."""
    return Path(out_dir) / f".{task_id}.tmp"


def remove(path: Path) -> None:
    """Remove a task's folder, or a file in its place (which a folder's rename cannot replace)."""
    if path.is_dir() and not path.is_symlink():
        shutil.rmtree(path, ignore_errors=True)
    elif path.exists() or path.is_symlink():
        path.unlink()


def run_task(base: str, task: Task, out_dir: str, device: str | None) -> dict:
    """Render one task into ``out_dir/<id>`` (via a temporary folder); return its summary row."""
    if task.stateful:
        return run_pool_task(base, task, out_dir, device)
    from warpcaustics.pipeline import Renderer
    from warpcaustics.scene import load_scene

    t0 = time.perf_counter()
    final = Path(out_dir) / task.id
    tmp = task_tmp_dir(out_dir, task.id)
    remove(tmp)
    try:
        renderer = Renderer(load_scene(base, task.overrides), device)
        results = []
        for k, t in enumerate(task.times_s):
            result = renderer.render(t)
            save_frame(result, tmp, frame=task.frame_start + k)
            results.append(result)
        entries = [frame_entry(task.frame_start + k, r) for k, r in enumerate(results)]  # as the files
        write_run_json(tmp, results, frames=entries)
        remove(final)
        os.replace(tmp, final)
    finally:
        remove(tmp)
    return {
        "rows": [summary_row(task, r, k, entries[k]["statistics"]) for k, r in enumerate(results)],
        "seconds": time.perf_counter() - t0,
        "device": results[0].device,
    }


CHECKPOINT = "checkpoint.npz"
CHECKPOINT_META = "checkpoint.json"


def _at_frame(saved_s: float, frame_s: float, renderer) -> bool:
    """Whether a pool saved at ``saved_s`` stood at the frame of ``frame_s``: the pool stops at its
    frame's time, the wave pool at the last of its fixed steps before it."""
    return -1e-6 <= frame_s - saved_s <= getattr(renderer.water, "dt", 0.0) + 1e-6


def _resume(partial: Path, renderer, task: Task) -> tuple[list[dict], list[dict]]:
    """The frames' records and summary rows of an interrupted pool animation, its pool's state loaded
    into ``renderer``; none (start again at frame 0) when there is no checkpoint or it cannot be
    trusted — the pair not written together, a damaged file, a state that is not this animation's
    at its last frame's time — rather than fail the task on every rerun."""
    meta_path = partial / CHECKPOINT_META
    if not (meta_path.exists() and (partial / CHECKPOINT).exists()):
        return [], []
    try:
        meta = json.loads(meta_path.read_text(encoding="utf-8"))
        with np.load(partial / CHECKPOINT, allow_pickle=False) as data:
            state = {name: np.asarray(data[name]) for name in data.files}
        done = int(state.pop("frames_done"))
        entries, rows = meta["entries"], meta["rows"]
        state["time_s"] = float(state["time_s"])
        trusted = (done == meta["frames_done"] and 0 < done <= len(task.times_s) and len(entries) == done
                   and len(rows) == done and _at_frame(state["time_s"], task.times_s[done - 1], renderer)
                   and all(a.dtype.kind in "fiu" and np.all(np.isfinite(a)) for a in state.values()
                           if isinstance(a, np.ndarray)))
        if trusted:
            renderer.water.load_state(state)
            return entries, rows
    except Exception:  # noqa: BLE001 - a damaged checkpoint, in whatever way: start again
        pass
    for name in (CHECKPOINT, CHECKPOINT_META):
        remove(partial / name)
    return [], []


def run_pool_task(base: str, task: Task, out_dir: str, device: str | None) -> dict:
    """Render a pool animation into ``out_dir/.<id>.partial/``, checkpointing the pool's state after
    every frame, and rename the folder to ``out_dir/<id>`` when all frames are done. A task that
    was interrupted continues from its last checkpoint (same frames, bit for bit on one device)
    instead of simulating from t = 0 again."""
    from warpcaustics.pipeline import Renderer
    from warpcaustics.scene import load_scene

    t0 = time.perf_counter()
    out = Path(out_dir)
    final = out / task.id
    partial = out / f".{task.id}.partial"
    if not partial.is_dir():
        remove(partial)
    partial.mkdir(parents=True, exist_ok=True)
    renderer = Renderer(load_scene(base, task.overrides), device)
    entries, rows = _resume(partial, renderer, task)
    meta_path = partial / CHECKPOINT_META
    result = None
    for k in range(len(entries), len(task.times_s)):
        result = renderer.render(task.times_s[k])
        save_frame(result, partial, frame=task.frame_start + k)
        entries.append(frame_entry(task.frame_start + k, result))
        rows.append(summary_row(task, result, k, entries[-1]["statistics"]))
        with atomic_path(partial / CHECKPOINT) as tmp, open(tmp, "wb") as fh:
            np.savez(fh, frames_done=len(entries), **renderer.water.state())
        write_json(meta_path, {"frames_done": len(entries), "entries": entries, "rows": rows})
    if result is None:  # every frame was done before the interruption
        result = renderer.render(task.times_s[-1])
    write_run_json(partial, [result], frames=entries)
    for name in (CHECKPOINT, CHECKPOINT_META):
        (partial / name).unlink()
    remove(final)
    os.replace(partial, final)
    return {"rows": rows, "seconds": time.perf_counter() - t0, "device": result.device}


def cell(value):
    """A varied key's value in summary.csv: numbers, strings and booleans as they are, a list or a
    table as its TOML literal (what the sweep file says), not a Python repr."""
    from warpcaustics.io.toml_out import literal

    return literal(value) if isinstance(value, (list, tuple, dict)) else value


def summary_row(task: Task, result, k: int, statistics: dict | None = None) -> dict:
    """Summary statistics of one frame: per band mean and max floor irradiance, caustic contrast
    (standard deviation / mean of the band-summed floor irradiance), photon counts, timings.
    ``statistics``: the frame's run.json statistics, when already computed."""
    floor = result.floor_irradiance.astype(np.float64)
    total = (floor * result.bin_widths_nm[:, None, None]).sum(axis=0)
    row = {"id": task.id, "frame": task.frame_start + k, "time_s": result.time_s}
    row.update({key: cell(task.overrides[key]) for key in sorted(task.overrides)})
    for wl, band in zip(result.wavelengths_nm, floor):
        row[f"mean_{wl:g}nm"] = float(band.mean())
        row[f"max_{wl:g}nm"] = float(band.max())
    row["floor_w_m2"] = float(total.mean())
    row["contrast"] = float(total.std() / total.mean()) if total.mean() > 0 else 0.0
    if statistics is None:
        from warpcaustics.batch.stats import frame_statistics

        statistics = frame_statistics(result, result.scene.config.stats)  # after the collector
    row["cv"] = statistics["irradiance_w_m2"]["cv"]
    row["flash_fraction"] = statistics["irradiance_w_m2"]["flash_fraction"]
    if "par_umol_m2_s" in statistics:
        row["par_umol_m2_s"] = statistics["par_umol_m2_s"]["mean"]
    if result.photon_stats:
        row.update({f"photons_{k2}": v for k2, v in result.photon_stats.items()})
    if result.beam_stats:
        row.update({f"beams_{k2}": v for k2, v in result.beam_stats.items()})
    if result.comparison is not None:  # "both" or "sunmap": how far the other method's floor map is
        other = result.comparison
        row[f"{result.method}_vs_{other.method}_l1"] = relative_l1(floor, other.floor_irradiance)
    row["render_s"] = float(sum(result.timings_s.values()))
    return row
