"""Progress of a sweep's tasks or a render's frames on the terminal or in a log, and what happens to
it when its reader goes away."""

from __future__ import annotations

import os
import sys
import time


def stdout_to_devnull() -> None:
    """Send what is still printed to /dev/null: the pipe stdout wrote to was closed by its reader, and
    the line that met it (or the interpreter's last flush) would otherwise raise BrokenPipeError."""
    devnull = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError):  # no file descriptor to replace (a StringIO under test)
        pass
    finally:
        os.close(devnull)


class Progress:
    """Progress of many tasks or frames: a tqdm bar with throughput and ETA on a terminal, one plain
    line per step otherwise (logs, CI), nothing when quiet."""

    def __init__(self, total: int, quiet: bool, unit: str = "task"):
        self.total, self.quiet, self.count, self.t0 = total, quiet, 0, time.perf_counter()
        self.bar = None
        if not quiet and sys.stdout.isatty():
            from tqdm import tqdm

            self.bar = tqdm(total=total, unit=unit, dynamic_ncols=True)

    def step(self, text: str) -> None:
        self.count += 1
        if self.quiet:
            return
        if self.bar is not None:
            self.bar.set_postfix_str(text[:60], refresh=False)
            self.bar.update(1)
            return
        elapsed = time.perf_counter() - self.t0
        rate = self.count / elapsed if elapsed > 0 else 0.0
        eta = (self.total - self.count) / rate if rate > 0 else 0.0
        try:
            print(f"[{self.count}/{self.total}] {text}  ({rate * 60:.1f}/min, ETA {eta:.0f} s)", flush=True)
        except BrokenPipeError:  # the reader went away (`| head -1`): the work goes on, unprinted
            self.quiet = True
            stdout_to_devnull()

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
