"""Phase functions of in-water scattering (host side): Henyey–Greenstein or Petzold (1972).

Petzold's volume scattering functions come from the ``jerlov`` package (eight stations at 530 nm,
0.1–180°, total: water and particles); the phase function is β(θ)/b, normalised over the sphere:
the measured share f of scattering below 0.1° sits in a forward cone of constant p, and the table
is scaled to carry the rest, 1 − f. Henyey–Greenstein's g defaults to the mean cosine of that
Petzold station (cone included), so both options describe the same water.
"""

from __future__ import annotations

import functools
import warnings
from dataclasses import dataclass

import numpy as np
import warp as wp

from warpcaustics.config import OpticsConfig, PhaseFunctionKind
from warpcaustics.kernels.optics import phase as phase_kernels


@functools.cache
def petzold_table(station: str) -> tuple[np.ndarray, np.ndarray, float, float]:
    """A Petzold station's phase function, normalised over the whole sphere.

    Returns (θ [rad], p(θ) [1/sr] at the measured angles, p in the forward cone θ < θ0 [1/sr], the
    share of scattering in that cone). The table (0.1–180°) is scaled so that, with ln p linear in θ
    as on the device, it integrates to 1 − f, f being the station's measured share below 0.1°; the
    cone holds f at a constant p.
    """
    import jerlov

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        vsf = jerlov.petzold_scattering(station)
    theta = np.radians(vsf.angles_deg)
    p = np.asarray(vsf.vsf, dtype=np.float64) / vsf.b
    f = float(vsf.fraction_below_0_1_deg)
    fine = np.linspace(theta[0], np.pi, 400001)
    table = np.exp(np.interp(fine, theta, np.log(p)))
    table_integral = 2.0 * np.pi * np.trapezoid(table * np.sin(fine), fine)
    p = p * (1.0 - f) / table_integral
    cone = f / (2.0 * np.pi * (1.0 - np.cos(theta[0])))
    return theta, p, cone, f


def table_on_grid(theta: np.ndarray, p: np.ndarray, cone: float, grid: np.ndarray) -> np.ndarray:
    """p [1/sr] of a :func:`petzold_table` on any angle grid [rad]: ln p linear in θ between the
    table's angles (as on the device), the constant ``cone`` below its first angle."""
    theta = np.asarray(theta, np.float64)
    table = np.exp(np.interp(grid, theta, np.log(np.asarray(p, np.float64))))
    return np.where(grid < theta[0], cone, table)


def solid_angle_weights(theta: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Trapezoid weights of 2π p(θ) sin θ dθ on the grid ``theta`` [rad]: Σ weights × f(θ) is
    ∫ f p dΩ over the sphere."""
    step = np.diff(theta)
    width = 0.5 * (np.concatenate([step, [0.0]]) + np.concatenate([[0.0], step]))
    return 2.0 * np.pi * p * np.sin(theta) * width


def mean_cosine(theta: np.ndarray, p: np.ndarray, cone: float) -> float:
    """∫ cosθ p dΩ over the sphere for a table (ln p linear in θ) plus its forward cone."""
    fine = np.linspace(theta[0], np.pi, 400001)
    pf = np.exp(np.interp(fine, theta, np.log(p)))
    forward = 2.0 * np.pi * cone * (1.0 - np.cos(theta[0]) ** 2) / 2.0  # ∫ cosθ sinθ dθ over the cone
    return float(2.0 * np.pi * np.trapezoid(np.cos(fine) * pf * np.sin(fine), fine) + forward)


@dataclass
class PhaseFunction:
    """A phase function ready for the device: kind, g and the (possibly unused) table."""

    kind: int
    """0 = Henyey–Greenstein, 1 = tabulated (Petzold)."""
    g: float
    angles_rad: wp.array
    log_phase: wp.array
    cone_phase: float
    """p [1/sr] inside the forward cone below the table's first angle."""

    @classmethod
    def from_optics(cls, optics: OpticsConfig, device: str) -> PhaseFunction:
        theta, p, cone, _ = petzold_table(optics.petzold_station.value)
        g = optics.hg_g if optics.hg_g is not None else mean_cosine(theta, p, cone)
        kind = 0 if optics.phase_function is PhaseFunctionKind.HENYEY_GREENSTEIN else 1
        return cls(kind, float(g), wp.array(theta.astype(np.float32), dtype=wp.float32, device=device),
                   wp.array(np.log(p).astype(np.float32), dtype=wp.float32, device=device), float(cone))

    def evaluate(self, cos_theta: np.ndarray, device: str) -> np.ndarray:
        """p(cos θ) [1/sr] for an array of cosines, computed by the device function."""
        c = wp.array(np.asarray(cos_theta, np.float32), dtype=wp.float32, device=device)
        out = wp.empty(len(c), dtype=wp.float32, device=device)
        wp.launch(phase_kernels.evaluate_phase, dim=len(c),
                  inputs=[c, self.kind, self.g, self.angles_rad, self.log_phase, self.cone_phase],
                  outputs=[out],
                  device=device)
        return out.numpy()
