"""Vectorised float64 numpy implementation of the flux-ratio floor caustics (refraction included).

The same algorithm as the Warp kernels (``kernels/optics/refract.py``,
``kernels/caustics/fluxratio.py``), written independently with array operations and no Python
loops over triangles or texels. It is the baseline of ``benchmarks/`` and a float64 cross-check in
``tests/``.
"""

from __future__ import annotations

import numpy as np

from warpcaustics.optics.snell import fresnel_transmittance, refract  # noqa: F401 (re-exported)

MIN_DOWNWARD_COS = 1.0e-3
DEGENERATE_AREA_TEXELS = 1.0e-9
MAX_CLIPPED_TEXELS = 4096
SAMPLE_SUBDIVISIONS = 32
_CHUNK_PAIRS = 1 << 18  # (triangle, texel) pairs clipped at once; bounds peak memory


def sun_visibility(positions, sun_dir, extent_m):
    """(N, N) 1 where a vertex sees the sun over the periodic height field, 0 where shaded: the
    sweep, as the kernels shade a periodic surface (:func:`sweep_visibility`)."""
    if np.asarray(sun_dir, np.float64)[2] <= 1e-6:
        return march_visibility(positions, sun_dir, extent_m)
    return sweep_visibility(positions, sun_dir, extent_m)


