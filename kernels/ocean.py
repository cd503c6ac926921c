"""Tessendorf FFT ocean: spectrum evolution, 2-D FFT passes and surface assembly.

Tessendorf (2001), "Simulating Ocean Water": heights ``h(x,t) = Σ_k h̃(k,t) e^{i k·x}`` with
``h̃(k,t) = h̃0(k) e^{iωt} + conj(h̃0(-k)) e^{-iωt}`` (eq. 26), slopes by spectral derivatives
``∇h = Σ i k h̃ e^{i k·x}`` (eq. 36). Complex numbers are ``vec2f`` (re, im).
"""

import functools

import warp as wp

from warpcaustics.kernels.geometry import cell_centre, normal_from_slopes

wp.set_module_options({"enable_backward": False})


@wp.func
def cmul(a: wp.vec2, b: wp.vec2) -> wp.vec2:
    return wp.vec2(a[0] * b[0] - a[1] * b[1], a[0] * b[1] + a[1] * b[0])


@wp.func
def cexp_i(phase: float) -> wp.vec2:
    return wp.vec2(wp.cos(phase), wp.sin(phase))


@wp.kernel
def evolve_spectrum(
    h0: wp.array2d[wp.vec2],
    h0_minus_conj: wp.array2d[wp.vec2],
    omega: wp.array2d[wp.float32],
    k_axis: wp.array[wp.float32],
    time_s: float,
    height_and_slope_x: wp.array2d[wp.vec2],
    slope_y: wp.array2d[wp.vec2],
):
    """Spectra at time t, packed two real fields per complex FFT.

    ``height_and_slope_x = H + i·(i kx H)`` transforms to ``h + i ∂h/∂x`` and ``slope_y = i ky H``
    to ``∂h/∂y`` (both inverse transforms are real because H is Hermitian).
    """
    iy, ix = wp.tid()
    wt = omega[iy, ix] * time_s
    h = cmul(h0[iy, ix], cexp_i(wt)) + cmul(h0_minus_conj[iy, ix], cexp_i(-wt))
    kx = k_axis[ix]
    ky = k_axis[iy]
    # i·(i kx h) = -kx h ; i ky h = (-ky h.im, ky h.re)
    height_and_slope_x[iy, ix] = h - kx * h
    slope_y[iy, ix] = wp.vec2(-ky * h[1], ky * h[0])


@functools.cache
def row_fft_kernel(n: int, inverse: bool):
    """Unnormalised DFT (forward, or inverse with e^{+i…}) of every row of an (n, n) complex
    array, in place, by ``wp.tile_fft`` / ``wp.tile_ifft``; n is fixed at compile time."""

    @wp.kernel(module="unique")
    def row_fft(data: wp.array2d[wp.vec2]):
        row = wp.tid()
        t = wp.tile_load(data, shape=(1, n), offset=(row, 0), storage="register")
        if wp.static(inverse):
            wp.tile_ifft(t)
        else:
            wp.tile_fft(t)
        wp.tile_store(data, t, offset=(row, 0))

    return row_fft


@wp.kernel
def transpose(src: wp.array2d[wp.vec2], dst: wp.array2d[wp.vec2]):
    i, j = wp.tid()
    dst[j, i] = src[i, j]


@wp.kernel
def assemble_surface(
    height_and_slope_x: wp.array2d[wp.vec2],
    slope_y: wp.array2d[wp.vec2],
    extent_m: float,
    positions: wp.array2d[wp.vec3],
    normals: wp.array2d[wp.vec3],
):
    """Vertices at cell centres ``(i + 0.5) L/N - L/2`` with height h and normal ∝ (-h_x, -h_y, 1)."""
    iy, ix = wp.tid()
    a = height_and_slope_x[iy, ix]
    xy = cell_centre(ix, iy, positions.shape[0], extent_m)
    positions[iy, ix] = wp.vec3(xy[0], xy[1], a[0])
    normals[iy, ix] = normal_from_slopes(a[1], slope_y[iy, ix][0])
