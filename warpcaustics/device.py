"""Choosing the Warp device and checking that a scene fits in its memory."""

from __future__ import annotations

import os
import sys

from warpcaustics.errors import DeviceError

DEVICE_ENV = "WARPCAUSTICS_DEVICE"
"""Environment variable that overrides the config's ``device`` (the CLI's --device wins over it)."""

_GIB = 1024.0**3
_notice_given = False


def _warp():
    import warp as wp

    try:
        if os.environ.get("WARPCAUSTICS_VERBOSE"):
            wp.init()
            return wp
        # Warp's info lines (init banner, module loads) drown our one-line messages, and on a machine
        # without a GPU its native library prints a driver warning on every start; our own notice
        # (see resolve_device) says the same once. Anything else it prints is passed on.
        wp.config.log_level = max(wp.config.log_level, wp.LOG_WARNING)
        _init_filtering_stderr(wp)  # later calls are cheap: wp.init() runs once
    except OSError as exc:  # its kernel cache (under $HOME unless WARP_CACHE_PATH) cannot be made
        where = f"{str(exc.filename)!r}: " if exc.filename else ""
        raise DeviceError(f"Warp cannot start: {where}{exc.strerror or exc}; its kernel cache must be "
                          "writable: set WARP_CACHE_PATH to a folder you can write to (or make HOME "
                          "writable)") from None
    return wp


def _init_filtering_stderr(wp) -> None:
    """``wp.init()`` with the native 'no CUDA driver' warning removed from stderr."""
    import tempfile

    sys.stderr.flush()
    saved = os.dup(2)
    with tempfile.TemporaryFile(mode="w+b") as capture:
        os.dup2(capture.fileno(), 2)
        try:
            wp.init()
        finally:
            os.dup2(saved, 2)
            os.close(saved)
        capture.seek(0)
        for line in capture.read().decode(errors="replace").splitlines(keepends=True):
            if "Could not find or load the NVIDIA CUDA driver" not in line:
                sys.stderr.write(line)
    sys.stderr.flush()


def resolve_device(requested: str | None, *, config_value: str = "auto") -> str:
    """Pick a Warp device name from (in order) the argument, ``$WARPCAUSTICS_DEVICE``, the config.

    ``auto`` means CUDA when available, else the CPU with a one-line notice on stderr; an explicit
    ``cuda`` (or ``cuda:N``) where there is none is an error.
    """
    if requested is not None and (not isinstance(requested, str) or not requested.strip()):
        raise DeviceError(f"device = {requested!r} must be a name: auto, cpu, cuda or cuda:N")
    from_env = (os.environ.get(DEVICE_ENV) or "").strip() or None  # set but blank: not set
    choice = requested or from_env or config_value or "auto"
    choice = choice.strip().lower()
    wp = _warp()
    if choice == "cpu":
        return "cpu"
    if choice == "auto":
        if wp.get_cuda_device_count() > 0:
            return "cuda:0"
        global _notice_given
        if not _notice_given:
            print("warpcaustics: no CUDA device found; running on the CPU", file=sys.stderr)
            _notice_given = True
        return "cpu"
    if choice == "cuda" or choice.startswith("cuda:"):
        index = 0 if choice == "cuda" else _cuda_index(choice)  # the name's form first: its fix is the name
        count = wp.get_cuda_device_count()
        if count == 0:
            raise DeviceError(f"device = {choice!r} was asked for but no CUDA device is available "
                              f"(driver missing or no GPU); use --device cpu or device = \"auto\"")
        if index >= count:
            raise DeviceError(f"device = {choice!r} does not exist; this machine has {count} CUDA "
                              f"device(s): cuda:0..cuda:{count - 1}")
        return f"cuda:{index}"
    raise DeviceError(f"device = {choice!r} is not allowed; allowed: auto, cpu, cuda, cuda:N "
                      f"(from --device, ${DEVICE_ENV} or the config's device key)")


def _cuda_index(choice: str) -> int:
    try:
        index = int(choice.split(":", 1)[1])
    except ValueError:
        raise DeviceError(f"device = {choice!r} is not allowed; use cuda:N with N an integer") from None
    if index < 0:
        raise DeviceError(f"device = {choice!r} is not allowed; use cuda:N with N = 0 for the first device")
    return index


MEMINFO = "/proc/meminfo"

CGROUPS = (
    ("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current", "/sys/fs/cgroup/memory.stat",
     "inactive_file"),
    ("/sys/fs/cgroup/memory/memory.limit_in_bytes", "/sys/fs/cgroup/memory/memory.usage_in_bytes",
     "/sys/fs/cgroup/memory/memory.stat", "total_inactive_file"),
)
"""A container's memory limit, its usage and the usage's reclaimable page cache: cgroup v2, then v1."""


def free_bytes(device: str) -> int | None:
    """Free memory on the device in bytes, or None where it cannot be told."""
    wp = _warp()
    if device.startswith("cuda"):
        return int(wp.get_device(device).free_memory)
    return host_available_bytes()


def host_available_bytes() -> int | None:
    """Host memory a run can still allocate [bytes]: the kernel's MemAvailable (free pages and the
    page cache it can reclaim; free pages alone, ``SC_AVPHYS_PAGES``, where there is no
    /proc/meminfo), and within a container's cgroup limit less its usage but the reclaimable cache
    (the working set). None where none of these can be read."""
    available = _field(MEMINFO, "MemAvailable:")
    if available is not None:
        available *= 1024  # kB
    else:
        try:
            available = os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
        except (ValueError, OSError, AttributeError):  # pragma: no cover - not POSIX
            return None
    for limit_path, usage_path, stat_path, cache_key in CGROUPS:
        limit, usage = _field(limit_path), _field(usage_path)
        if limit is None or usage is None:  # absent, or "max": no limit
            continue
        working_set = usage - (_field(stat_path, cache_key) or 0)
        return min(available, max(limit - working_set, 0))
    return available


def _field(path: str, key: str | None = None) -> int | None:
    """The integer a file holds (``key`` None), or the one after ``key`` on its line of ``key value``
    pairs; None where the file, the key or the number is missing."""
    try:
        with open(path, encoding="ascii") as fh:
            for line in fh:
                words = line.split()
                if key is None:
                    return int(words[0])
                if words[:1] == [key]:
                    return int(words[1])
    except (OSError, ValueError, IndexError):
        pass
    return None


def check_fits(device: str, needed_bytes: int, what: str) -> None:
    """Fail before allocating when a scene needs more memory than the device has free."""
    free = free_bytes(device)
    if free is not None and needed_bytes > free:
        raise DeviceError(f"the scene needs {needed_bytes / _GIB:.2f} GiB on {device} but only "
                          f"{free / _GIB:.2f} GiB is free; {what}")


def out_of_memory(device: str, needed_bytes: int, what: str) -> DeviceError:
    return DeviceError(f"out of memory on {device}: the scene needs about {needed_bytes / _GIB:.2f} "
                       f"GiB; {what}")
