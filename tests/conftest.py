"""Shared fixtures: the ``device`` fixture runs a test on the CPU and, where present, on CUDA.

Shared functions and paths live in ``helpers.py`` (``from helpers import CONFIGS``): a conftest is
pytest's to load, not a module to import."""

from __future__ import annotations

# One BLAS thread per test process: xdist's workers are the parallelism, and a worker's BLAS threads
# spinning against the others' on a 2-core runner made PythonicDISORT's solves 10× slower. Set here,
# before pytest-xdist starts its workers, so that their numpy reads it at import.
from warpcaustics.batch.threads import one_blas_thread  # imports nothing heavy

one_blas_thread()

import numpy as np  # noqa: E402
import pytest  # noqa: E402
import warp as wp  # noqa: E402

wp.config.log_level = max(wp.config.log_level, wp.LOG_WARNING)
wp.init()

_CUDA = wp.get_cuda_device_count() > 0


@pytest.fixture(params=["cpu", "cuda:0"])
def device(request) -> str:
    """Warp device for a test; CUDA is skipped (and reported) where there is none."""
    if request.param.startswith("cuda") and not _CUDA:
        pytest.skip("no CUDA device")
    return request.param


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(20261125)

