"""The flux-ratio deposit by edge accumulation (``kernels/caustics/coverage.py``) against float64
clipping of every footprint against every texel, on windows and on periodic maps."""

import numpy as np
import pytest
import warp as wp

from warpcaustics.kernels.caustics.coverage import CoverDeposit, cover_to_bands, cover_triangle
from warpcaustics.reference.floor import _area, _clip, subtriangle_centroids

M = 12


@wp.kernel
def _deposit(q0: wp.array[wp.vec2], e1: wp.array[wp.vec2], e2: wp.array[wp.vec2],
             flux: wp.array4d[wp.float32], m: int, wrap: int, max_clipped: int,
             cover: wp.array3d[wp.float32], carry: wp.array2d[wp.float64], texels: wp.array3d[wp.float32],
             coarse: wp.array[wp.int32]):
    t = wp.tid()
    dep = CoverDeposit()
    dep.cover = cover
    dep.carry = carry
    dep.texels = texels
    dep.flux_w_nm = flux
    dep.k_begin = 0
    dep.k_count = 1
    dep.iy = t
    dep.ix = 0
    dep.half = 0
    cover_triangle(dep, q0[t], e1[t], e2[t], m, wrap, max_clipped, 1.0, coarse)


def _edge_accumulated(q0, e1, e2, flux, wrap, max_clipped, device):
    """(M, M) map and the count of footprints taken by samples, from the Warp kernels."""
    t = len(q0)
    vec = [wp.array(a.astype(np.float32), dtype=wp.vec2, device=device) for a in (q0, e1, e2)]
    flux_w = wp.array(flux.astype(np.float32).reshape(t, 1, 1, 1), dtype=wp.float32, device=device)
    cover = wp.zeros((M, M, 1), dtype=wp.float32, device=device)
    carry = wp.zeros((M, 1), dtype=wp.float64, device=device)
    texels = wp.zeros((M, M, 1), dtype=wp.float32, device=device)
    coarse = wp.zeros(1, dtype=wp.int32, device=device)
    out = wp.empty((1, M, M), dtype=wp.float32, device=device)
    wp.launch(_deposit, dim=t, inputs=[*vec, flux_w, M, wrap, max_clipped],
              outputs=[cover, carry, texels, coarse], device=device)
    wp.launch(cover_to_bands, dim=(M, 1), inputs=[cover, carry, texels], outputs=[out], device=device)
    return out.numpy()[0].astype(np.float64), int(coarse.numpy()[0])


def _clipped(q0, e1, e2, flux, wrap):
    """(M, M) float64: each footprint (every periodic image of it when ``wrap``) clipped against every
    texel, overlap / area × flux. The footprints are the kernel's: corners q0, q0 + e1, q0 + e2 and
    area |e1 × e2| / 2 from the float32 inputs (what the kernel is given), the rest in float64."""
    out = np.zeros((M, M))
    tx, ty = np.meshgrid(np.arange(M), np.arange(M))
    tx, ty = tx.ravel().astype(np.float64), ty.ravel().astype(np.float64)
    q0, e1, e2 = (np.asarray(x, np.float32) for x in (q0, e1, e2))
    for a, u, v, f in zip(q0, e1, e2, flux):
        corners = np.array([a, a + u, a + v], np.float64)  # the sums rounded to float32, as the kernel's
        u, v = u.astype(np.float64), v.astype(np.float64)
        area = 0.5 * abs(u[0] * v[1] - u[1] * v[0])
        shifts = [(0, 0)]
        if wrap:
            lo = np.floor(corners.min(axis=0) / M).astype(int)
            hi = np.floor(corners.max(axis=0) / M).astype(int)
            shifts = [(sx, sy) for sx in range(-hi[0], -lo[0] + 1) for sy in range(-hi[1], -lo[1] + 1)]
        for sx, sy in shifts:
            px = np.zeros((M * M, 8))
            py = np.zeros((M * M, 8))
            px[:, :3] = corners[:, 0] + sx * M
            py[:, :3] = corners[:, 1] + sy * M
            count = np.full(M * M, 3)
            for axis, bound, above in ((0, tx, True), (0, tx + 1, False), (1, ty, True), (1, ty + 1, False)):
                px, py, count = _clip(px, py, count, axis, bound, above)
            overlap = np.where(count >= 3, _area(px, py, count), 0.0)
            out += (overlap / area * f).reshape(M, M)
    return out


