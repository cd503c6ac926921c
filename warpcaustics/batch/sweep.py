"""Parameter sweeps: many scene variants and frames, in worker processes, resumable.

A sweep TOML names a base scene and the keys to vary::

    base = "../ocean.toml"            # relative to the sweep file
    [set]                             # the same for every task
    "water.resolution" = 64
    [grid]                            # cartesian product
    "optics.water_type" = ["clear_ocean", "coastal_ocean"]
    "floor.depth_m" = [2.0, 5.0]
    [zip]                             # varied together (equal lengths): one more grid axis
    "sun.elevation_deg" = [30.0, 60.0]
    "sun.azimuth_deg" = [0.0, 90.0]
    [frames]                          # animation frames of every variant
    count = 1
    fps = 30.0
    start_s = 0.0

A task is a scene variant × frame for stateless water, and a whole variant (all its frames, in
order) for the stateful pools. Its id hashes the resolved config, the frame time(s) and the package
version, so a rerun recognises finished tasks. Each task renders into ``DIR/.<id>.tmp/`` and
that folder is renamed to ``DIR/<id>/`` only once complete. The driver alone appends to
``DIR/manifest.jsonl`` (one JSON object per line, flushed and fsynced): a task whose id is recorded
as done and whose folder holds a whole ``run.json`` is skipped on a rerun; anything else (a damaged
manifest line or run.json included) runs again. Leftover
temporary folders of a killed run are removed at the start. Workers are separate processes (Warp's
CPU launches run on one core each), and they die with the driver (parent-death signal plus a parent
check), so a killed sweep leaves nothing writing. A sweep removes only the temporary folders of
its own tasks (their ids), never other entries of ``DIR`` by a pattern.

This module reads and expands sweeps and drives them; ``batch/worker.py`` renders one task,
``batch/executors.py`` runs the tasks on a local process pool or on Ray.
"""

from __future__ import annotations

import difflib
import functools
import hashlib
import itertools
import json
import math
import os
import shutil
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from warpcaustics import __version__
from warpcaustics.batch.arguments import output_folder, overrides_argument, path_argument, workers_argument
from warpcaustics.batch.executors import check_workers_fit, run_locally, run_on_ray
from warpcaustics.batch.progress import Progress
from warpcaustics.batch.worker import task_tmp_dir
from warpcaustics.config import config_to_dict, read_toml
from warpcaustics.config.loading import check_key
from warpcaustics.errors import ConfigError, WarpcausticsError
from warpcaustics.io.files import atomic_path, folder_lock, write_csv, write_json
from warpcaustics.io.manifest import MANIFEST as RUN_MANIFEST
from warpcaustics.io.manifest import SWEEP_MANIFEST as MANIFEST
from warpcaustics.io.manifest import SWEEP_RECORD

SUMMARY = "summary.csv"


@dataclass(frozen=True)
class Task:
    """One unit of work: a scene variant and the frame times it renders."""

    id: str
    overrides: dict[str, Any]
    """Dotted overrides applied to the base scene (``set``, then the grid and zip values)."""
    times_s: tuple[float, ...]
    frame_start: int
    """Index of the first frame (for file names)."""
    error: str | None = None
    """Why the variant cannot run (its overrides do not make a valid scene); recorded as failed."""
    stateful: bool = False
    """A pool animation: its frames step on from each other, with a checkpoint after each."""
    config: dict | None = None
    """The resolved configuration the id hashes (recorded in the manifest)."""
    memory: tuple[int, int, int] = (0, 0, 0)
    """What one render of it needs [bytes]: device memory on CUDA, on the CPU, and host memory for
    the read-back (``pipeline.scene_bytes``, ``pipeline.host_bytes``); the pool's check of
    ``--workers`` renders at once (:func:`~warpcaustics.batch.executors.check_workers_fit`)."""


@dataclass
class Sweep:
    base: Path
    tasks: list[Task]
    source: Path
    varied: list[str] = field(default_factory=list)
    """The grid and zip keys, in order (the study table's leading columns)."""


