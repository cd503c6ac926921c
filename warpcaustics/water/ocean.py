"""Tessendorf's FFT ocean: the initial spectrum h̃0 from a directional spectrum (``water/spectra.py``),
2-D FFTs in Warp (``wp.tile_fft`` rows, ``kernels/water/ocean.py``) and :class:`FFTOcean` (heights,
slopes and choppy displacement by inverse FFT, finite-depth dispersion)."""

from __future__ import annotations

import numpy as np
import warp as wp

from warpcaustics.config import Config
from warpcaustics.kernels.water import ocean as ocean_kernels
from warpcaustics.scene.heights import DEFAULT_RESOLUTION
from warpcaustics.water.spectra import ocean_spectrum, wave_depth_m
from warpcaustics.water.surface import (
    FLOAT32_BYTES,
    GRAVITY_M_S2,
    SURFACE_BYTES_PER_VERTEX,
    VEC2_BYTES,
    Surface,
    is_cuda,
    surface_arrays,
)


def wavenumbers(n: int, extent_m: float) -> np.ndarray:
    """Wavenumbers of the FFT grid, in numpy's FFT order [rad/m]."""
    return 2.0 * np.pi * np.fft.fftfreq(n, d=extent_m / n)


def initial_spectrum(spectrum: np.ndarray, extent_m: float, *, seed: int) -> np.ndarray:
    """h̃0(k) = ξ sqrt(P(k) Δk² / 2), ξ complex unit Gaussian (Tessendorf eq. 42), FFT order.

    ``spectrum`` is P(k) [m^4] on the FFT grid. With this scaling the variance of h(x, t) is
    Σ_k P(k) Δk² ≈ ∫P d²k. The Nyquist row and column are zeroed so that the spectrum shifted to
    cell centres stays Hermitian (real heights).
    """
    n = spectrum.shape[0]
    dk = 2.0 * np.pi / extent_m
    rng = np.random.default_rng(seed)
    xi = (rng.standard_normal((n, n)) + 1j * rng.standard_normal((n, n))) / np.sqrt(2.0)
    h0 = xi * np.sqrt(spectrum * dk * dk / 2.0)
    h0[n // 2, :] = 0.0
    h0[:, n // 2] = 0.0
    return h0


NEGLIGIBLE_AMPLITUDE = 1e-20
"""Spectral amplitudes below this fraction of the largest are set to zero before float32."""


def negligible_to_zero(h: np.ndarray) -> np.ndarray:
    """``h`` with every component below NEGLIGIBLE_AMPLITUDE × max|h| set to zero.

    A spectrum's high-k tail falls steeply (Phillips' small-wave factor, JONSWAP's k⁻⁴), and
    below about 1e-38 float32 holds it as subnormal numbers, which x86 CPUs compute 10–100×
    slower (6 % of ``ocean.toml``'s h̃0 at 1024²; the spectrum evolution ran 2.3× slower). Nothing
    is lost: a vertex sums at most N² components of h̃0 and as many of conj h̃0(−k), weighted by at
    most k_max/k_min < N in the derivative spectra, so together the dropped ones move it by less
    than 2 N³ · 1e-20 of the largest amplitude, below float32's rounding (6e-8) for N up to 8192.
    In practice they move nothing: ``ocean.toml``'s surface is the same to the bit at 64²…1024².
    """
    h = np.array(h, dtype=np.complex128)
    h[np.abs(h) < NEGLIGIBLE_AMPLITUDE * np.abs(h).max(initial=0.0)] = 0.0
    return h


def to_vec2(a: np.ndarray, device: str) -> wp.array:
    c = np.ascontiguousarray(a, dtype=np.complex64)
    return wp.array(c.view(np.float32).reshape(*c.shape, 2), dtype=wp.vec2, device=device)


def from_vec2(a: wp.array) -> np.ndarray:
    v = a.numpy()
    return v[..., 0].astype(np.complex128) + 1j * v[..., 1]


def ifft2(data: wp.array2d, scratch: wp.array2d | None = None) -> wp.array2d:
    """In-place unnormalised 2-D inverse DFT of a square complex (vec2) array: Σ X e^{+2πi…}.

    Equals ``numpy.fft.ifft2(x) * N**2``. Rows by ``wp.tile_ifft``, then the columns: on the CPU as
    the rows of a transposed view, on CUDA by a transpose into ``scratch``, rows again, and a
    transpose back.
    """
    return _fft2(data, ocean_kernels.row_fft_kernel(data.shape[0], True), scratch)


def fft2(data: wp.array2d, scratch: wp.array2d | None = None) -> wp.array2d:
    """In-place unnormalised 2-D forward DFT of a square complex (vec2) array (= numpy.fft.fft2)."""
    return _fft2(data, ocean_kernels.row_fft_kernel(data.shape[0], False), scratch)


def fft_block_dim(n: int, device) -> int:
    """Threads per row transform: 1 (the sequential path) on the CPU, :func:`cuda_fft_block_dim`
    on CUDA."""
    if not wp.get_device(device).is_cuda:
        return 1
    return cuda_fft_block_dim(n)


def cuda_fft_block_dim(n: int) -> int:
    """Threads per row transform on CUDA: a power of two that divides N and leaves each thread at
    least two elements, as cuFFTDx and Warp's scalar GPU path require."""
    return max(1, min(64, n // 2))


def _fft2(data: wp.array2d, row_kernel, scratch: wp.array2d | None) -> wp.array2d:
    n = data.shape[0]
    if data.shape != (n, n) or n & (n - 1):
        raise ValueError(f"FFT needs a square power-of-two array, got {data.shape}")
    device = data.device
    block_dim = fft_block_dim(n, device)
    wp.launch_tiled(row_kernel, dim=[n], inputs=[data], block_dim=block_dim, device=device)
    if not device.is_cuda:
        # The columns in place, as the rows of a transposed view: a column's loads are strided, but
        # the next columns' elements share their cache lines, so the CPU reads each line once and
        # needs neither the two transposes (a third of the 2-D FFT at 1024²) nor a scratch array.
        wp.launch_tiled(row_kernel, dim=[n], inputs=[data.transpose()], block_dim=block_dim, device=device)
        return data
    # CUDA: strided column loads would not coalesce; transpose, transform the rows, transpose back.
    if scratch is None:
        scratch = wp.empty_like(data)
    wp.launch(ocean_kernels.transpose, dim=(n, n), inputs=[data, scratch], device=device)
    wp.launch_tiled(row_kernel, dim=[n], inputs=[scratch], block_dim=block_dim, device=device)
    wp.launch(ocean_kernels.transpose, dim=(n, n), inputs=[scratch, data], device=device)
    return data


def vertex_shift(n: int, extent_m: float) -> np.ndarray:
    """e^{i k·x0}, FFT order: vertex (ix, iy) lies at x0 + ix L/N, x0 = −L/2 + L/(2N), which
    :class:`FFTOcean` folds into h̃0."""
    k = wavenumbers(n, extent_m)
    kx, ky = np.meshgrid(k, k)
    x0 = -0.5 * extent_m + 0.5 * extent_m / n
    return np.exp(1j * (kx + ky) * x0)


def dispersion(k: np.ndarray, depth_m: float) -> np.ndarray:
    """Angular frequency of gravity waves over a floor at depth h: ω² = g k tanh(k h) (Tessendorf
    eq. 19) [rad/s]."""
    return np.sqrt(GRAVITY_M_S2 * k * np.tanh(k * depth_m))


class FFTOcean:
    """Tessendorf FFT ocean: any initial spectrum h̃0, finite-depth dispersion, choppy waves."""

    periodic = True
    """A tileable patch: floor footprints wrap."""

    def __init__(self, h0: np.ndarray, extent_m: float, depth_m: float, device: str, *,
                 choppiness: float = 0.0):
        n = h0.shape[0]
        self.device = device
        self.extent_m = extent_m
        self.depth_m = float(depth_m)
        self.choppiness = float(choppiness)
        k = wavenumbers(n, extent_m)
        kx, ky = np.meshgrid(k, k)
        omega = dispersion(np.hypot(kx, ky), depth_m)
        h0_minus = h0[(-np.arange(n)) % n][:, (-np.arange(n)) % n]
        # Vertex (ix, iy) is at x0 + ix L/N with x0 = -L/2 + L/(2N): fold e^{i k·x0} into h̃0.
        shift = vertex_shift(n, extent_m)
        self.h0 = to_vec2(negligible_to_zero(h0 * shift), device)
        self.h0_minus_conj = to_vec2(negligible_to_zero(np.conj(h0_minus) * shift), device)
        self.omega = wp.array(omega.astype(np.float32), dtype=wp.float32, device=device)
        self.k_axis = wp.array(k.astype(np.float32), dtype=wp.float32, device=device)
        self._spectra = [wp.empty((n, n), dtype=wp.vec2, device=device) for _ in range(4)]
        # The CUDA FFT's transposes need a scratch array; the CPU's transforms its columns in place.
        self._scratch = wp.empty((n, n), dtype=wp.vec2, device=device) if is_cuda(device) else None

    @classmethod
    def from_config(cls, cfg: Config, device: str, *, heights: np.ndarray | None = None,
                    floor_relief: np.ndarray | None = None) -> FFTOcean:
        """The ocean of ``water.*`` (spectrum, wind, fetch, choppiness, seed) over water of
        ``water.depth_m`` (0: ``floor.depth_m``)."""
        w = cfg.water
        n = w.resolution or DEFAULT_RESOLUTION
        k = wavenumbers(n, w.extent_m)
        spectrum = ocean_spectrum(cfg, *np.meshgrid(k, k))
        return cls(initial_spectrum(spectrum, w.extent_m, seed=w.seed), w.extent_m, wave_depth_m(cfg),
                   device, choppiness=w.choppiness)

    def truncated(self, n: int) -> FFTOcean:
        """The same ocean on an N×N grid (N a power of two up to :attr:`resolution`): its waves
        whose wavenumbers the coarser grid holds, each with its own amplitude and phase, the shorter
        ones (and the coarser grid's Nyquist row and column, as :func:`initial_spectrum`) left out.
        Its heights are the spectral low-pass of this ocean's at every time."""
        big = self.resolution
        if n > big or n & (n - 1) or n < 2:
            raise ValueError(f"a truncated ocean needs a power of two up to {big}, got {n}")
        h0 = from_vec2(self.h0) * np.conj(vertex_shift(big, self.extent_m))  # the unshifted h̃0
        index = np.r_[0:n // 2, big - n // 2:big]  # the coarse grid's wavenumbers in the fine FFT order
        coarse = h0[np.ix_(index, index)]
        coarse[n // 2, :] = 0.0
        coarse[:, n // 2] = 0.0
        return FFTOcean(coarse, self.extent_m, self.depth_m, self.device, choppiness=self.choppiness)

    @staticmethod
    def device_bytes(n: int, device) -> int:
        scratch = 1 if is_cuda(device) else 0  # the CUDA FFT's transposes (see __init__)
        spectra = (2 + 4 + scratch) * VEC2_BYTES  # h̃0, conj h̃0(−k), the four spectra
        omega = FLOAT32_BYTES
        surface = SURFACE_BYTES_PER_VERTEX + FLOAT32_BYTES  # positions, normals, Jacobian
        return n * n * (spectra + omega + surface) + n * FLOAT32_BYTES  # and the k axis

    @property
    def resolution(self) -> int:
        return self.h0.shape[0]

    def spectra_at(self, time_s: float) -> list[wp.array2d]:
        """The four packed device spectra at time t (see kernels/water/ocean.py:evolve_spectrum)."""
        n = self.resolution
        wp.launch(ocean_kernels.evolve_spectrum, dim=(n, n),
                  inputs=[self.h0, self.h0_minus_conj, self.omega, self.k_axis, float(time_s)],
                  outputs=self._spectra, device=self.device)
        return self._spectra

    def at(self, time_s: float) -> Surface:
        n = self.resolution
        spectra = self.spectra_at(time_s)
        for spectrum in spectra[: 4 if self.choppiness else 2]:
            ifft2(spectrum, self._scratch)
        positions, normals = surface_arrays(n, self.device)
        jacobian = wp.empty((n, n), dtype=wp.float32, device=self.device)
        wp.launch(ocean_kernels.assemble_surface, dim=(n, n),
                  inputs=[*spectra, self.choppiness, self.extent_m],
                  outputs=[positions, normals, jacobian], device=self.device)
        return Surface(positions, normals, self.extent_m, jacobian)
