"""Phase functions of in-water scattering (host side): Henyey–Greenstein or Petzold (1972).

Petzold's volume scattering functions come from the ``jerlov`` package (eight stations at 530 nm,
0.1–180°, total: water and particles); the phase function is β(θ)/b, normalised over the sphere:
the measured share f of scattering below 0.1° sits in a forward cone where p follows the report's
own power-law extension (:class:`ForwardCone`), and the table is scaled to carry the rest, 1 − f.
Henyey–Greenstein's g defaults to the mean cosine of that Petzold station (cone included), so both
options describe the same water. Host-side integrals over the phase function all use one float64
quadrature, :func:`phase_quadrature`.
"""

from __future__ import annotations

import functools
import warnings
from dataclasses import dataclass

import numpy as np
import warp as wp

from warpcaustics.config import OpticsConfig, PhaseFunctionKind
from warpcaustics.kernels.optics import phase as phase_kernels


@dataclass(frozen=True)
class ForwardCone:
    """A Petzold station's phase function below its first angle θ0 = 0.1°, where nothing was measured.

    The report extends β there with a power law, its log-log slope at the first angles (the notes of
    ``petzold1972_vsf.csv`` in the ``jerlov`` package), and the share f of b below 0.1° that it prints
    is that extension's integral. Here p = p0 (θ/θ0)^−m, p0 the normalised table's first value (so p
    is continuous at θ0) and m fixed by f: 2π p0 θ0^m ∫₀^θ0 θ^(1−m) dθ = f, i.e.
    m = 2 − 2π p0 θ0² / f (sin θ ≈ θ, good to θ0²/6 = 5e-7). At all eight stations m agrees with
    the table's own slope between 0.1° and 0.126° within 0.015 (``tests/test_phase.py``): the power law
    is the report's.
    """

    theta0: float
    """The table's first angle [rad]."""
    p0: float
    """p at θ0 [1/sr]."""
    exponent: float
    """m: p falls as θ^−m towards θ0 (0 < m < 2, so that the cone holds a finite share)."""
    share: float
    """f: the share of scattering below θ0."""

    def value(self, theta: np.ndarray) -> np.ndarray:
        """p(θ) [1/sr] for 0 < θ ≤ θ0."""
        return self.p0 * (np.asarray(theta, np.float64) / self.theta0) ** -self.exponent

    def share_below(self, theta: float) -> float:
        """The share of scattering at angles below ``theta`` ≤ θ0."""
        return self.share * (theta / self.theta0) ** (2.0 - self.exponent)

    @property
    def mean(self) -> float:
        """p averaged over the cone [1/sr]: what a float32 cos θ, which resolves θ only to ~0.02°,
        can use on the device."""
        return self.share / (2.0 * np.pi * (1.0 - np.cos(self.theta0)))