def _values(table: Any, key: str) -> dict[str, list]:
    if table is None:
        return {}
    if not isinstance(table, dict):
        raise ConfigError(
            f'sweep [{key}] must be a table of dotted keys, e.g. [{key}] "floor.depth_m" = [2.0]'
        )
    out = {}
    for name, values in table.items():
        if isinstance(values, dict):
            raise ConfigError(f'sweep [{key}] {name!r} is a table; quote dotted keys: "{name}.…" = [...]')
        if not isinstance(values, list) or not values:
            raise ConfigError(f"sweep [{key}] {name!r} must be a non-empty list of values")
        if key == "grid":  # a value twice would be the same task twice, racing on one folder
            twice = next((v for i, v in enumerate(values) if v in values[:i]), None)
            if twice is not None:
                raise ConfigError(f"sweep [grid] {name!r} lists {twice!r} twice; give each value once")
        out[name] = values
    return out


MAX_SWEEP_FRAMES = 100_000
"""The most frames one sweep (or field comparison) renders: past it the tasks alone would take
minutes to list and days to render, so it is refused before anything is built."""


def check_sweep_size(variants: int, frames: int, what: str) -> None:
    """Refuse a sweep of more than :data:`MAX_SWEEP_FRAMES` frames, naming ``what`` sets the count."""
    if variants * frames > MAX_SWEEP_FRAMES:
        raise ConfigError(f"{what}: {variants} variant(s) × {frames} frame(s) is more than "
                          f"{MAX_SWEEP_FRAMES} frames; split the sweep or render fewer frames")


FRAME_KEYS = ("count", "fps", "start_s")
"""The keys of a sweep's [frames] table."""


def load_sweep(path: str | Path, overrides: dict | None = None) -> Sweep:
    """Read a sweep TOML and expand it into tasks; every key and variant is validated before
    anything runs. ``overrides`` (the command line's ``--set``) join the sweep's [set]."""
    path = path_argument("load_sweep", "path", path, "a sweep's .toml file")
    overrides = overrides_argument("load_sweep", overrides)
    table = read_toml(path)
    unknown = set(table) - {"base", "set", "grid", "zip", "frames"}
    if unknown:
        raise ConfigError(f"sweep key(s) {sorted(unknown)} unknown; allowed: base, set, grid, zip, frames")
    if not isinstance(table.get("base"), str):
        raise ConfigError("sweep 'base' is missing; name the base scene, e.g. base = \"../ocean.toml\"")
    base = (path.parent / table["base"]).resolve()
    fixed = table.get("set", {})
    if not isinstance(fixed, dict):
        raise ConfigError("sweep [set] must be a table of dotted keys and values")
    fixed = {**fixed, **(overrides or {})}
    grid = _values(table.get("grid"), "grid")
    zipped = _values(table.get("zip"), "zip")
    lengths = {len(v) for v in zipped.values()}
    if len(lengths) > 1:
        raise ConfigError(f"sweep [zip] lists must have equal lengths; got {sorted(lengths)}")
    both = next((k for k in grid if k in zipped), None)
    if both is not None:
        raise ConfigError(f"sweep {both!r} is in both [grid] and [zip]; put it in one of them")
    rows = list(zip(*zipped.values()))
    twice = next((i for i, row in enumerate(rows) if row in rows[:i]), None)
    if twice is not None:
        raise ConfigError(f"sweep [zip] entry {twice + 1} repeats entry {rows.index(rows[twice]) + 1} "
                          f"({dict(zip(zipped, rows[twice]))}); give each combination once")
    for where, keys in (("sweep [set]", fixed), ("sweep [grid]", grid), ("sweep [zip]", zipped)):
        for key in keys:  # a misspelt key fails the sweep at once, not each of its tasks
            check_key(key, where)
    frames = table.get("frames", {})
    if not isinstance(frames, dict):
        raise ConfigError("sweep [frames] must be a table of count, fps and start_s")
    for key in frames:
        if key not in FRAME_KEYS:
            near = difflib.get_close_matches(key, FRAME_KEYS, n=1, cutoff=0.0)
            raise ConfigError(f"sweep [frames] key {key!r} is unknown; nearest valid key: {near[0]!r} "
                              f"(allowed: {', '.join(FRAME_KEYS)})")
    count = frames.get("count", 1)
    fps = frames.get("fps", 30.0)
    start = frames.get("start_s", 0.0)
    if not isinstance(count, int) or isinstance(count, bool) or count < 1:
        raise ConfigError(f"sweep frames.count = {count!r} must be a positive integer")
    if not isinstance(fps, (int, float)) or not fps > 0:
        raise ConfigError(f"sweep frames.fps = {fps!r} must be a positive number")
    if not isinstance(start, (int, float)) or isinstance(start, bool):
        raise ConfigError(f"sweep frames.start_s = {start!r} must be a number of seconds")
    variants = math.prod(len(v) for v in grid.values()) * (len(rows) if rows else 1)
    check_sweep_size(variants, count, "sweep [grid], [zip] and frames.count")
    times = tuple(float(start) + i / float(fps) for i in range(count))
    from warpcaustics.pipeline import check_time

    for name, t in (("sweep frames.start_s", times[0]), ("sweep frames' last time", times[-1])):
        check_time(name, t)
    sweep = expand_sweep(base, fixed, grid, zipped, times, path)
    errors = {task.error for task in sweep.tasks}
    if None not in errors and len(errors) == 1:  # the base or [set], not a variant: nothing would run
        raise ConfigError(f"every variant of {path.name} fails the same way, with base {base.name}: "
                          f"{errors.pop()}")
    return sweep


