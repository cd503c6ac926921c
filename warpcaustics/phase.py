"""Phase functions of in-water scattering (host side): Henyey–Greenstein or Petzold (1972).

Petzold's volume scattering functions come from the ``jerlov`` package (eight stations at 530 nm,
0.1–180°, total: water and particles); the phase function is p(θ) = β(θ)/b with the station's
measured b. Below 0.1° (unmeasured; the package gives the fraction of b there) the table holds its
0.1° value. Henyey–Greenstein's g defaults to the mean cosine of that Petzold station, computed
from the table, so both options describe the same water.
"""

from __future__ import annotations

import functools
import warnings
from dataclasses import dataclass

import numpy as np
import warp as wp

from warpcaustics.config import OpticsConfig, PhaseFunctionKind
from warpcaustics.kernels import phase as phase_kernels


@functools.cache
def petzold_table(station: str) -> tuple[np.ndarray, np.ndarray, float]:
    """(θ [rad], p(θ) [1/sr], fraction of scattering below the first angle) of a Petzold station."""
    import jerlov

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        vsf = jerlov.petzold_scattering(station)
    return np.radians(vsf.angles_deg), np.asarray(vsf.vsf) / vsf.b, float(vsf.fraction_below_0_1_deg)


def mean_cosine(theta: np.ndarray, p: np.ndarray) -> float:
    """∫ cosθ p dΩ / ∫ p dΩ over the tabulated angles (trapezoid in θ)."""
    weight = 2.0 * np.pi * np.sin(theta) * p
    return float(np.trapezoid(np.cos(theta) * weight, theta) / np.trapezoid(weight, theta))


@dataclass
class PhaseFunction:
    """A phase function ready for the device: kind, g and the (possibly unused) table."""

    kind: int
    """0 = Henyey–Greenstein, 1 = tabulated (Petzold)."""
    g: float
    angles_rad: wp.array
    log_phase: wp.array

    @classmethod
    def from_optics(cls, optics: OpticsConfig, device: str) -> PhaseFunction:
        theta, p, _ = petzold_table(optics.petzold_station)
        g = optics.hg_g if optics.hg_g is not None else mean_cosine(theta, p)
        kind = 0 if optics.phase_function is PhaseFunctionKind.HENYEY_GREENSTEIN else 1
        return cls(kind, float(g), wp.array(theta.astype(np.float32), dtype=wp.float32, device=device),
                   wp.array(np.log(p).astype(np.float32), dtype=wp.float32, device=device))

    def evaluate(self, cos_theta: np.ndarray, device: str) -> np.ndarray:
        """p(cos θ) [1/sr] for an array of cosines, computed by the device function."""
        c = wp.array(np.asarray(cos_theta, np.float32), dtype=wp.float32, device=device)
        out = wp.empty(len(c), dtype=wp.float32, device=device)
        wp.launch(phase_kernels.evaluate_phase, dim=len(c),
                  inputs=[c, self.kind, self.g, self.angles_rad, self.log_phase], outputs=[out],
                  device=device)
        return out.numpy()
