"""Where a sweep's tasks run: a local pool of worker processes that die with the driver, or Ray.

Each executor submits :func:`warpcaustics.batch.worker.run_task` per task and calls
``finish(task, outcome, error)`` in the driver as tasks complete; the driver alone writes the
manifest.
"""

from __future__ import annotations

import os
import time
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from pathlib import Path
from typing import TYPE_CHECKING

from warpcaustics.batch.threads import one_blas_thread_per_worker
from warpcaustics.batch.worker import run_task
from warpcaustics.errors import WarpcausticsError

if TYPE_CHECKING:
    from warpcaustics.batch.sweep import Sweep, Task


def die_with_parent(parent_pid: int) -> None:
    """Worker initializer: end this process when the driver goes (Linux parent-death signal, plus
    a thread that checks the parent every half second elsewhere). Ctrl-C, which a terminal sends to
    the whole process group, is the driver's to handle: a worker that took it as its task's error
    went on to the next task in its queue."""
    import signal
    import threading

    signal.signal(signal.SIGINT, signal.SIG_IGN)

    try:
        import ctypes

        libc = ctypes.CDLL("libc.so.6", use_errno=True)
        libc.prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):
        pass

    def watch() -> None:
        while True:
            if os.getppid() != parent_pid:
                os._exit(1)
            time.sleep(0.5)

    threading.Thread(target=watch, daemon=True).start()


WORKER_PROCESS_BYTES = 400 * 2**20
"""A worker process's own host memory beside its scene's [bytes]: Python with Warp's CPU runtime,
numpy and the writers imported; a two-worker sweep of 32² renders peaked at 360 MB resident a
worker (``ru_maxrss`` of the children, docs/benchmarks.md)."""


def check_workers_fit(todo: list[Task], workers: int, device: str | None) -> None:
    """Refuse, in one line before anything is written, ``workers`` processes whose renders at once
    (as many as there are tasks ``todo``, each the largest) would not fit in the free host memory,
    or on ``device``'s if it is a GPU that they share; a single render keeps the Renderer's own check."""
    from warpcaustics import device as devices

    at_once = min(workers, len(todo))
    if at_once < 2 or device is None:  # None: the tasks name devices of their own
        return
    gib = 2.0**30
    on_gpu = device.startswith("cuda")
    host = WORKER_PROCESS_BYTES + max(t.memory[2] + (0 if on_gpu else t.memory[1]) for t in todo)
    needs = [(host, devices.host_available_bytes(), "host memory")]
    if on_gpu:
        needs.append((max(t.memory[0] for t in todo), devices.free_bytes(device), f"memory on {device}"))
    for each, free, what in needs:
        if free is not None and at_once * each > free:
            fit = max(1, int(free // each))
            raise WarpcausticsError(
                f"--workers {workers}: {at_once} renders at once need about {at_once * each / gib:.1f} GiB "
                f"of {what} but {free / gib:.1f} GiB is free; use --workers {fit} or fewer")


def run_locally(sweep: Sweep, todo: list[Task], out: Path, workers: int, device: str | None, finish) -> None:
    import multiprocessing

    devices = {t.config.get("device", "auto") for t in todo if t.config}
    if device is None and todo and len(devices) == 1:
        # chosen once here, so "no CUDA device found" is said once, not by every worker
        from warpcaustics.device import resolve_device

        device = resolve_device(None, config_value=devices.pop())
    context = multiprocessing.get_context("spawn")  # no forked Warp/CUDA state in the workers
    with one_blas_thread_per_worker(), ProcessPoolExecutor(
        max_workers=workers, mp_context=context, initializer=die_with_parent, initargs=(os.getpid(),)
    ) as pool:
        pending = {pool.submit(run_task, str(sweep.base), task, str(out), device): task for task in todo}
        try:
            while pending:
                finished, _ = wait(pending, return_when=FIRST_COMPLETED)
                for future in finished:
                    task = pending.pop(future)
                    try:
                        outcome = future.result()
                    except Exception as exc:
                        finish(task, None, exc)
                    else:
                        finish(task, outcome, None)
        except BaseException:  # Ctrl-C: stop now, not after every queued task (a rerun resumes)
            stop_workers(pool)
            raise


def stop_workers(pool: ProcessPoolExecutor) -> None:
    """Cancel what has not started and end the workers mid-task: their half-written task folders are
    temporary ones, which the next run removes."""
    processes = list((getattr(pool, "_processes", None) or {}).values())  # shutdown forgets them
    pool.shutdown(wait=False, cancel_futures=True)
    for process in processes:
        process.terminate()


def run_on_ray(
    sweep: Sweep, todo: list[Task], out: Path, workers: int, device: str | None, address: str | None, finish
) -> None:
    """One Ray task per sweep task (``num_gpus=1`` when rendering on CUDA); the workers write to
    ``out``, which must be storage they share with the driver."""
    import importlib.util

    try:
        import ray
    except ImportError:
        raise WarpcausticsError("--executor ray needs Ray: pip install 'warpcaustics[ray]'") from None
    if address and address.startswith("ray://") and importlib.util.find_spec("grpc") is None:
        raise WarpcausticsError(f"--address {address!r} is a Ray client address, which needs Ray's client "
                                "(ray[client]): pip install 'warpcaustics[ray]'")
    started = not ray.is_initialized()
    if started:
        try:
            ray.init(
                address=address,
                num_cpus=None if address else workers,
                include_dashboard=False,
                log_to_driver=False,
                configure_logging=False,
            )
        except (ConnectionError, RuntimeError, ValueError, TimeoutError) as exc:
            first = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
            raise WarpcausticsError(f"--address {address!r}: Ray could not start or connect ({first}); "
                                    "check the address, or leave it out for a local Ray") from None
    try:
        gpus = 1 if device is not None and device.startswith("cuda") else 0
        remote = ray.remote(num_cpus=1, num_gpus=gpus, max_retries=0)(run_task)
        pending = {remote.remote(str(sweep.base), task, str(out.resolve()), device): task for task in todo}
        while pending:
            ready, _ = ray.wait(list(pending), num_returns=1)
            for ref in ready:
                task = pending.pop(ref)
                try:
                    outcome = ray.get(ref)
                except Exception as exc:
                    finish(task, None, exc)
                else:
                    finish(task, outcome, None)
    finally:
        if started:
            ray.shutdown()