def _footprints(rng, count, wrap):
    """Footprints of every kind the deposit meets: sizes from a twentieth of a texel (inside one
    texel) to twice the map (wrapping over itself), both orientations, slivers, and on a window
    ones reaching past every side or lying wholly beside it. None narrower than a hundredth of a
    texel: there the float32 geometry, of clipping as of this deposit, leaves the overlap uncertain
    by ~1e-7 / width of the footprint's flux (its area is the difference of nearly equal products)."""
    q0 = rng.uniform(0.0, M, (count, 2)) if wrap else rng.uniform(-0.5 * M, 1.5 * M, (count, 2))
    size = np.exp(rng.uniform(np.log(0.05), np.log(2.0 * M), (count, 1)))
    e1 = size * rng.normal(size=(count, 2))
    e2 = size * rng.normal(size=(count, 2))
    sliver = rng.random(count) < 0.2  # long and thin, as footprints are near a fold
    e2[sliver] = e1[sliver] * rng.uniform(0.5, 2.0, (sliver.sum(), 1)) + 0.05 * size[sliver] * rng.normal(
        size=(sliver.sum(), 2))
    longest = np.max(np.linalg.norm(np.stack([e1, e2, e2 - e1]), axis=2), axis=0)
    width = np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0]) / longest
    keep = width > 0.01
    flux = rng.uniform(0.5, 2.0, count)
    return q0[keep], e1[keep], e2[keep], flux[keep]


@pytest.mark.parametrize("wrap", [0, 1], ids=["window", "periodic"])
def test_edge_accumulation_equals_clipping(device, wrap):
    """Every texel gets overlap area / footprint area of each footprint's flux, as float64 clipping
    of each footprint (and on a periodic map each of its images) against each texel gives (to 2e-5
    of the largest texel: the kernels' float32 geometry), and on a periodic map the flux is kept."""
    rng = np.random.default_rng(7 + wrap)
    q0, e1, e2, flux = _footprints(rng, 400, wrap)
    got, coarse = _edge_accumulated(q0, e1, e2, flux, wrap, 10**9, device)
    expected = _clipped(q0, e1, e2, flux, wrap)
    assert coarse == 0
    np.testing.assert_allclose(got, expected, rtol=0, atol=2e-5 * expected.max())
    if wrap:
        np.testing.assert_allclose(got.sum(), flux.sum(), rtol=1e-6)


@pytest.mark.parametrize("wrap", [0, 1], ids=["window", "periodic"])
def test_huge_footprints_go_by_samples(device, wrap):
    """A footprint whose box exceeds the bound is spread over its sub-triangles' centroids with equal
    shares (``fluxratio.deposit_by_samples``'s rule), the same texels a float64 evaluation of the
    centroids gives."""
    rng = np.random.default_rng(3)
    q0, e1, e2, flux = (a.astype(np.float32) for a in _footprints(rng, 60, wrap))
    # the kernel's rule, in its float32 arithmetic: the box of texels the footprint touches (within
    # a window: of the window's texels) over the bound
    corners = np.stack([q0, q0 + e1, q0 + e2])
    lo, hi = np.floor(corners.min(axis=0)), np.floor(corners.max(axis=0))
    if not wrap:
        lo, hi = np.maximum(lo, 0), np.minimum(hi, M - 1)
    big = np.prod(hi - lo + 1, axis=1) > 9
    got, coarse = _edge_accumulated(q0, e1, e2, flux, wrap, 9, device)
    assert coarse > 0
    bary, w = subtriangle_centroids(32)
    expected = np.zeros((M, M))
    for a, u, v, f in zip(q0[big], e1[big], e2[big], flux[big]):
        points = np.floor(a + bary[:, :1] * u + bary[:, 1:] * v).astype(int)
        if wrap:
            points %= M
        inside = np.all((points >= 0) & (points < M), axis=1)
        np.add.at(expected, (points[inside, 1], points[inside, 0]), w * f)
    small = np.zeros((M, M))
    for a, u, v, f in zip(q0[~big], e1[~big], e2[~big], flux[~big]):
        small += _clipped([a], [u], [v], [f], wrap)
    np.testing.assert_allclose(got, expected + small, rtol=0, atol=2e-5 * (expected + small).max())
