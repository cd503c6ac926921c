"""Shared fixtures: the ``device`` fixture runs a test on the CPU and, where present, on CUDA.

Shared functions and paths live in ``helpers.py`` (``from helpers import CONFIGS``): a conftest is
pytest's to load, not a module to import."""

from __future__ import annotations

import numpy as np
import pytest
import warp as wp

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

