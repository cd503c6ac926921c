"""Shared fixtures: the ``device`` fixture runs a test on the CPU and, where present, on CUDA."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import warp as wp

wp.config.log_level = max(wp.config.log_level, wp.LOG_WARNING)
wp.init()

_CUDA = wp.get_cuda_device_count() > 0
ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(autouse=True, scope="session")
def _run_from_the_repository_root():
    """Tests and the benchmarks they import open ``configs/…`` by relative path: run the session
    from the repository root, wherever pytest was started (a test may still chdir elsewhere)."""
    with pytest.MonkeyPatch.context() as patch:
        patch.chdir(ROOT)
        yield


@pytest.fixture(params=["cpu", "cuda:0"])
def device(request) -> str:
    """Warp device for a test; CUDA is skipped (and reported) where there is none."""
    if request.param.startswith("cuda") and not _CUDA:
        pytest.skip("no CUDA device")
    return request.param


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(20261125)


def fresnel_t_angles(theta_i: np.ndarray, n1: float, n2: float) -> np.ndarray:
    """Unpolarised Fresnel transmittance from the angle form of Fresnel's equations (float64).

    rs = -sin(θi-θt)/sin(θi+θt), rp = tan(θi-θt)/tan(θi+θt) (Born & Wolf §1.5.2); at normal
    incidence R = ((n1-n2)/(n1+n2))^2. Written independently of the code under test.
    """
    theta_i = np.asarray(theta_i, dtype=np.float64)
    sin_t = n1 / n2 * np.sin(theta_i)
    out = np.zeros_like(theta_i)
    ok = sin_t < 1.0
    ti = theta_i[ok]
    tt = np.arcsin(sin_t[ok])
    normal = ti < 1e-6
    with np.errstate(invalid="ignore", divide="ignore"):
        rs = -np.sin(ti - tt) / np.sin(ti + tt)
        rp = np.tan(ti - tt) / np.tan(ti + tt)
    r = np.where(normal, ((n1 - n2) / (n1 + n2)) ** 2, 0.5 * (rs**2 + rp**2))
    out[ok] = 1.0 - r
    return out