@functools.cache
def petzold_table(station: str) -> tuple[np.ndarray, np.ndarray, ForwardCone]:
    """A Petzold station's phase function, normalised over the whole sphere.

    Returns (θ [rad], p(θ) [1/sr] at the measured angles, the :class:`ForwardCone` below the first).
    The table (0.1–180°) is scaled so that, with ln p linear in θ as on the device, it integrates to
    1 − f, f being the station's measured share below 0.1°, which the cone holds.
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
    exponent = 2.0 - 2.0 * np.pi * p[0] * theta[0] ** 2 / f
    if not 0.0 < exponent < 2.0:
        raise ValueError(f"Petzold station {station!r}: no power law below 0.1° holds its share {f:g}")
    return theta, p, ForwardCone(float(theta[0]), float(p[0]), float(exponent), f)


def table_on_grid(theta: np.ndarray, p: np.ndarray, cone: ForwardCone, grid: np.ndarray) -> np.ndarray:
    """p [1/sr] of a :func:`petzold_table` on any angle grid [rad] (θ > 0): ln p linear in θ between
    the table's angles (as on the device), the ``cone``'s power law below its first angle."""
    theta = np.asarray(theta, np.float64)
    grid = np.asarray(grid, np.float64)
    table = np.exp(np.interp(grid, theta, np.log(np.asarray(p, np.float64))))
    return np.where(grid < theta[0], cone.value(np.maximum(grid, 1e-300)), table)


def solid_angle_weights(theta: np.ndarray, p: np.ndarray) -> np.ndarray:
    """Trapezoid weights of 2π p(θ) sin θ dθ on the grid ``theta`` [rad]: Σ weights × f(θ) is
    ∫ f p dΩ over the sphere."""
    step = np.diff(theta)
    width = 0.5 * (np.concatenate([step, [0.0]]) + np.concatenate([[0.0], step]))
    return 2.0 * np.pi * p * np.sin(theta) * width


CONE_DECADES = 10
"""The quadrature resolves the forward cone down to θ0 × 10^−CONE_DECADES; the share below (2e-5 of
f at m = 1.6) sits at θ = 0."""


@functools.cache
def phase_quadrature(kind: PhaseFunctionKind, g: float | None, station: str) -> tuple[np.ndarray, np.ndarray]:
    """(θ [rad], w) with Σ w f(θ) = ∫ f p dΩ over the sphere, float64, for a phase function:
    Henyey–Greenstein in closed form (mean cosine ``g``, or the station's own), or the station's
    table with its power-law cone. The nodes are θ = 0, then log-spaced through the cone
    (20000, resolving J₀(νθ) to νθ ~ 10³) and the table (60000): the one quadrature of the phase
    function behind the walk's sampling, the small-angle transfer and DISORT's moments."""
    theta_t, p_t, cone = petzold_table(station)
    nodes = np.concatenate([np.geomspace(cone.theta0 * 10.0**-CONE_DECADES, cone.theta0, 20000)[:-1],
                            np.geomspace(cone.theta0, np.pi, 60000)])
    if kind is PhaseFunctionKind.HENYEY_GREENSTEIN:
        g = station_mean_cosine(station) if g is None else g
        p = (1.0 - g * g) / (4.0 * np.pi * (1.0 + g * g - 2.0 * g * np.cos(nodes)) ** 1.5)
        below = 2.0 * np.pi * p[0] * (1.0 - np.cos(nodes[0]))
    else:
        p = table_on_grid(theta_t, p_t, cone, nodes)
        below = cone.share_below(nodes[0])
    return np.concatenate([[0.0], nodes]), np.concatenate([[below], solid_angle_weights(nodes, p)])


def mean_cosine(theta: np.ndarray, weight: np.ndarray) -> float:
    """∫ cos θ p dΩ / ∫ p dΩ of a :func:`phase_quadrature`."""
    return float(weight @ np.cos(theta) / weight.sum())


def station_mean_cosine(station: str) -> float:
    """The mean cosine of a Petzold station's phase function, cone included: Henyey–Greenstein's
    default g."""
    return mean_cosine(*phase_quadrature(PhaseFunctionKind.PETZOLD, None, station))


def phase_values(optics: OpticsConfig, theta: np.ndarray) -> np.ndarray:
    """The configured phase function p(θ) [1/sr] at scattering angles ``theta`` [rad] > 0, float64:
    Henyey–Greenstein in closed form (mean cosine ``optics.hg_g`` or the station's), or the Petzold
    station's table with its power-law cone (:func:`table_on_grid`)."""
    station = optics.petzold_station.value
    theta = np.maximum(np.asarray(theta, np.float64), 1e-12)
    if optics.phase_function is PhaseFunctionKind.HENYEY_GREENSTEIN:
        g = station_mean_cosine(station) if optics.hg_g is None else optics.hg_g
        return (1.0 - g * g) / (4.0 * np.pi * (1.0 + g * g - 2.0 * g * np.cos(theta)) ** 1.5)
    return table_on_grid(*petzold_table(station), theta)


def quadrature_for(optics: OpticsConfig) -> tuple[np.ndarray, np.ndarray]:
    """The configured phase function's :func:`phase_quadrature`."""
    return phase_quadrature(optics.phase_function, optics.hg_g, optics.petzold_station.value)


@dataclass
class PhaseFunction:
    """A phase function ready for the device: kind, g and the (possibly unused) table."""

    kind: int
    """0 = Henyey–Greenstein, 1 = tabulated (Petzold)."""
    g: float
    angles_rad: wp.array
    log_phase: wp.array
    cone_phase: float
    """p [1/sr] inside the forward cone below the table's first angle: the cone's mean
    (:attr:`ForwardCone.mean`), as a float32 cos θ cannot resolve its power law."""

    @classmethod
    def from_optics(cls, optics: OpticsConfig, device: str) -> PhaseFunction:
        theta, p, cone = petzold_table(optics.petzold_station.value)
        g = optics.hg_g if optics.hg_g is not None else station_mean_cosine(optics.petzold_station.value)
        kind = 0 if optics.phase_function is PhaseFunctionKind.HENYEY_GREENSTEIN else 1
        return cls(kind, float(g), wp.array(theta.astype(np.float32), dtype=wp.float32, device=device),
                   wp.array(np.log(p).astype(np.float32), dtype=wp.float32, device=device), cone.mean)

    def evaluate(self, cos_theta: np.ndarray, device: str) -> np.ndarray:
        """p(cos θ) [1/sr] for an array of cosines, computed by the device function."""
        c = wp.array(np.asarray(cos_theta, np.float32), dtype=wp.float32, device=device)
        out = wp.empty(len(c), dtype=wp.float32, device=device)
        wp.launch(phase_kernels.evaluate_phase, dim=len(c),
                  inputs=[c, self.kind, self.g, self.angles_rad, self.log_phase, self.cone_phase],
                  outputs=[out],
                  device=device)
        return out.numpy()
