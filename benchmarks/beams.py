"""Beam caustics (``caustics.method = "beams"``): the tile rasteriser in Warp vs a vectorised numpy twin.

Both sides get the same beams and the same tile lists (built by the Warp stage and read back), so
the ratio measures the per-pixel work alone:

- **surface gather** (``kernels/beams.py`` ``point_irradiance``): for every receiver point, the
  point-in-beam test of each beam in its horizontal tile, the flat flux density, the receiver's
  cosine factor and the attenuation, summed per band. Points: a regular grid of points (4×4 per
  map texel) on a rippled floor under the default ocean, shadows by the beams' end planes.
- **volume scan planes** (``scan_plane_radiance``): for every camera pixel, the oriented-box test
  and the scan-plane chord of each beam copy in its screen tile, then the midpoint pieces of the
  in-scattering integral (Henyey–Greenstein phase), summed per band. Camera: ``ocean_floor.toml``.

numpy runs the pairs (point or pixel, beam) as flat float64 arrays (no Python loop over pixels or
beams; one loop over the ≤ 16 chord pieces) and accumulates with ``bincount``. Scaling rows time the
whole beam stage (build, bin, flat-floor map) against the beam count and the map resolution.
``python -m benchmarks.beams --help``.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from benchmarks.run import calls_per_round, device_record, interleaved_times, median_time, point_sun_scene

ROOT = Path(__file__).resolve().parents[1]

FULL = {
    "gather_n": 128,
    "gather_m": 128,
    "camera": (160, 120),
    "camera_n": 64,
    "scaling_n": (32, 64, 128, 256),
    "scaling_m": (128, 256, 512, 1024),
    "adaptive_n": 256,
    "adaptive_m": 256,
}
QUICK = {
    "gather_n": 32,
    "gather_m": 64,
    "camera": (64, 48),
    "camera_n": 32,
    "scaling_n": (16, 32),
    "scaling_m": (32, 64),
    "adaptive_n": 32,
    "adaptive_m": 32,
}
WAVELENGTHS = "rgb"
MIN_AREA_FRACTION = 1.0e-6  # as kernels/beams.py
MAX_CHORD_PIECES = 16


def _beam_arrays(stage) -> dict:
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


def _tile_lists(bins) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
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
    """Horizontal tile of each point (kernels/beams.py tile_of)."""
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
    """Unit rays through the centres of pixels (j, i) (kernels/camera.py pixel_ray) in float64."""
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
    d and edge lengths end_m: ``kernels/beams.py scan_chord`` in float64 (s_a > s_b for a miss)."""
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


def relative_l1(reference: np.ndarray, other: np.ndarray) -> float:
    return float(
        np.abs(np.asarray(other, np.float64) - reference).sum() / max(np.abs(reference).sum(), 1e-300)
    )


