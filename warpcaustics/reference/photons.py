"""Photon splatting in vectorised float64 numpy: the twin of ``kernels/caustics/photons.py``.

:func:`numpy_photons` does in float64 what the photon kernels do for a periodic sea over a flat
floor: emit s×s photons on the bilinear patch of every surface quad, refract them (Snell + exact
Fresnel), move each start by whole periods so it lands in the patch, intersect the floor and
deposit the flux. Intersections: ``newton`` is Shah's iteration with the kernel's look-ups
(bilinear between texel centres showing one receiver, else the nearest texel) on the very
light-view position buffer the Warp stage renders; ``exact`` is the analytic ray/plane
intersection. The baseline of ``benchmarks/photons.py`` and a cross-check in ``tests/``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from warpcaustics.reference.floor import MIN_DOWNWARD_COS, fresnel_transmittance


@dataclass(frozen=True)
class LightViewArrays:
    """Host copy of the Warp ``LightView`` (Shah's receiver-position buffer seen from the light)."""

    positions: np.ndarray
    """(R, R, 3) first receiver point seen through texel [j, i] [m]."""
    receiver: np.ndarray
    """(R, R) receiver id of the face seen through texel [j, i] (0 = floor; −1: nothing seen)."""
    origin: np.ndarray
    """(3,) corner of the view [m]; texel (i, j) is centred on origin + (i + ½) texel u + (j + ½) texel v."""
    u: np.ndarray
    v: np.ndarray
    texel_m: float

    @classmethod
    def from_warp(cls, view, face_receiver: np.ndarray) -> LightViewArrays:
        """From a Warp ``LightView`` and the receivers' face → receiver id table."""
        faces = view.faces.numpy()
        receiver = np.where(faces >= 0, np.asarray(face_receiver)[np.maximum(faces, 0)], -1)
        return cls(positions=view.positions.numpy().astype(np.float64), receiver=receiver,
                   origin=np.array(view.origin, np.float64), u=np.array(view.u, np.float64),
                   v=np.array(view.v, np.float64), texel_m=float(view.texel_m))


def _bilinear(a00, a10, a01, a11, tu, tv):
    """(1-tv)((1-tu) a00 + tu a10) + tv((1-tu) a01 + tu a11), as ``bilinear_vec3``."""
    return (1.0 - tv) * ((1.0 - tu) * a00 + tu * a10) + tv * ((1.0 - tu) * a01 + tu * a11)


def _quad_corners(a: np.ndarray, shift_m: float):
    """Corners (0,0), (1,0), (0,1), (1,1) of every periodic quad [qy, qx] of grid ``a`` (N, N, ...).

    A corner past the last column/row wraps to index 0 and, for positions (``shift_m`` = L), moves
    by +L in x/y (``grid_corner`` + ``lift``).
    """
    a10 = np.roll(a, -1, axis=1)
    a01 = np.roll(a, -1, axis=0)
    a11 = np.roll(a01, -1, axis=1)
    if shift_m:
        a10[:, -1, 0] += shift_m
        a01[-1, :, 1] += shift_m
        a11[:, -1, 0] += shift_m
        a11[-1, :, 1] += shift_m
    return a, a10, a01, a11


def _look_up(view: LightViewArrays, x: np.ndarray):
    """``look_up``: the receiver point R(x) the light view sees through each x, its receiver id (−1: none
    or outside the view). Bilinear between the four texel centres around x where they all show
    the receiver of x's own texel, else that texel's point."""
    res = view.positions.shape[0]
    pos = view.positions.reshape(-1, 3)
    receiver = view.receiver.ravel()
    rel = x - view.origin
    a = rel @ (view.u / view.texel_m)
    b = rel @ (view.v / view.texel_m)
    inside = (a >= 0.0) & (b >= 0.0) & (a < res) & (b < res)
    own = np.clip(b, 0, res - 1).astype(np.int64) * res + np.clip(a, 0, res - 1).astype(np.int64)
    rec = np.where(inside, receiver[own], -1)
    fa, fb = a - 0.5, b - 0.5
    i0 = np.floor(fa)
    j0 = np.floor(fb)
    tu, tv = (fa - i0)[:, None], (fb - j0)[:, None]
    same = (i0 >= 0) & (j0 >= 0) & (i0 + 1 < res) & (j0 + 1 < res) & (rec >= 0)
    c00 = np.clip(j0, 0, res - 2).astype(np.int64) * res + np.clip(i0, 0, res - 2).astype(np.int64)
    for corner in (c00, c00 + 1, c00 + res, c00 + res + 1):
        same &= receiver[corner] == rec
    point = _bilinear(*(np.take(pos, c, axis=0) for c in (c00, c00 + 1, c00 + res, c00 + res + 1)), tu, tv)
    edge = ~same
    point[edge] = np.take(pos, own[edge], axis=0)
    return point, rec


def _newton(view: LightViewArrays, o: np.ndarray, d: np.ndarray, floor_z: float, iterations: int):
    """Shah's iteration ``t ← |R(o + t d) − o|`` from the plane z = floor_z (``newton_hit``).

    Returns t and whether the photon stayed in the light view and ends on the floor (receiver 0);
    a photon that leaves the view at any step is dropped, as in the kernel.
    """
    t = (floor_z - o[:, 2]) / d[:, 2]
    ok = np.ones(len(t), bool)
    for _ in range(iterations):
        r, rec = _look_up(view, o + t[:, None] * d)
        ok &= rec >= 0
        t = np.where(ok, np.linalg.norm(r - o, axis=1), t)
    _, rec = _look_up(view, o + t[:, None] * d)
    return t, ok & (rec == 0)


def _wrapped_texel(x: np.ndarray, m: int) -> np.ndarray:
    """``texel_of`` on a periodic map: x [texels] reduced into [0, m), then its texel."""
    r = x - m * np.floor(x / m)
    return np.where(r >= m, 0.0, r).astype(np.int64)


def numpy_photons(positions, normals, visible, ior, sun_dir, s, extent_m, floor_z, sun_irradiance,
                  attenuation_per_m, map_resolution, mode, newton_iterations=3, view=None) -> np.ndarray:
    """The Warp photon stage in float64 numpy for a periodic sea over the flat floor z = floor_z.

    Args:
        positions, normals: (N, N, 3) surface vertices [m] and unit normals, ``[iy, ix]``.
        visible: (N, N) sun visibility of each vertex (0…1).
        ior: (G,) refractive index of each index group; the K bands split evenly into the G groups.
        sun_dir: (3,) unit vector towards the sun.
        s: photons per quad are s×s.
        extent_m: side L of the periodic patch [m]; floor_z: height of the floor plane [m].
        sun_irradiance, attenuation_per_m: (K,) E_sun [W m^-2 nm^-1] and c [1/m] per band.
        map_resolution: M texels per side of the floor map over the patch.
        mode: ``"exact"``: analytic ray/plane intersection (numpy has no BVH, so this is cheaper
            than Warp's exact mode, a BVH ray query, which it equals on a flat floor);
            ``"newton"``: Shah's iteration with ``newton_iterations`` steps on ``view``.
        view: the Warp stage's light view (:class:`LightViewArrays`), for ``newton``; photons
            that end on another receiver than the floor (id 0) are dropped from the map.

    Returns:
        (K, M, M) floor irradiance [W m^-2 nm^-1] (photon flux over the texel's area).
    """
    p = np.asarray(positions, np.float64)
    nrm = np.asarray(normals, np.float64)
    vis = np.asarray(visible, np.float64)
    sun = np.asarray(sun_dir, np.float64)
    e_sun = np.asarray(sun_irradiance, np.float64)
    c = np.asarray(attenuation_per_m, np.float64)
    ior = np.atleast_1d(np.asarray(ior, np.float64))
    k_bands, m = len(e_sun), map_resolution
    per_group = k_bands // len(ior)

    # Emission: sub-sample (tu, tv) = ((i + ½)/s, (j + ½)/s), sub = j s + i, on every quad [qy, qx].
    sub = np.arange(s * s)
    tu = ((sub % s + 0.5) / s)[:, None]
    tv = ((sub // s + 0.5) / s)[:, None]
    p00, p10, p01, p11 = (a[:, :, None, :] for a in _quad_corners(p, extent_m))
    origin = _bilinear(p00, p10, p01, p11, tu, tv).reshape(-1, 3)
    dp_du = ((1.0 - tv) * (p10 - p00) + tv * (p11 - p01)).reshape(-1, 3)
    dp_dv = ((1.0 - tu) * (p01 - p00) + tu * (p11 - p10)).reshape(-1, 3)
    a_perp = np.maximum(np.cross(dp_du, dp_dv) @ sun, 0.0) / (s * s)
    normal = _bilinear(*(a[:, :, None, :] for a in _quad_corners(nrm, 0.0)), tu, tv).reshape(-1, 3)
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    seen = _bilinear(*(a[:, :, None] for a in _quad_corners(vis, 0.0)), tu[:, 0], tv[:, 0]).ravel()
    cos_i = normal @ sun

    out = np.zeros((k_bands, m * m))
    texel_area_m2 = (extent_m / m) ** 2  # flat floor: the true texel area
    for g, n_g in enumerate(ior):
        eta = 1.0 / n_g
        # refract(-sun, normal, eta): eta d + (eta c − √k) n, zero on total internal reflection.
        k = 1.0 - eta * eta * (1.0 - cos_i * cos_i)
        t = -eta * sun + (eta * cos_i - np.sqrt(np.maximum(k, 0.0)))[:, None] * normal
        w = a_perp * fresnel_transmittance(cos_i, eta) * seen
        live = (cos_i > 0.0) & (k >= 0.0) & (t[:, 2] < -MIN_DOWNWARD_COS) & (w > 0.0)
        o, w = origin[live], w[live]
        d = t[live] / np.linalg.norm(t[live], axis=1, keepdims=True)

        # periodic_start: shift by whole periods so the photon lands inside the patch.
        t_plane = (floor_z - o[:, 2]) / d[:, 2]
        land = o[:, :2] + t_plane[:, None] * d[:, :2]
        o[:, :2] -= extent_m * np.floor(land / extent_m + 0.5)

        if mode == "exact":
            t_hit = (floor_z - o[:, 2]) / d[:, 2]
        elif mode == "newton":
            t_hit, found = _newton(view, o, d, floor_z, newton_iterations)
            o, d, w, t_hit = o[found], d[found], w[found], t_hit[found]
        else:
            raise ValueError(f"mode = {mode!r}: expected 'exact' or 'newton'")
        hit = o + t_hit[:, None] * d
        ell = np.linalg.norm(hit - o, axis=1)

        tx = _wrapped_texel((hit[:, 0] + 0.5 * extent_m) * m / extent_m, m)
        ty = _wrapped_texel((hit[:, 1] + 0.5 * extent_m) * m / extent_m, m)
        flat = ty * m + tx
        for kb in range(g * per_group, (g + 1) * per_group):
            flux = w * (e_sun[kb] / texel_area_m2) * np.exp(-c[kb] * ell)
            out[kb] = np.bincount(flat, weights=flux, minlength=m * m)
    return out.reshape(k_bands, m, m)
