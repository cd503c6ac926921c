"""Beam caustics in vectorised float64 numpy: the twins of the beam rasteriser's per-pixel work.

- :func:`numpy_points` (``kernels/caustics/beams/irradiance.py`` ``point_irradiance``): for every
  receiver point, the point-in-beam test of each beam in its horizontal tile, the flat flux
  density, the receiver's cosine factor and the attenuation, summed per band;
- :func:`numpy_volume` (``kernels/caustics/beams/volume.py`` ``scan_plane_radiance``): for every
  camera pixel, the oriented-box test and the scan-plane chord of each beam copy in its screen tile,
  then the midpoint pieces of the in-scattering integral (Henyey–Greenstein phase), summed per band.

Both take the beams and tile lists the Warp stage built (read back with :func:`beam_arrays` and
:func:`tile_lists`) and run the (point or pixel, beam) pairs as flat float64 arrays (no Python loop
over pixels or beams; one loop over the ≤ 16 chord pieces), accumulating with ``bincount``. The
baselines of ``benchmarks/beams.py``.
"""

from __future__ import annotations

import numpy as np

MIN_AREA_FRACTION = 1.0e-6  # as kernels/caustics/beams/section.py
MAX_CHORD_PIECES = 16


def beam_arrays(stage) -> dict:
    return {
        "base": stage.base.numpy().astype(np.float64),
        "direction": stage.direction.numpy().astype(np.float64),
        "transmit": stage.transmit.numpy().astype(np.float64),
        "end_m": stage.end_m.numpy().astype(np.float64),
        "weight": stage.weight.numpy().astype(np.float64),
        "area_coef": stage.area_coef.numpy().astype(np.float64),
        "sun": stage.sun_irradiance.numpy().astype(np.float64),
        "attenuation": stage.attenuation_per_m.numpy().astype(np.float64),
        "per_group": stage.beams_per_group,
        "bands_per_group": stage.k // stage.groups,
        "k": stage.k,
    }


def tile_lists(bins) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return bins.start.numpy().copy(), bins.count.numpy().copy(), bins.items.numpy()[: bins.entries].copy()


CHUNK_PAIRS = 1 << 20
"""numpy handles the (query, beam) pairs in chunks of about this many (bounded memory)."""


def _expand(tile_of_query: np.ndarray, start: np.ndarray, count: np.ndarray, items: np.ndarray):
    """(query index, item) of every pair a tile list makes, as flat arrays."""
    n = count[tile_of_query]
    query = np.repeat(np.arange(len(tile_of_query)), n)
    first = np.repeat(start[tile_of_query] - np.concatenate([[0], np.cumsum(n)[:-1]]), n)
    return query, items[first + np.arange(n.sum())]


def _chunks(tile_of_query: np.ndarray, count: np.ndarray):
    """Consecutive query ranges holding about CHUNK_PAIRS pairs each."""
    cum = np.cumsum(count[tile_of_query])
    cuts = np.searchsorted(cum, np.arange(CHUNK_PAIRS, cum[-1] if len(cum) else 0, CHUNK_PAIRS))
    edges = np.unique(np.concatenate([[0], cuts + 1, [len(tile_of_query)]]))
    return [slice(a, b) for a, b in zip(edges[:-1], edges[1:])]


def _safe_area(coef: np.ndarray, z: np.ndarray, base_z: np.ndarray) -> np.ndarray:
    a = coef[:, 0] + z * (coef[:, 1] + z * coef[:, 2])
    a0 = coef[:, 0] + base_z * (coef[:, 1] + base_z * coef[:, 2])
    return np.maximum(np.abs(a), MIN_AREA_FRACTION * np.abs(a0) + 1e-20)


def _sections(v: np.ndarray, d: np.ndarray, z: np.ndarray) -> np.ndarray:
    return v[:, :, :2] + ((z[:, None] - v[:, :, 2]) / d[:, :, 2])[..., None] * d[:, :, :2]


def _barycentrics(sec: np.ndarray, p: np.ndarray) -> np.ndarray:
    a, b, c = sec[:, 0], sec[:, 1], sec[:, 2]

    def cross(u, w):
        return u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0]

    det = cross(b - a, c - a)
    safe = np.where(det == 0.0, 1.0, det)
    l1 = cross(p - a, c - a) / safe
    l2 = cross(b - a, p - a) / safe
    lam = np.stack([1.0 - l1 - l2, l1, l2], axis=1)
    lam[det == 0.0] = [-1.0, 0.0, 0.0]
    return lam