def expand_sweep(
    base: Path,
    fixed: dict,
    grid: dict[str, list],
    zipped: dict[str, list],
    times: tuple[float, ...],
    source: Path,
) -> Sweep:
    """The tasks of a sweep: every ``grid`` combination (with the ``zip`` lists as one more axis)
    applied after ``fixed``, each variant validated, and one task per frame time (a whole animation
    for the stateful pools). Also used by commands that build their sweep in code
    (``warpcaustics field``)."""
    from warpcaustics.pipeline import host_bytes, scene_bytes
    from warpcaustics.scene import load_scene

    read_toml(base)  # a missing or unreadable base fails the whole sweep (exit 2), not each task
    axes = [[(k, v) for v in values] for k, values in grid.items()]
    if zipped:
        axes.append([tuple(zip(zipped, combo)) for combo in zip(*zipped.values())])
    tasks: list[Task] = []
    for combo in itertools.product(*axes) if axes else [()]:
        overrides = dict(fixed)
        for item in combo:
            pairs = item if isinstance(item[0], tuple) else (item,)
            overrides.update(dict(pairs))
        try:
            scene = load_scene(base, overrides)
        except ConfigError as exc:  # a bad variant fails alone; the rest of the sweep runs
            tasks.append(Task(task_id({"overrides": overrides}, times), overrides, times, 0, str(exc)))
            continue
        resolved = config_to_dict(scene.config)
        stateful = scene.config.water.stateful  # the pools: frame k steps on from frame k-1
        short = _too_short_to_integrate(scene.config.stats.integration_s, times) if stateful else None
        if short is not None:  # refused before it renders, as the render command does
            tasks.append(Task(task_id(resolved, times), overrides, times, 0, short, stateful, resolved))
            continue
        groups = [times] if stateful else [(t,) for t in times]
        memory = (scene_bytes(scene, "cuda"), scene_bytes(scene, "cpu"), host_bytes(scene))
        inputs = input_digests(resolved, scene.base_dir)
        for i, group in enumerate(groups):
            tasks.append(Task(task_id(resolved, group, inputs), overrides, group, 0 if stateful else i, None,
                              stateful, resolved, memory))
    return Sweep(base, tasks, source, list(grid) + list(zipped))


def _too_short_to_integrate(integration_s: float, times: tuple[float, ...]) -> str | None:
    """Why an animation at ``times`` cannot give the time statistics of a radiometer integrating
    over ``integration_s`` (None: it can, or it has no time statistics)."""
    from warpcaustics.io.run_json import integration_frames

    if integration_s <= 0.0 or len(times) < 3:
        return None
    needed = integration_frames(integration_s, times[1] - times[0])
    if len(times) >= needed:
        return None
    return (f"stats.integration_s = {integration_s:g} needs frames.count ≥ {needed} at frames.fps "
            f"{1 / (times[1] - times[0]):g} for its time statistics; give more frames or a shorter "
            "integration_s")