def _gather_case(n: int, m: int, device: str, warp_repeats: int, numpy_repeats: int) -> dict:
    import warp as wp

    import warpcaustics as wc

    scene = point_sun_scene(
        ROOT / "configs" / "ocean.toml",
        {
            "caustics.method": "beams",
            "water.resolution": n,
            "caustics.map_resolution": m,
            "optics.wavelengths": WAVELENGTHS,
            "floor.shape": "ripples",
            "floor.ripple_amplitude_m": 0.1,
            "floor.ripple_wavelength_m": 16.0 / np.hypot(7, 26),
            "floor.ripple_direction_deg": np.degrees(np.arctan2(26, 7)),
        },
    )
    renderer = wc.Renderer(scene, device)
    renderer.render(0.0)  # warm-up: JIT compile, builds and bins the beams
    stage = renderer.beams
    # Both sides decide shadows by the beam's end plane (the twin has no BVH for shadow rays).
    stage.occluders = False
    # Receiver points: (m·4)² points on the rippled relief (what a camera's G-buffer would hold).
    from warpcaustics.scene.receivers import floor_relief_height

    cfg = scene.config
    u = (np.arange(4 * m) + 0.5) * (cfg.water.extent_m / (4 * m)) - 0.5 * cfg.water.extent_m
    x, y = (a.ravel() for a in np.meshgrid(u, u))
    h = 1e-4
    z = floor_relief_height(cfg.floor, None, cfg.water.extent_m, x, y)
    dzdx = (floor_relief_height(cfg.floor, None, cfg.water.extent_m, x + h, y) - z) / h
    dzdy = (floor_relief_height(cfg.floor, None, cfg.water.extent_m, x, y + h) - z) / h
    nrm = np.stack([-dzdx, -dzdy, np.ones_like(z)], -1)
    nrm /= np.linalg.norm(nrm, axis=-1, keepdims=True)
    pts = np.stack([x, y, z], -1)
    args = (wp.array(pts.astype(np.float32), dtype=wp.vec3, device=device),
            wp.array(nrm.astype(np.float32), dtype=wp.vec3, device=device),
            wp.zeros(len(pts), dtype=wp.int32, device=device),
            wp.empty((stage.k, len(pts)), dtype=wp.float32, device=device))

    def warp_run():
        stage.points(*args)

    warp_run()
    wp.synchronize_device(device)
    warp_out = args[3].numpy().astype(np.float64)
    beams = _beam_arrays(stage)
    bins = stage.point_bins
    grid = {
        "origin": np.array(bins.grid.origin, np.float64),
        "size": float(bins.grid.size[0]),
        "n": bins.grid.nx,
    }
    tiles = _tile_lists(bins)
    points = args[0].numpy().astype(np.float64)
    normals = args[1].numpy().astype(np.float64)

    numpy_out = []

    def numpy_run():
        numpy_out[:] = [numpy_points(beams, tiles, grid, points, normals, stage.extent_m, stage.periodic)]

    times = interleaved_times({"warp": (warp_run, calls_per_round(warp_repeats, numpy_repeats)),
                               "numpy": (numpy_run, 1)}, numpy_repeats, device)
    warp_s, numpy_s = (float(np.median(times[side])) for side in ("warp", "numpy"))
    numpy_out = numpy_out[0]
    pairs = int(tiles[1][horizontal_tile(points, grid, stage.periodic)].sum())
    return {
        "water_n": n,
        "map_m": m,
        "points": len(points),
        "beams": stage.weight.shape[0],
        "pairs": pairs,
        "warp_s": warp_s,
        "numpy_s": numpy_s,
        "speedup_warp_vs_numpy": numpy_s / warp_s,
        "warp_points_per_s": len(points) / warp_s,
        "numpy_points_per_s": len(points) / numpy_s,
        "relative_l1_numpy_vs_warp": relative_l1(numpy_out, warp_out),
    }


def _convex_area_on_screen(points: np.ndarray, width: int, height: int) -> float:
    """Area [pixels] of the convex hull of 2-D points clipped to the screen (≈ pixels a rasteriser
    touches)."""
    pts = sorted(map(tuple, points))
    if len(pts) < 3:
        return 0.0

    def half(seq):
        out = []
        for q in seq:
            while len(out) >= 2 and ((out[-1][0] - out[-2][0]) * (q[1] - out[-2][1])
                                     - (out[-1][1] - out[-2][1]) * (q[0] - out[-2][0])) <= 0:
                out.pop()
            out.append(q)
        return out

    poly = half(pts)[:-1] + half(pts[::-1])[:-1]
    for axis, bound, keep_above in ((0, 0.0, True), (0, float(width), False), (1, 0.0, True),
                                    (1, float(height), False)):
        clipped = []
        for a, b in zip(poly, poly[1:] + poly[:1]):
            sa = (a[axis] - bound) * (1 if keep_above else -1)
            sb = (b[axis] - bound) * (1 if keep_above else -1)
            if sa >= 0:
                clipped.append(a)
            if (sa >= 0) != (sb >= 0):
                t = sa / (sa - sb)
                clipped.append((a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])))
        poly = clipped
        if len(poly) < 3:
            return 0.0
    x, y = np.array(poly).T
    return 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))


