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
    height_slope_x: wp.array2d[wp.vec2],
    slope_y_disp_x: wp.array2d[wp.vec2],
    disp_y_dxx: wp.array2d[wp.vec2],
    dyy_dxy: wp.array2d[wp.vec2],
):
    """Spectra at time t, two real fields packed per complex FFT (all spectra are Hermitian).

    ``h̃ = h̃0(k) e^{-iωt} + conj(h̃0(-k)) e^{iωt}`` (Tessendorf eq. 26 with t → −t, so that h̃0(k)
    is a wave travelling along +k). Packed pairs: (h, ∂h/∂x), (∂h/∂y, D_x), (D_y, ∂D_x/∂x),
    (∂D_y/∂y, ∂D_x/∂y) with the choppy displacement ``D̃ = +i k̂ h̃`` and its derivatives
    ``∂_a D_b ↔ −(k_a k_b / k) h̃``. The sign is that of Tessendorf's Gerstner wave (eq. 7): vertices
    move towards the crests, which sharpen (his eq. 29 prints −i, which needs λ < 0).
    """
    iy, ix = wp.tid()
    wt = omega[iy, ix] * time_s
    h = cmul(h0[iy, ix], cexp_i(-wt)) + cmul(h0_minus_conj[iy, ix], cexp_i(wt))
    kx = k_axis[ix]
    ky = k_axis[iy]
    k = wp.sqrt(kx * kx + ky * ky)
    inv_k = float(0.0)
    if k > 0.0:
        inv_k = 1.0 / k
    # i·(i a h) = -a h ; i a h = (-a h.im, a h.re)
    height_slope_x[iy, ix] = h - kx * h
    slope_y_disp_x[iy, ix] = wp.vec2(-ky * h[1], ky * h[0]) - (kx * inv_k) * h  # + i·(i kx/k h)
    disp_y = wp.vec2(-ky * inv_k * h[1], ky * inv_k * h[0])  # i (ky/k) h
    dxx = -(kx * kx * inv_k) * h
    disp_y_dxx[iy, ix] = disp_y + wp.vec2(-dxx[1], dxx[0])
    dxy = -(kx * ky * inv_k) * h
    dyy_dxy[iy, ix] = -(ky * ky * inv_k) * h + wp.vec2(-dxy[1], dxy[0])


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
    height_slope_x: wp.array2d[wp.vec2],
    slope_y_disp_x: wp.array2d[wp.vec2],
    disp_y_dxx: wp.array2d[wp.vec2],
    dyy_dxy: wp.array2d[wp.vec2],
    choppiness: float,
    extent_m: float,
    positions: wp.array2d[wp.vec3],
    normals: wp.array2d[wp.vec3],
    jacobian: wp.array2d[wp.float32],
):
    """Vertex = cell centre + λ D (horizontal), height h; normal = ∂P/∂x × ∂P/∂y normalised;
    Jacobian of the horizontal map J = (1 + λD_xx)(1 + λD_yy) − (λD_xy)² (≤ 0 where it folds).

    With λ = 0 the last two spectra are not transformed and are not read.
    """
    iy, ix = wp.tid()
    a = height_slope_x[iy, ix]
    b = slope_y_disp_x[iy, ix]
    xy = cell_centre(ix, iy, positions.shape[0], extent_m)
    if choppiness == 0.0:
        positions[iy, ix] = wp.vec3(xy[0], xy[1], a[0])
        normals[iy, ix] = normal_from_slopes(a[1], b[0])
        jacobian[iy, ix] = 1.0
        return
    c = disp_y_dxx[iy, ix]
    d = dyy_dxy[iy, ix]
    jxx = 1.0 + choppiness * c[1]
    jyy = 1.0 + choppiness * d[0]
    jxy = choppiness * d[1]
    positions[iy, ix] = wp.vec3(xy[0] + choppiness * b[1], xy[1] + choppiness * c[0], a[0])
    tangent_x = wp.vec3(jxx, jxy, a[1])
    tangent_y = wp.vec3(jxy, jyy, b[0])
    normals[iy, ix] = wp.normalize(wp.cross(tangent_x, tangent_y))
    jacobian[iy, ix] = jxx * jyy - jxy * jxy