def bilinear_periodic(z: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Periodic bilinear heights of cell-centre heights ``z`` (N, N) at cell coordinates (u, v)."""
    n = z.shape[0]
    i0, j0 = np.floor(u).astype(np.int64), np.floor(v).astype(np.int64)
    tu, tv = u - i0, v - j0
    return ((1 - tv) * ((1 - tu) * z[j0 % n, i0 % n] + tu * z[j0 % n, (i0 + 1) % n])
            + tv * ((1 - tu) * z[(j0 + 1) % n, i0 % n] + tu * z[(j0 + 1) % n, (i0 + 1) % n]))


def sweep_visibility(positions, sun_dir, extent_m):
    """(N, N) crest shading by the sweep of ``kernels/optics/horizon.py`` in float64: on a lattice
    aligned with the light's azimuth, half a cell apart both ways and covering the patch turned to
    it, F(x) = max(h(x), F(x + δâ) − δk) swept down every line from where no crest can reach a ray,
    then each vertex shaded where F(p + δâ) − δk (bilinear in the lattice) rises above it."""
    positions = np.asarray(positions, np.float64)
    n = positions.shape[0]
    s = np.asarray(sun_dir, np.float64)
    horizontal = np.hypot(s[0], s[1])
    if horizontal < 1e-6:
        return np.ones((n, n))
    z = positions[..., 2]
    along = s[:2] / horizontal
    across = np.array([-along[1], along[0]])
    spacing = 0.5 * extent_m / n
    rise = spacing * s[2] / horizontal
    half = 0.5 * extent_m * (abs(along[0]) + abs(along[1])) + 2.0 * spacing
    lines = int(np.ceil(2.0 * half / spacing)) + 1
    stored = lines + 2
    steps = stored + int(np.ceil((z.max() - z.min()) / rise)) + 2
    r = -half + np.arange(lines) * spacing
    best = np.full(lines, -np.inf)
    horizon = np.empty((stored, lines))
    for i in range(steps - 1, -1, -1):
        x = (-half + i * spacing) * along[0] + r * across[0] + 0.5 * extent_m
        y = (-half + i * spacing) * along[1] + r * across[1] + 0.5 * extent_m
        h = bilinear_periodic(z, x * n / extent_m - 0.5, y * n / extent_m - 0.5)
        best = np.maximum(best, h - i * rise)
        if i < stored:
            horizon[i] = best + i * rise
    x = positions[..., 0] - extent_m * np.floor((positions[..., 0] + 0.5 * extent_m) / extent_m)
    y = positions[..., 1] - extent_m * np.floor((positions[..., 1] + 0.5 * extent_m) / extent_m)
    u = (x * along[0] + y * along[1] + spacing + half) / spacing
    v = (x * across[0] + y * across[1] + half) / spacing
    i0 = np.clip(np.floor(u).astype(np.int64), 0, stored - 2)
    j0 = np.clip(np.floor(v).astype(np.int64), 0, lines - 2)
    tu, tv = u - i0, v - j0
    highest = ((1 - tu) * ((1 - tv) * horizon[i0, j0] + tv * horizon[i0, j0 + 1])
               + tu * ((1 - tv) * horizon[i0 + 1, j0] + tv * horizon[i0 + 1, j0 + 1]))
    return np.where(highest - rise > z + 1e-4 * extent_m / n, 0.0, 1.0)


def march_visibility(positions, sun_dir, extent_m, step_cells=0.5):
    """(N, N) crest shading by the half-cell march towards the sun of ``kernels/optics/refract.py``
    (walled surfaces, and the sweep's baseline), for all vertices at once; ``step_cells``: the
    horizontal step in cells (finer: the bilinear surface's own shading, to that step)."""
    n = positions.shape[0]
    s = np.asarray(sun_dir, np.float64)
    horizontal = np.hypot(s[0], s[1])
    visible = np.ones((n, n))
    if horizontal < 1e-6:
        return visible
    z = positions[..., 2]
    cell = extent_m / n
    step = step_cells * cell / horizontal
    steps = np.ceil((z.max() - z) / (s[2] * step)).astype(np.int64) + 1
    for i in range(1, int(steps.max()) + 1):
        q = positions + (i * step) * s
        h = bilinear_periodic(z, (q[..., 0] + 0.5 * extent_m) * n / extent_m - 0.5,
                              (q[..., 1] + 0.5 * extent_m) * n / extent_m - 0.5)
        visible[(i <= steps) & (h > q[..., 2] + 1e-4 * cell)] = 0.0
    return visible


def refract_to_floor(positions, normals, sun_dir, ior, floor_z, visible=None):
    """Per-vertex floor hit (N, N, 2), path length (N, N) and transmittance (N, N)."""
    eta = 1.0 / ior
    s = np.asarray(sun_dir, np.float64)
    cos_i = normals @ s
    d = refract(np.broadcast_to(-s, normals.shape), normals, eta)
    ok = (cos_i > 0) & (d[..., 2] < -MIN_DOWNWARD_COS)
    t = np.where(ok[..., None], d / np.linalg.norm(np.where(ok[..., None], d, 1.0), axis=-1,
                                                   keepdims=True), [0.0, 0.0, -1.0])
    ell = (floor_z - positions[..., 2]) / t[..., 2]
    hit = positions[..., :2] + ell[..., None] * t[..., :2]
    trans = np.where(ok, fresnel_transmittance(cos_i, eta), 0.0)
    if visible is not None:
        trans = trans * visible
    return hit, ell, trans


def triangles(n: int, extent_m: float):
    """Corner indices (T, 3) into the flattened grid and periodic shifts (T, 3, 2) [m].

    Triangle order matches the kernels' ``(half, iy, ix)``: half 0 = corners (0,0),(1,0),(1,1);
    half 1 = (0,0),(1,1),(0,1).
    """
    iy, ix = np.meshgrid(np.arange(n), np.arange(n), indexing="ij")
    corners = {0: [(0, 0), (1, 0), (1, 1)], 1: [(0, 0), (1, 1), (0, 1)]}
    idx, shift = [], []
    for half in (0, 1):
        ci, cs = [], []
        for dx, dy in corners[half]:
            cx, cy = ix + dx, iy + dy
            cs.append(np.stack([(cx == n) * extent_m, (cy == n) * extent_m], axis=-1).reshape(-1, 2))
            ci.append(((cy % n) * n + (cx % n)).reshape(-1))
        idx.append(np.stack(ci, axis=1))
        shift.append(np.stack(cs, axis=1))
    return np.concatenate(idx), np.concatenate(shift).astype(np.float64)


def subtriangle_centroids(s: int) -> tuple[np.ndarray, float]:
    """Barycentric (u, v) of the centroids of the s² congruent sub-triangles, and their weight."""
    a, b = np.meshgrid(np.arange(s), np.arange(s), indexing="ij")
    up = (a + b) <= s - 1
    down = (a + b) <= s - 2
    pts = np.concatenate([np.stack([a[up] + 1 / 3, b[up] + 1 / 3], -1),
                          np.stack([a[down] + 2 / 3, b[down] + 2 / 3], -1)]) / s
    return pts, 1.0 / (s * s)


def _clip(px, py, count, axis, bound, keep_above):
    """Vectorised Sutherland–Hodgman step on padded polygons (P, V) with per-row counts."""
    p_count, v = px.shape
    j = np.arange(v)
    valid = j[None, :] < count[:, None]
    jn = np.where(j[None, :] + 1 < count[:, None], j[None, :] + 1, 0)
    nx = np.take_along_axis(px, jn, axis=1)
    ny = np.take_along_axis(py, jn, axis=1)
    a, b = (px, nx) if axis == 0 else (py, ny)
    bound = bound[:, None]
    sa, sb = (a - bound, b - bound) if keep_above else (bound - a, bound - b)
    keep = valid & (sa >= 0)
    cross = valid & ((sa >= 0) != (sb >= 0))
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(cross, sa / (sa - sb), 0.0)
    # Two output slots per input edge: the kept vertex, then the crossing point.
    ox = np.stack([px, px + t * (nx - px)], axis=2).reshape(p_count, 2 * v)
    oy = np.stack([py, py + t * (ny - py)], axis=2).reshape(p_count, 2 * v)
    om = np.stack([keep, cross], axis=2).reshape(p_count, 2 * v)
    # Compact the kept slots to the left of each row (at most 8 survive a slab clip).
    rows, cols = np.nonzero(om)
    dest = (np.cumsum(om, axis=1) - 1)[rows, cols]
    qx = np.zeros((p_count, 8))
    qy = np.zeros((p_count, 8))
    qx[rows, dest] = ox[rows, cols]
    qy[rows, dest] = oy[rows, cols]
    return qx, qy, om.sum(axis=1)


def _area(px, py, count):
    v = px.shape[1]
    j = np.arange(v)
    valid = j[None, :] < count[:, None]
    jn = np.where(j[None, :] + 1 < count[:, None], j[None, :] + 1, 0)
    nx = np.take_along_axis(px, jn, axis=1)
    ny = np.take_along_axis(py, jn, axis=1)
    return 0.5 * np.abs(np.sum(np.where(valid, px * ny - nx * py, 0.0), axis=1))


def view_weights(positions, hit, ell, floor_z, axis, cos_half):
    """(N, N) a radiance sensor's weight of each vertex's refracted ray (``floor.view_*``): 1/|t_z|
    where the ray t (from the vertex to its floor hit) arrives from within the cone of half-angle
    acos(``cos_half``) about the upward ``axis``, 0 elsewhere."""
    t = np.concatenate([hit - positions[..., :2], (floor_z - positions[..., 2])[..., None]], axis=-1)
    t = t / ell[..., None]
    inside = (-(t @ np.asarray(axis, np.float64)) >= cos_half) & (t[..., 2] < 0.0)
    return np.where(inside, 1.0 / np.where(inside, -t[..., 2], 1.0), 0.0)


def floor_caustics(positions, normals, sun_dir, ior, floor_depth_m, sun_irradiance,
                   attenuation_per_m, extent_m, map_resolution, view=None):
    """Floor irradiance (K, M, M) [W m^-2 nm^-1] and per-triangle flux (K, T) [W nm^-1]; with
    ``view`` = (axis, cos_half), the light within a radiance sensor's cone, ∫ L dω [W m^-2 nm^-1]
    (:func:`view_weights`)."""
    positions = np.asarray(positions, np.float64)
    normals = np.asarray(normals, np.float64)
    n = positions.shape[0]
    m = map_resolution
    visible = sun_visibility(positions, sun_dir, extent_m)
    hit, ell, trans = refract_to_floor(positions, normals, sun_dir, ior, -floor_depth_m, visible)
    if view is not None:
        trans = trans * view_weights(positions, hit, ell, -floor_depth_m, *view)
    idx, shift = triangles(n, extent_m)
    p = positions.reshape(-1, 3)[idx]
    p[..., :2] += shift
    a_perp = 0.5 * np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]) @ np.asarray(sun_dir, np.float64)
    att = np.exp(-np.asarray(attenuation_per_m)[:, None, None] * ell.reshape(-1)[idx][None])
    mean_t = np.mean(trans.reshape(-1)[idx][None] * att, axis=2)  # (K, T)
    flux = np.where(a_perp > 0, np.asarray(sun_irradiance)[:, None] * a_perp * mean_t, 0.0)

    # Footprints in texels, corner 0 wrapped into [0, M) (a whole-period shift changes nothing).
    corners = hit.reshape(-1, 2)[idx] + shift
    q = (corners - corners[:, :1]) * (m / extent_m)
    q += np.mod((corners[:, :1] + 0.5 * extent_m) * (m / extent_m), m)
    lo_f, hi_f = np.floor(q.min(axis=1)), np.floor(q.max(axis=1))
    e1, e2 = q[:, 1] - q[:, 0], q[:, 2] - q[:, 0]
    area = 0.5 * np.abs(e1[:, 0] * e2[:, 1] - e1[:, 1] * e2[:, 0])
    lit = np.nonzero(flux.max(axis=0) > 0)[0]
    coarse = (np.prod(hi_f - lo_f + 1, axis=1) > MAX_CLIPPED_TEXELS)[lit]
    lo = np.where(coarse[:, None], 0, lo_f[lit]).astype(np.int64)
    hi = np.where(coarse[:, None], 0, hi_f[lit]).astype(np.int64)
    lo_all = np.zeros((len(q), 2), np.int64)
    hi_all = np.zeros((len(q), 2), np.int64)
    lo_all[lit], hi_all[lit] = lo, hi
    lo, hi = lo_all, hi_all
    q = q - lo[:, None, :]
    single = ~coarse & (np.all(lo[lit] == hi[lit], axis=1) | (area[lit] < DEGENERATE_AREA_TEXELS))

    tri_parts, texel_parts, weight_parts = [], [], []
    # Huge footprints: equal shares at the centroids of S² congruent sub-triangles.
    tc = lit[coarse]
    bary, w = subtriangle_centroids(SAMPLE_SUBDIVISIONS)
    pts = q[tc, None, 0] + bary[None, :, :1] * e1[tc, None] + bary[None, :, 1:] * e2[tc, None]
    cells = np.mod(np.floor(pts), m).astype(np.int64)
    tri_parts.append(np.repeat(tc, len(bary)))
    texel_parts.append((cells[..., 1] * m + cells[..., 0]).reshape(-1))
    weight_parts.append(np.full(len(tc) * len(bary), w))
    # Footprints inside one texel (or degenerate): everything to the centroid's texel.
    t1 = lit[single]
    c = lo[t1] + np.floor(q[t1].mean(axis=1)).astype(np.int64)
    tri_parts.append(t1)
    texel_parts.append((c[:, 1] % m) * m + (c[:, 0] % m))
    weight_parts.append(np.ones(len(t1)))
    # Larger footprints: clip against every texel of the bounding box.
    tm = lit[~single & ~coarse]
    span = hi[tm] - lo[tm] + 1
    counts = span[:, 0] * span[:, 1]
    starts = np.concatenate([[0], np.cumsum(counts)])
    # Chunk boundaries (in triangles) so that each chunk clips at most ~_CHUNK_PAIRS pairs.
    bounds = np.unique(np.searchsorted(starts, np.arange(0, starts[-1], _CHUNK_PAIRS), side="right") - 1)
    for b0, b1 in zip(bounds, np.append(bounds[1:], len(tm))):
        tri = np.repeat(tm[b0:b1], counts[b0:b1])
        local = np.arange(starts[b0], starts[b1]) - np.repeat(starts[b0:b1], counts[b0:b1])
        w_span = np.repeat(span[b0:b1, 0], counts[b0:b1])
        ci, cj = local % w_span, local // w_span
        px = np.zeros((len(tri), 8))
        py = np.zeros((len(tri), 8))
        px[:, :3] = q[tri, :, 0]
        py[:, :3] = q[tri, :, 1]
        cnt = np.full(len(tri), 3)
        for axis, b, above in ((0, ci, True), (0, ci + 1, False), (1, cj, True), (1, cj + 1, False)):
            px, py, cnt = _clip(px, py, cnt, axis, b.astype(np.float64), above)
        overlap = np.where(cnt >= 3, _area(px, py, cnt), 0.0)
        tri_parts.append(tri)
        texel_parts.append(((lo[tri, 1] + cj) % m) * m + (lo[tri, 0] + ci) % m)
        weight_parts.append(overlap / area[tri])
    tri = np.concatenate(tri_parts)
    texel = np.concatenate(texel_parts)
    weight = np.concatenate(weight_parts) * (m / extent_m) ** 2
    floor = np.stack([np.bincount(texel, weights=weight * flux[k, tri], minlength=m * m)
                      for k in range(flux.shape[0])]).reshape(-1, m, m)
    return floor, flux