def task_id(resolved_config: dict, times_s: tuple[float, ...], inputs: dict[str, str] | None = None) -> str:
    """Stable id: SHA-256 of the resolved config, the frame times and the package version, and of the
    contents of the files the config names (``inputs``: key → digest, :func:`input_digests`), so that
    a file changed under the same name is a new task, not a finished one."""
    record = {"config": resolved_config, "times_s": times_s, "version": __version__}
    if inputs:  # a config without files keeps the id it had
        record["inputs"] = inputs
    text = json.dumps(record, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def input_digests(resolved_config: dict, base_dir: Path) -> dict[str, str]:
    """SHA-256 of each file the config names (key → hex digest); a file is read once per sweep while its
    size and modification time stay the same."""
    from warpcaustics.scene import named_files

    digests = {}
    for key, path in named_files(resolved_config, base_dir).items():
        stat = path.stat()
        digests[key] = _file_digest(str(path.resolve()), stat.st_size, stat.st_mtime_ns)
    return digests


@functools.lru_cache(maxsize=256)
def _file_digest(path: str, size: int, mtime_ns: int) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for block in iter(lambda: fh.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


# ---------------------------------------------------------------------------------------------
# Driver


def _varied(sweep: Sweep, task: Task) -> str:
    """The task's values of the sweep's varied keys (its grid and zip), and its frame times."""
    from warpcaustics.io.toml_out import literal

    keys = sweep.varied or sorted(task.overrides)
    text = ", ".join(f"{k}={literal(task.overrides[k])}" for k in keys if k in task.overrides)
    times = "t=" + ",".join(f"{t:g}" for t in task.times_s)
    return f"{text}, {times}" if text else times


def sweep_hash(sweep: Sweep) -> str:
    return hashlib.sha256(" ".join(sorted(t.id for t in sweep.tasks)).encode()).hexdigest()[:16]


def _claim(out: Path, sweep: Sweep, force: bool) -> None:
    """A folder resumes the sweep it holds and refuses another one (a one-line error naming
    ``--force``, which lets the two share the folder); the first run records its hash."""
    record = out / SWEEP_RECORD
    for name in (MANIFEST, SWEEP_RECORD, SUMMARY):
        if (out / name).is_dir():
            raise WarpcausticsError(f"--out {str(out)!r} has a folder {name!r} where the sweep keeps its "
                                    "file; remove it or give another --out")
    mine = sweep_hash(sweep)
    if record.exists():
        try:
            theirs = json.loads(record.read_text(encoding="utf-8")).get("hash")
        except (OSError, ValueError, AttributeError):
            theirs = None
    elif (out / MANIFEST).exists():  # the record was lost: the tasks the manifest names say whose it is
        theirs = mine if set(read_manifest(out)) <= {t.id for t in sweep.tasks} else "unrecorded"
    else:
        theirs = None
    if not force and ((out / RUN_MANIFEST).exists() or (out / "run.json").exists()):
        raise WarpcausticsError(f"--out {str(out)!r} holds a render's outputs ({RUN_MANIFEST} or run.json); "
                                "give another --out, or --force to add the sweep beside them")
    if theirs not in (None, mine) and not force:
        raise WarpcausticsError(f"--out {str(out)!r} holds the results of another sweep (other keys, values, "
                                "frames, version, or files the configs name whose contents changed); give "
                                "another --out, or --force to add this one to it")
    if theirs is None or force or not record.exists():
        write_json(record, {"hash": mine, "version": __version__, "source": str(sweep.source)})


def read_manifest(out_dir: Path) -> dict[str, dict]:
    """The last record of each task id. A line that is not a task's record — cut by a crash, or
    damaged — is ignored, so its task counts as not done and renders again."""
    records: dict[str, dict] = {}
    path = out_dir / MANIFEST
    if path.exists():
        for line in path.read_bytes().splitlines():
            try:
                rec = json.loads(line.decode("utf-8"))
            except (UnicodeDecodeError, json.JSONDecodeError):
                continue
            if _is_record(rec):
                records[rec["id"]] = rec
    return records


NUMBER_COLUMNS = ("frame", "time_s", "floor_w_m2", "contrast", "cv", "render_s")
"""A summary row's columns that are numbers in every sweep (``warpcaustics report`` plots some)."""


def _finished_ids(out: Path, sweep: Sweep) -> set[str]:
    """The tasks a rerun into ``out`` skips: recorded as done, their folders whole (read only, so it
    can be asked before the folder is claimed)."""
    records = read_manifest(out) if out.is_dir() else {}
    return {task.id for task in sweep.tasks
            if records.get(task.id, {}).get("state") == "done" and _finished(out / task.id, task)}


def _finished(folder: Path, task: Task) -> bool:
    """Whether a task's folder holds its finished run: a ``run.json`` that reads as one, with a record
    for each of its frames and that frame's statistics (a damaged one renders again)."""
    try:
        frames = json.loads((folder / "run.json").read_text(encoding="utf-8"))["frames"]
        return len(frames) == len(task.times_s) and all(
            isinstance(f["statistics"]["irradiance_w_m2"]["cv"], (int, float)) for f in frames)
    except (OSError, ValueError, TypeError, KeyError):
        return False


def _is_record(rec) -> bool:
    """A task's manifest record: an id, and if done, its rows, whose statistics are numbers."""
    if not (isinstance(rec, dict) and isinstance(rec.get("id"), str)):
        return False
    if rec.get("state") != "done":
        return True
    rows = rec.get("rows")
    return isinstance(rows, list) and bool(rows) and all(
        isinstance(row, dict) and all(isinstance(row.get(c, 0.0), (int, float)) for c in NUMBER_COLUMNS)
        for row in rows)


def _append(out_dir: Path, record: dict) -> None:
    """Add ``record`` as a line of the manifest. A line a killed driver left cut (no newline at the
    end of the file) is ended first, so that this record stands on a line of its own rather than
    merging into the cut one, where :func:`read_manifest` would lose it too."""
    line = json.dumps(record, default=str) + "\n"
    with open(out_dir / MANIFEST, "a+b") as fh:
        if fh.seek(0, os.SEEK_END) > 0:
            fh.seek(-1, os.SEEK_END)
            if fh.read(1) != b"\n":
                line = "\n" + line
        fh.write(line.encode("utf-8"))  # appended at the end whatever the position
        fh.flush()
        os.fsync(fh.fileno())


@dataclass
class SweepReport:
    done: int = 0
    skipped: int = 0
    failed: list[tuple[str, str]] = field(default_factory=list)
    seconds: float = 0.0


def run_sweep(
    sweep: Sweep,
    out_dir: str | Path,
    *,
    workers: int = 1,
    device: str | None = None,
    quiet: bool = False,
    executor: str = "local",
    address: str | None = None,
    force: bool = False,
) -> SweepReport:
    """Run every unfinished task of ``sweep`` into ``out_dir``: with a local process pool
    (``executor = "local"``, ``workers`` processes) or on Ray (``"ray"``: the cluster at ``address``,
    or a local instance of ``workers`` CPUs started and stopped here). Workers write the task
    folders; the driver alone keeps the manifest."""
    if not isinstance(sweep, Sweep):
        raise ConfigError(f"run_sweep() takes a sweep from load_sweep(path); got {type(sweep).__name__} "
                          f"{sweep!r:.60}")
    if executor not in ("local", "ray"):
        raise WarpcausticsError(f"--executor {executor!r} is not allowed; allowed: local, ray")
    workers = workers_argument(workers)
    out = path_argument("run_sweep", "out_dir", out_dir, "the output folder")
    finished = _finished_ids(out, sweep)
    todo = [t for t in sweep.tasks if t.error is None and t.id not in finished]
    if executor == "local":  # checked once here, before anything is written
        from warpcaustics.device import resolve_device

        configured = {t.config.get("device", "auto") for t in sweep.tasks if t.config}
        if device is not None:
            device = resolve_device(device)
        elif len(configured) == 1 and todo:
            # the config's device (or $WARPCAUSTICS_DEVICE), said once; a finished sweep needs none
            device = resolve_device(None, config_value=configured.pop())
        check_workers_fit(todo, workers, device)
    output_folder("--out", out)
    with folder_lock(out):  # a second run into the same folder is refused, not interleaved
        _claim(out, sweep, force)
        for task in sweep.tasks:  # a killed run's half-written tasks: by this sweep's own task ids only
            shutil.rmtree(task_tmp_dir(out, task.id), ignore_errors=True)
        report = SweepReport(skipped=sum(t.error is None and t.id in finished for t in sweep.tasks))
        for task in (t for t in sweep.tasks if t.error is not None):
            _append(
                out,
                {
                    "id": task.id,
                    "version": __version__,
                    "overrides": task.overrides,
                    "state": "failed",
                    "error": task.error,
                },
            )
            report.failed.append((task.id, task.error))
        t0 = time.perf_counter()
        progress = Progress(len(todo), quiet)

        def finish(task: Task, outcome: dict | None, error: BaseException | None) -> None:
            record = {
                "id": task.id,
                "version": __version__,
                "config": task.config,
                "overrides": task.overrides,
                "times_s": list(task.times_s),
            }
            if error is not None:  # a failing task is recorded and the sweep goes on
                message = _error_line(error)
                _append(out, {**record, "state": "failed", "error": message})
                report.failed.append((task.id, message))
                progress.step(f"FAILED {task.id} ({_varied(sweep, task)}): {message}")
                return
            _append(
                out,
                {
                    **record,
                    "state": "done",
                    "seconds": outcome["seconds"],
                    "device": outcome["device"],
                    "rows": outcome["rows"],
                },
            )
            report.done += 1
            progress.step(f"done {task.id} ({_varied(sweep, task)}) in {outcome['seconds']:.1f} s")

        try:
            if executor == "ray":
                run_on_ray(sweep, todo, out, workers, device, address, finish)
            else:
                run_locally(sweep, todo, out, workers, device, finish)
        finally:
            progress.close()
        report.seconds = time.perf_counter() - t0
        write_summary(out, sweep)
        return report


def _error_line(error: BaseException) -> str:
    """One line for a failed task; Ray's wrapped errors are unwrapped to their cause."""
    from concurrent.futures.process import BrokenProcessPool

    cause = getattr(error, "cause", None)
    if isinstance(cause, BaseException):
        error = cause
    if isinstance(error, BrokenProcessPool):  # the pool's own words say nothing of why
        return ("BrokenProcessPool: a worker process died (killed, most often for lack of memory); rerun "
                "the same command with fewer --workers to finish the rest")
    text = str(error).strip()
    return f"{type(error).__name__}: {text.splitlines()[0] if text else ''}"



def write_summary(out_dir: Path, sweep: Sweep) -> Path:
    """``summary.csv`` (and ``summary.parquet`` if pyarrow is installed): one row per frame of the
    sweep's finished tasks, in task order; written atomically."""
    records = read_manifest(out_dir)
    rows = [
        row
        for task in sweep.tasks
        if records.get(task.id, {}).get("state") == "done"
        for row in records[task.id]["rows"]
    ]
    path = out_dir / SUMMARY
    columns: list[str] = []
    for row in rows:
        columns += [c for c in row if c not in columns]
    write_csv(path, rows, columns)
    try:
        import pyarrow as pa
        import pyarrow.parquet as pq
    except ImportError:
        return path
    with atomic_path(out_dir / "summary.parquet") as tmp:
        pq.write_table(pa.Table.from_pylist(rows), tmp)
    return path


def format_report(report: SweepReport) -> str:
    lines = [
        f"done {report.done}, skipped {report.skipped} (finished before), failed {len(report.failed)}"
        f"  in {report.seconds:.1f} s"
    ]
    lines += [f"  failed {tid}: {msg}" for tid, msg in report.failed]
    return "\n".join(lines)


def sweep_main(
    path: str,
    out: str,
    workers: int,
    device: str | None,
    quiet: bool,
    executor: str = "local",
    address: str | None = None,
    overrides: dict | None = None,
    force: bool = False,
) -> int:
    sweep = load_sweep(path, overrides)
    report = run_sweep(
        sweep, out, workers=workers, device=device, quiet=quiet, executor=executor, address=address,
        force=force,
    )
    print(format_report(report), file=sys.stdout)
    print(f"summary: {Path(out) / SUMMARY}")
    return 1 if report.failed else 0
