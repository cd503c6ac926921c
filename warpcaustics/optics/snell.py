"""Snell's law and Fresnel's equations on numpy arrays in float64, for the host-side optics (the
walked beam spread, the small-angle transfer's refracted paths, the view from above, the sky's
cells) and for the float64 references (:mod:`warpcaustics.reference`); the kernels have their own
(``kernels/geometry.py``)."""

from __future__ import annotations

import numpy as np


def fresnel_transmittance(cos_i: np.ndarray, eta: float) -> np.ndarray:
    """Exact unpolarised Fresnel transmittance for ``eta = n1/n2`` (0 on TIR or cos_i <= 0)."""
    cos_i = np.asarray(cos_i, dtype=np.float64)
    k = 1.0 - eta**2 * (1.0 - cos_i**2)
    ok = (cos_i > 0) & (k > 0)
    cos_t = np.sqrt(np.where(ok, k, 1.0))
    ci = np.where(ok, cos_i, 1.0)
    rs = (eta * ci - cos_t) / (eta * ci + cos_t)
    rp = (ci - eta * cos_t) / (ci + eta * cos_t)
    return np.where(ok, 1.0 - 0.5 * (rs**2 + rp**2), 0.0)


def refract(d: np.ndarray, n: np.ndarray, eta: float) -> np.ndarray:
    """Snell's law for arrays of unit vectors (..., 3); zero vectors on TIR."""
    c = -np.sum(n * d, axis=-1, keepdims=True)
    k = 1.0 - eta**2 * (1.0 - c**2)
    t = eta * d + (eta * c - np.sqrt(np.maximum(k, 0.0))) * n
    return np.where(k >= 0, t, 0.0)