def _end_planes(v: np.ndarray, d: np.ndarray, ends: np.ndarray):
    e = v + ends[..., None] * d
    along = d.sum(axis=1)
    nrm = np.cross(e[:, 1] - e[:, 0], e[:, 2] - e[:, 0])
    scale = ((e[:, 1] - e[:, 0]) ** 2).sum(-1) + ((e[:, 2] - e[:, 0]) ** 2).sum(-1)
    collinear = np.linalg.norm(nrm, axis=-1) <= 1e-12 * np.maximum(scale, 1e-30)
    point = np.where(collinear[:, None], e.mean(axis=1), e[:, 0])
    nrm = np.where(collinear[:, None], [0.0, 0.0, -1.0], nrm)
    nrm /= np.linalg.norm(nrm, axis=-1, keepdims=True)
    nrm *= np.where((nrm * along).sum(-1) < 0.0, -1.0, 1.0)[:, None]
    return point, nrm


def _accumulate(
    out: np.ndarray, query: np.ndarray, beam: np.ndarray, value: np.ndarray, path: np.ndarray, beams: dict
) -> None:
    """out[k] += value · E_sun(k) exp(−c(k) path) for the bands of each beam's index group."""
    group = beam // beams["per_group"]
    for k in range(beams["k"]):
        sel = group == k // beams["bands_per_group"]
        w = value[sel] * beams["sun"][k] * np.exp(-beams["attenuation"][k] * path[sel])
        out[k] += np.bincount(query[sel], weights=w, minlength=out.shape[1])


def horizontal_tile(points: np.ndarray, grid: dict, periodic: bool) -> np.ndarray:
    """Horizontal tile of each point (kernels/caustics/beams/raster.py tile_of)."""
    ij = np.floor((points[:, :2] - grid["origin"]) / grid["size"]).astype(np.int64)
    ij = ij % grid["n"] if periodic else np.clip(ij, 0, grid["n"] - 1)
    return ij[:, 1] * grid["n"] + ij[:, 0]


def numpy_points(
    beams: dict, tiles, grid: dict, points: np.ndarray, normals: np.ndarray, extent_m: float, periodic: bool
) -> np.ndarray:
    """(K, P) irradiance at receiver points: ``point_irradiance`` with flat interpolation and the
    end-plane shadow test (no occluders), in float64."""
    tile = horizontal_tile(points, grid, periodic)
    out = np.zeros((beams["k"], len(points)))
    for part in _chunks(tile, tiles[1]):
        query, b = _expand(tile[part], *tiles)
        _points_chunk(out[:, part], beams, query, b, points[part], normals[part], extent_m, periodic)
    return out


def _points_chunk(out, beams, query, b, points, normals, extent_m, periodic) -> None:
    p, n = points[query], normals[query]
    v, d = beams["base"][b], beams["direction"][b]
    z = p[:, 2]
    sec = _sections(v, d, z)
    xy = p[:, :2]
    if periodic:
        xy = xy + extent_m * np.floor((sec[:, 0] - xy) / extent_m + 0.5)
    lam = _barycentrics(sec, xy)
    lengths = (v[:, :, 2] - z[:, None]) / -d[:, :, 2]
    path = (lam * lengths).sum(axis=1)
    inside = np.all(lam >= 0.0, axis=1) & (path >= 0.0)
    area = _safe_area(beams["area_coef"][b], z, v[:, :, 2].mean(axis=1))
    e0, ne = _end_planes(v, d, beams["end_m"][b])
    q = np.concatenate([xy, z[:, None]], axis=1)
    lit = ((q - e0) * ne).sum(-1) <= np.sqrt(area) + 1e-4
    dd = (lam[..., None] * d).sum(axis=1)
    dd /= np.linalg.norm(dd, axis=-1, keepdims=True)
    cos_factor = np.abs((dd * n).sum(-1)) / np.abs(dd[:, 2])
    density = beams["weight"][b] * (lam * beams["transmit"][b]).sum(axis=1) / area
    keep = inside & lit
    _accumulate(out, query[keep], b[keep], (cos_factor * density)[keep], path[keep], beams)


def _hg(cos_theta: np.ndarray, g: float) -> np.ndarray:
    denom = 1.0 + g * g - 2.0 * g * cos_theta
    return (1.0 - g * g) / (4.0 * np.pi * denom * np.sqrt(denom))


