"""One BLAS thread per process where processes are the parallelism: the environment variables that
set numpy's and scipy's BLAS threads (read when numpy is imported), set unless the user chose.

A worker's BLAS threads spinning against the other workers on the same cores made a solver's many
small products 10× slower (PythonicDISORT on a 2-core runner). Imports nothing heavy, so that a
script or conftest can call it before numpy loads.
"""

from __future__ import annotations

import contextlib
import os

NUMERIC_THREADS = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")
"""The environment variables that set numpy's and scipy's BLAS threads, read at import."""


def one_blas_thread() -> list[str]:
    """Set each of :data:`NUMERIC_THREADS` the user has not set to 1; the ones set."""
    added = [var for var in NUMERIC_THREADS if var not in os.environ]
    os.environ.update(dict.fromkeys(added, "1"))
    return added


@contextlib.contextmanager
def one_blas_thread_per_worker():
    """While a pool starts its workers, their BLAS on one thread each (unless the user chose): the
    workers are the parallelism."""
    added = one_blas_thread()
    try:
        yield
    finally:
        for var in added:
            os.environ.pop(var, None)