def prism_ends(v: np.ndarray, d: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """(B, 3, 3) end vertices of a bounding prism of each beam in the manner of Ernst et al. 2005:
    each side is the plane through a base edge tilted just enough to hold all three end points;
    neighbouring sides meet in a line through the shared base vertex, cut by the plane of
    the three edge ends. NaN where a corner line runs parallel to the end plane."""
    e = v + ends[..., None] * d
    normals = []
    for i in range(3):
        j, k = (i + 1) % 3, (i + 2) % 3
        u = v[:, j] - v[:, i]
        inward = v[:, k] - v[:, i]
        best = np.full_like(u, np.nan)
        for cand in range(3):  # the plane through the edge and the end that holds all three ends
            n = np.cross(u, e[:, cand] - v[:, i])
            n *= np.where((n * inward).sum(-1) < 0, -1.0, 1.0)[:, None]
            tol = 1e-9 * np.linalg.norm(n, axis=-1, keepdims=True)
            ok = np.all(((e - v[:, i][:, None]) * n[:, None]).sum(-1) >= -tol, axis=1)
            best = np.where(ok[:, None] & np.isnan(best), n, best)
        normals.append(best)
    dbar = d.sum(axis=1)
    e0 = e.mean(axis=1)
    ne = np.cross(e[:, 1] - e[:, 0], e[:, 2] - e[:, 0])
    out = np.empty_like(v)
    for i in range(3):
        line = np.cross(normals[(i + 2) % 3], normals[i])  # sides (k, i) and (i, j) meet at v_i
        line *= np.where((line * dbar).sum(-1) < 0, -1.0, 1.0)[:, None]
        t = ((e0 - v[:, i]) * ne).sum(-1) / (line * ne).sum(-1)
        out[:, i] = v[:, i] + t[:, None] * line
    return out


def fill_measure(stage, camera, copies: int, samples: int, seed: int = 1) -> dict:
    """Pixels a rasteriser would touch for the beams' bounding volumes, on a sample of the beam copies
    wholly in front of the camera: the tight hull (convex hull of base and end vertices) against a
    bounding prism in Ernst's manner (:func:`prism_ends`), each projected and clipped to the frame;
    and the pixels where the beam really is, whose centre ray has a scan-plane chord through it in
    front of the camera (:func:`scan_chords`, float64; receivers not considered)."""
    cam = camera.cam
    pos = np.array(cam.position, np.float64)
    right, up, fwd = (np.array(a, np.float64) for a in (cam.right, cam.up, cam.forward))
    w, h = int(cam.width), int(cam.height)
    v = stage.base.numpy().astype(np.float64)
    d = stage.direction.numpy().astype(np.float64)
    ends = stage.end_m.numpy().astype(np.float64)
    carrying = np.flatnonzero(stage.weight.numpy() > 0)
    rng = np.random.default_rng(seed)
    items = rng.choice(len(carrying) * copies * copies, size=min(samples * 4, len(carrying) * copies**2),
                       replace=False)
    b = carrying[items // (copies * copies)]
    c = items % (copies * copies)
    r = copies // 2
    shift = np.stack([(c % copies - r) * stage.extent_m, (c // copies - r) * stage.extent_m, 0 * c], 1)
    vb = v[b] + shift[:, None]
    hull = np.concatenate([vb, vb + ends[b][..., None] * d[b]], axis=1)
    prism = np.concatenate([vb, prism_ends(vb, d[b], ends[b])], axis=1)

    def project(x):
        rel = x - pos
        z = rel @ fwd
        px = (rel @ right / (z * cam.tan_half_fov * cam.aspect) + 1.0) * 0.5 * w
        py = (1.0 - rel @ up / (z * cam.tan_half_fov)) * 0.5 * h
        return np.stack([px, py], -1), z

    hp, hz = project(hull)
    pp, pz = project(prism)
    good = np.all(hz > 1e-3, axis=1) & np.all(pz > 1e-3, axis=1) & np.all(np.isfinite(pp), axis=(1, 2))
    hull_px, prism_px, used = 0.0, 0.0, []
    for i in np.flatnonzero(good):
        a_hull = _convex_area_on_screen(hp[i], w, h)
        a_prism = _convex_area_on_screen(pp[i], w, h)
        if a_prism <= 0.0 and a_hull <= 0.0:
            continue
        hull_px += a_hull
        prism_px += a_prism
        used.append(i)
        if len(used) >= samples:
            break
    # Where the beams are: every pixel of each hull's screen box, tested by its centre ray.
    used = np.array(used, np.int64)
    lo = np.clip(np.floor(hp[used].min(axis=1)), 0, [w, h]).astype(np.int64)
    hi = np.clip(np.ceil(hp[used].max(axis=1)), 0, [w, h]).astype(np.int64)
    size = hi - lo
    count = size[:, 0] * size[:, 1]
    beam = np.repeat(np.arange(len(used)), count)
    k = np.arange(count.sum()) - np.repeat(np.cumsum(count) - count, count)
    px = lo[beam, 0] + k % np.maximum(size[beam, 0], 1)
    py = lo[beam, 1] + k // np.maximum(size[beam, 0], 1)
    inside = 0
    cam_np = camera_dict(cam)
    for part in np.array_split(np.arange(len(beam)), max(1, len(beam) // CHUNK_PAIRS + 1)):
        q = used[beam[part]]
        s_a, s_b = scan_chords(pos, pixel_rays(cam_np, px[part], py[part], w, h), vb[q], d[b[q]], ends[b[q]])
        inside += int(np.count_nonzero(s_b > np.maximum(s_a, 0.0)))
    return {"beams_measured": len(used), "hull_pixels": hull_px, "prism_pixels": prism_px,
            "hull_over_prism": hull_px / max(prism_px, 1e-300), "beam_pixels": inside,
            "hull_fill": inside / max(hull_px, 1e-300), "prism_fill": inside / max(prism_px, 1e-300)}


def _volume_case(n: int, size: tuple[int, int], device: str, warp_repeats: int, numpy_repeats: int) -> dict:
    import warp as wp

    import warpcaustics as wc
    from warpcaustics.caustics.beams import SCREEN_TILE_PIXELS

    scene = point_sun_scene(
        ROOT / "configs" / "ocean_floor.toml",
        {
            "caustics.method": "beams",
            "water.resolution": n,
            "optics.wavelengths": WAVELENGTHS,
            "camera.width": size[0],
            "camera.height": size[1],
            "optics.phase_function": "henyey_greenstein",
        },
    )
    renderer = wc.Renderer(scene, device)
    renderer.render(0.0)  # warm-up
    camera, stage = renderer.camera, renderer.beams

    camera.render_beams(stage, True)
    wp.synchronize_device(device)
    warp_out = camera.shafts.numpy().astype(np.float64)
    fill = camera.beam_fill()
    fill.update(fill_measure(stage, camera, 3 if stage.periodic else 1, samples=3000))
    bins = camera._screen_bins
    cam_np = camera_dict(camera.cam)
    depth = camera.depth.numpy().astype(np.float64)
    boxes = tuple(a.numpy().astype(np.float64) for a in (bins.box_axis, bins.box_lo, bins.box_hi))
    beams = _beam_arrays(stage)
    tiles = _tile_lists(bins)
    copies = 3 if stage.periodic else 1

    scattering_per_m = camera.scattering_per_m.numpy().astype(np.float64)
    numpy_out = []

    def numpy_run():
        numpy_out[:] = [numpy_volume(beams, tiles, cam_np, depth, copies, stage.extent_m, boxes,
                                     scattering_per_m, float(camera.phase.g), SCREEN_TILE_PIXELS)]

    # The shafts alone: render_beams also gathers the G-buffer points and shades, so each round
    # times it with and without the shafts and takes the difference.
    calls = calls_per_round(warp_repeats, numpy_repeats)
    times = interleaved_times({"with shafts": (lambda: camera.render_beams(stage, True), calls),
                               "without": (lambda: camera.render_beams(stage, False), calls),
                               "numpy": (numpy_run, 1)}, numpy_repeats, device)
    warp_volume_s = max(float(np.median(np.subtract(times["with shafts"], times["without"]))), 1e-9)
    numpy_s = float(np.median(times["numpy"]))
    numpy_out = numpy_out[0]
    pixels = size[0] * size[1]
    return {
        "water_n": n,
        "camera_px": list(size),
        "beams": stage.weight.shape[0],
        "fill": fill,
        "warp_s": warp_volume_s,
        "numpy_s": numpy_s,
        "speedup_warp_vs_numpy": numpy_s / warp_volume_s,
        "warp_pixels_per_s": pixels / warp_volume_s,
        "numpy_pixels_per_s": pixels / numpy_s,
        "warp_chords_per_s": fill["inside_pairs"] / warp_volume_s,
        "relative_l1_numpy_vs_warp": relative_l1(numpy_out, warp_out),
    }


def _stage_time(n: int, m: int, device: str, repeats: int) -> dict:
    """The whole beam stage on a flat floor (build, bin, clipped texel map) per frame."""
    import warp as wp

    import warpcaustics as wc

    scene = point_sun_scene(
        ROOT / "configs" / "ocean.toml",
        {
            "caustics.method": "beams",
            "water.resolution": n,
            "caustics.map_resolution": m,
            "optics.wavelengths": WAVELENGTHS,
        },
    )
    renderer = wc.Renderer(scene, device)
    renderer.render(0.0)
    surface = renderer.water.at(0.0)

    def run():
        renderer.beams.run(surface, renderer.visible)
        wp.synchronize_device(device)

    s = median_time(run, repeats)
    beams = renderer.beams.weight.shape[0]
    return {
        "water_n": n,
        "map_m": m,
        "beams": beams,
        "stage_s": s,
        "beams_per_s": beams / s,
        "texels_per_s": m * m / s,
    }


def _adaptive_rows(config: str, overrides: dict, levels: int, device: str, repeats: int) -> list[dict]:
    """Adaptive beams (caustics.beam_levels) against the uniform grid: beams, frame time and the
    floor map's relative L1 from the uniform grid's, for a range of tolerances; the coarse uniform
    grids (every quad kept at level 1, 2, …: tolerance ∞) are the baselines at equal beam counts."""
    import warpcaustics as wc

    base = {"caustics.method": "beams", "optics.wavelengths": WAVELENGTHS, "optics.water_type": "none",
            **overrides}
    rows = []
    reference = None
    cases = ([(0, 0.0)] + [(levels, t) for t in (0.05, 0.1, 0.25, 0.5, 1.0)]
             + [(lv, 1e30) for lv in range(1, levels + 1)])
    for lv, tol in cases:
        renderer = wc.Renderer(point_sun_scene(ROOT / "configs" / config, {
            **base, "caustics.beam_levels": lv, "caustics.beam_tolerance": tol}), device)
        renderer.render(0.0)  # warm-up
        s = median_time(lambda renderer=renderer: renderer.render(0.0), repeats)
        result = renderer.render(0.0)
        if reference is None:
            reference = result.floor_irradiance.astype(np.float64)
        l1 = relative_l1(reference, result.floor_irradiance)
        label = "uniform" if lv == 0 else (f"uniform x{1 << lv} cells" if tol > 1e20 else
                                           f"adaptive L={lv} tol={tol:g}")
        rows.append({"config": config, "case": label, "beam_levels": lv,
                     "beam_tolerance": None if tol > 1e20 else tol, "beams": result.beam_stats["beams"],
                     "frame_s": s, "beams_stage_s": result.timings_s["beams"], "relative_l1_vs_uniform": l1})
        print(f"beams        {config:11s} {label:24s} {rows[-1]['beams']:8d} beams | frame {s * 1e3:8.1f} ms "
              f"| L1 vs uniform {l1:.2e}", flush=True)
    return rows


def _fill_vs_depth(depths, n: int, size: tuple[int, int], device: str,
                   overrides: dict | None = None) -> list[dict]:
    """Hull / prism fill as the light focuses: ocean_floor.toml (with ``overrides``, e.g. a steeper
    sea) over a flat floor at several depths (floor caustic contrast std/mean beside it), the camera
    aimed at the floor."""
    import warpcaustics as wc

    rows = []
    for depth in depths:
        scene = point_sun_scene(ROOT / "configs" / "ocean_floor.toml", {
            "caustics.method": "beams", "water.resolution": n, "floor.shape": "flat",
            "floor.depth_m": depth,
            "camera.width": size[0], "camera.height": size[1], "caustics.shafts": False,
            "optics.wavelengths": WAVELENGTHS, "camera.position_m": [0.0, -6.0, -1.0],
            "camera.look_at_m": [0.0, 0.0, -0.6 * depth], **(overrides or {})})
        renderer = wc.Renderer(scene, device)
        result = renderer.render(0.0)
        fill = fill_measure(renderer.beams, renderer.camera, 3, samples=2000)
        floor = result.floor_irradiance[1].astype(np.float64)
        rows.append({"floor_depth_m": depth, "contrast": float(floor.std() / floor.mean()), **fill})
        print(f"beams        fill at floor depth {depth:5.1f} m (contrast {rows[-1]['contrast']:.2f}): "
              f"hull/prism {fill['hull_over_prism']:.3f} on {fill['beams_measured']} beams; fill (beam "
              f"pixels / touched) hull {fill['hull_fill']:.2f}, prism {fill['prism_fill']:.2f}", flush=True)
    return rows


def _slope(rows: list[dict], x: str, y: str) -> float:
    return float(np.polyfit(np.log([r[x] for r in rows]), np.log([r[y] for r in rows]), 1)[0])


def run(quick: bool, device: str) -> dict:
    import warp as wp

    from benchmarks.run import _cpu_name

    sizes = QUICK if quick else FULL
    warp_repeats, numpy_repeats = (2, 1) if quick else (5, 3)
    record = device_record(device)
    wp_name = record["device_name"]
    print(f"beams        warp {wp.__version__} [{device}: {wp_name}] | cpu {_cpu_name()} | numpy twins "
          "float64, same beams and tile lists", flush=True)
    gather = _gather_case(sizes["gather_n"], sizes["gather_m"], device, warp_repeats, numpy_repeats)
    g = gather
    print(f"beams        surface gather N={g['water_n']} {g['points']} points, {g['pairs']} pairs | "
          f"warp[{device}] {g['warp_points_per_s'] / 1e6:8.2f} Mpt/s ({g['warp_s'] * 1e3:8.2f} ms) | numpy "
          f"{g['numpy_points_per_s'] / 1e6:8.2f} Mpt/s ({g['numpy_s'] * 1e3:8.1f} ms) | ratio "
          f"{g['speedup_warp_vs_numpy']:6.1f}x | rel L1 {g['relative_l1_numpy_vs_warp']:.1e}", flush=True)
    volume = _volume_case(sizes["camera_n"], sizes["camera"], device, warp_repeats, numpy_repeats)
    v = volume
    print(f"beams        volume scan planes N={v['water_n']} {v['camera_px'][0]}x{v['camera_px'][1]} "
          f"{v['fill']['inside_pairs']} chords | warp[{device}] {v['warp_pixels_per_s'] / 1e3:8.1f} kpx/s "
          f"({v['warp_s'] * 1e3:8.1f} ms) | numpy {v['numpy_pixels_per_s'] / 1e3:8.1f} kpx/s "
          f"({v['numpy_s'] * 1e3:8.1f} ms) | ratio {v['speedup_warp_vs_numpy']:6.1f}x | rel L1 "
          f"{v['relative_l1_numpy_vs_warp']:.1e}", flush=True)
    fill = volume["fill"]
    print(f"beams        fill: (pixel, beam) pairs in axis-aligned boxes {fill['box_pixels']:.3g}, in tile "
          f"lists {fill['tile_pairs']:.3g}, in oriented boxes {fill['oriented_box_pairs']:.3g}, with a "
          f"chord {fill['inside_pairs']:.3g}", flush=True)
    print(f"beams        bounding volumes on {fill['beams_measured']} beams in view: tight hull "
          f"{fill['hull_pixels']:.4g} px, Ernst-style prism {fill['prism_pixels']:.4g} px, hull/prism "
          f"{fill['hull_over_prism']:.2f}; where the beams are {fill['beam_pixels']} px: fill hull "
          f"{fill['hull_fill']:.2f}, prism {fill['prism_fill']:.2f}", flush=True)
    by_n = [_stage_time(n, sizes["scaling_m"][1], device, warp_repeats) for n in sizes["scaling_n"]]
    by_m = [_stage_time(sizes["scaling_n"][1], m, device, warp_repeats) for m in sizes["scaling_m"]]
    for rows, key in ((by_n, "beams"), (by_m, "map_m")):
        slope = _slope(rows, "beams" if key == "beams" else "map_m", "stage_s")
        for r in rows:
            print(
                f"beams        stage N={r['water_n']:5d} M={r['map_m']:5d} {r['beams']:8d} beams | "
                f"{r['stage_s'] * 1e3:9.2f} ms | {r['beams_per_s'] / 1e6:7.2f} Mbeams/s",
                flush=True,
            )
        what = "beam count" if key == "beams" else "map side M"
        print(f"  log-log slope of stage time vs {what}: {slope:.2f}")
        for r in rows:
            r[f"loglog_slope_vs_{key}"] = slope
    fill_rows = _fill_vs_depth((3.0, 12.0) if quick else (3.0, 6.0, 12.0, 24.0), 32 if quick else 64,
                               (64, 48) if quick else (160, 120), device)
    adaptive = _adaptive_rows("ocean.toml", {"water.resolution": sizes["adaptive_n"],
                                             "caustics.map_resolution": sizes["adaptive_m"]}, 2, device,
                              warp_repeats)
    adaptive += _adaptive_rows("lens.toml", {} if not quick else {"caustics.map_resolution": 64}, 3, device,
                               warp_repeats)
    return {
        "adaptive_vs_uniform": adaptive,
        "fill_vs_depth": fill_rows,
        "benchmark": "beam_rasteriser",
        **record,
        "wavelengths": WAVELENGTHS,
        "warp_repeats": warp_repeats,
        "interleaved_rounds": numpy_repeats,
        "warp_calls_per_round": calls_per_round(warp_repeats, numpy_repeats),
        "timing": "median wall time after a warm-up frame, device synchronised; the gather and volume "
        "passes time Warp and numpy in turn, interleaved_rounds rounds of warp_calls_per_round Warp calls "
        "(averaged) and one numpy call (benchmarks.run.interleaved_times); the stage and adaptive rows "
        "take the median of warp_repeats; beams and tile lists built by Warp once and shared with numpy",
        "surface_gather": gather,
        "volume_scan_planes": volume,
        "stage_vs_beams": by_n,
        "stage_vs_map": by_m,
    }


def main(argv: list[str] | None = None) -> int:
    from benchmarks.run import module_main

    return module_main(argv, "beams", run, __doc__)


if __name__ == "__main__":
    sys.exit(main())