def numpy_volume(
    beams: dict,
    tiles,
    cam: dict,
    depth: np.ndarray,
    copies: int,
    extent_m: float,
    boxes: tuple[np.ndarray, np.ndarray, np.ndarray],
    scattering: np.ndarray,
    g: float,
    tile_px: int,
) -> np.ndarray:
    """(K, H, W) in-scattered radiance: ``scan_plane_radiance`` (flat interpolation, HG phase) in
    float64 over the pairs (pixel, beam copy) of the screen tile lists."""
    h, w = depth.shape
    jj, ii = np.mgrid[0:h, 0:w]
    tiles_x = -(-w // tile_px)
    tile = ((jj // tile_px) * tiles_x + ii // tile_px).ravel()
    out = np.zeros((beams["k"], h * w))
    for part in _chunks(tile, tiles[1]):
        query, item = _expand(tile[part], *tiles)
        query = query + part.start
        _volume_chunk(
            out,
            beams,
            query,
            item,
            ii.ravel(),
            jj.ravel(),
            cam,
            depth,
            copies,
            extent_m,
            boxes,
            scattering,
            g,
        )
    return out.reshape(beams["k"], h, w)


def pixel_rays(cam: dict, i: np.ndarray, j: np.ndarray, w: int, h: int) -> np.ndarray:
    """Unit rays through the centres of pixels (j, i) (kernels/scene/camera/pinhole.py pixel_ray), in
    float64."""
    x = 2.0 * (i + 0.5) / w - 1.0
    y = 1.0 - 2.0 * (j + 0.5) / h
    ray = (
        cam["forward"]
        + (x * cam["tan"] * cam["aspect"])[:, None] * cam["right"]
        + (y * cam["tan"])[:, None] * cam["up"]
    )
    return ray / np.linalg.norm(ray, axis=-1, keepdims=True)


def camera_dict(cam) -> dict:
    """A PinholeCamera's fields in float64, as the numpy twins take them."""
    return {
        "position": np.array(cam.position, np.float64),
        "right": np.array(cam.right, np.float64),
        "up": np.array(cam.up, np.float64),
        "forward": np.array(cam.forward, np.float64),
        "tan": float(cam.tan_half_fov),
        "aspect": float(cam.aspect),
    }


def scan_chords(o: np.ndarray, ray: np.ndarray, v: np.ndarray, d: np.ndarray, end_m: np.ndarray):
    """(s_a, s_b) of rays o + s·ray through beams with base vertices v (B, 3, 3), unit edge directions
    d and edge lengths end_m: ``kernels/caustics/beams/volume.py scan_chord`` in float64 (s_a > s_b
    for a miss)."""
    dbar = d.sum(axis=1)
    dbar /= np.linalg.norm(dbar, axis=-1, keepdims=True)
    wv = np.cross(ray, dbar)
    parallel = np.linalg.norm(wv, axis=-1) < 1e-4
    n_p = np.cross(ray, wv)
    n_p /= np.maximum(np.linalg.norm(n_p, axis=-1, keepdims=True), 1e-300)
    e2 = np.cross(n_p, ray)
    den = (d * n_p[:, None]).sum(-1)
    ok = np.all(np.abs(den) >= 1e-12, axis=1) & ~parallel
    t = ((o - v) * n_p[:, None]).sum(-1) / np.where(ok[:, None], den, 1.0)
    q = v + t[..., None] * d - o
    a = (q * ray[:, None]).sum(-1)
    cc = (q * e2[:, None]).sum(-1)
    s_a = np.full(len(v), np.inf)
    s_b = np.full(len(v), -np.inf)
    for i in range(3):
        j = (i + 1) % 3
        cross = (cc[:, i] >= 0) != (cc[:, j] >= 0)
        denom = np.where(cross, cc[:, i] - cc[:, j], 1.0)
        s = a[:, i] + (a[:, j] - a[:, i]) * cc[:, i] / denom
        s_a = np.where(cross, np.minimum(s_a, s), s_a)
        s_b = np.where(cross, np.maximum(s_b, s), s_b)
    # Along the beam: inside iff the ray's point on the base plane is in the base triangle.
    nb = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
    if parallel.any():
        dn = (ray * nb).sum(-1)
        hit = o + (((v[:, 0] - o) * nb).sum(-1) / np.where(dn == 0, 1.0, dn))[:, None] * ray
        lam = _barycentrics(v[:, :, :2], hit[:, :2])
        inside = parallel & (dn != 0) & np.all(lam >= 0, axis=1)
        s_a = np.where(inside, -1e30, s_a)
        s_b = np.where(inside, 1e30, s_b)
    s_a = np.where(ok | parallel, s_a, np.inf)
    nb /= np.linalg.norm(nb, axis=-1, keepdims=True)
    nb *= np.where((nb * dbar).sum(-1) < 0, -1.0, 1.0)[:, None]
    e0, ne = _end_planes(v, d, end_m)
    for p0, nrm, sign in ((v[:, 0], nb, 1.0), (e0, ne, -1.0)):
        a0 = sign * ((o - p0) * nrm).sum(-1)
        k = sign * (ray * nrm).sum(-1)
        flat = np.abs(k) < 1e-20
        root = -a0 / np.where(flat, 1.0, k)
        s_a = np.where(~flat & (k > 0), np.maximum(s_a, root), s_a)
        s_b = np.where(~flat & (k < 0), np.minimum(s_b, root), s_b)
        s_a = np.where(flat & (a0 < 0), np.inf, s_a)
    return s_a, s_b


def _volume_chunk(
    out, beams, query, item, ii, jj, cam, depth, copies, extent_m, boxes, scattering, g
) -> None:
    h, w = depth.shape
    px, py = ii[query] + 0.5, jj[query] + 0.5
    axis, lo, hi = boxes[0][item], boxes[1][item], boxes[2][item]
    u = px * axis[:, 0] + py * axis[:, 1]
    vv = -px * axis[:, 1] + py * axis[:, 0]
    keep = (u >= lo[:, 0] - 1e-3) & (u <= hi[:, 0] + 1e-3) & (vv >= lo[:, 1] - 1e-3) & (vv <= hi[:, 1] + 1e-3)
    query, item = query[keep], item[keep]
    ray = pixel_rays(cam, ii[query], jj[query], w, h)
    o = cam["position"]
    b = item // (copies * copies)
    c = item % (copies * copies)
    r = copies // 2
    shift = np.stack([(c % copies - r) * extent_m, (c // copies - r) * extent_m, np.zeros(len(c))], axis=1)
    v = beams["base"][b] + shift[:, None]
    s_a, s_b = scan_chords(o, ray, v, beams["direction"][b], beams["end_m"][b])
    s_a = np.maximum(s_a, 0.0)
    s_b = np.minimum(s_b, depth.ravel()[query])
    hit = s_b > s_a
    query, b, ray, shift, s_a, s_b = query[hit], b[hit], ray[hit], shift[hit], s_a[hit], s_b[hit]
    v = beams["base"][b]
    d = beams["direction"][b]
    ds = s_b - s_a
    mid = o + (0.5 * (s_a + s_b))[:, None] * ray - shift
    width = np.sqrt(_safe_area(beams["area_coef"][b], mid[:, 2], v[:, 0, 2]))
    pieces = np.clip((ds / np.maximum(width, 1e-6)).astype(np.int64) + 1, 1, MAX_CHORD_PIECES)
    piece = ds / pieces
    e0, ne = _end_planes(v, d, beams["end_m"][b])
    for n in range(MAX_CHORD_PIECES):
        m = n < pieces
        s_m = s_a[m] + (n + 0.5) * piece[m]
        xm = o + s_m[:, None] * ray[m] - shift[m]
        vm, dm = v[m], d[m]
        z = xm[:, 2]
        lam = np.clip(_barycentrics(_sections(vm, dm, z), xm[:, :2]), 0.0, None)
        total = lam.sum(axis=1)
        lam = np.where(total[:, None] > 0, lam / np.where(total > 0, total, 1.0)[:, None], 1.0 / 3.0)
        path = (lam * (vm[:, :, 2] - z[:, None]) / -dm[:, :, 2]).sum(axis=1)
        area = _safe_area(beams["area_coef"][b[m]], z, vm[:, :, 2].mean(axis=1))
        lit = ((xm - e0[m]) * ne[m]).sum(-1) <= np.sqrt(area) + 1e-4
        dd = (lam[..., None] * dm).sum(axis=1)
        dd /= np.linalg.norm(dd, axis=-1, keepdims=True)
        phase = _hg(-(dd * ray[m]).sum(-1), g)
        density = beams["weight"][b[m]] * (lam * beams["transmit"][b[m]]).sum(axis=1) / area
        value = piece[m] * phase * density / np.abs(dd[:, 2])
        group = b[m] // beams["per_group"]
        for k in range(beams["k"]):
            sel = lit & (group == k // beams["bands_per_group"])
            wk = (
                value[sel]
                * scattering[k]
                * beams["sun"][k]
                * np.exp(-beams["attenuation"][k] * (path[sel] + s_m[sel]))
            )
            out[k] += np.bincount(query[m][sel], weights=wk, minlength=h * w)
