"""The beams' bounding volumes measured in float64, apart from the kernels: Ernst's touching-plane
prisms (Liktor & Dachsbacher 2011 §4.3) and how much of each volume's screen area a beam fills.

Used by ``benchmarks/beams.py`` (the volume pass with each of ``caustics.beam_bounds``'s volumes),
``benchmarks/previews.py`` and ``tests/test_beam_bounds.py`` (the kernel's prisms against
:func:`prism_ends`).
"""

from __future__ import annotations

import numpy as np

from warpcaustics.reference.beams import CHUNK_PAIRS, camera_dict, pixel_rays, scan_chords


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


def prism_ends(v: np.ndarray, d: np.ndarray, ends: np.ndarray, cap: str = "ends") -> np.ndarray:
    """(B, 3, 3) end vertices of a bounding prism of each beam by Ernst's touching planes (Liktor &
    Dachsbacher 2011 §4.3): each side is the plane through a base edge tilted just enough to hold
    all three end points; neighbouring sides meet in a line through the shared base vertex, cut by
    the cap: ``"ends"``, the plane of the three edge ends (``caustics.beam_bounds = "prism"``), or
    ``"parallel"``, the plane parallel to the base through the farthest end (``"ernst"``). NaN
    where a side plane does not exist or a corner line does not meet the cap ahead of its base
    vertex (the kernel, kernels/caustics/beams/bounds.py, takes the hull there)."""
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
    if cap == "ends":
        e0 = e.mean(axis=1)
        ne = np.cross(e[:, 1] - e[:, 0], e[:, 2] - e[:, 0])
    else:
        ne = np.cross(v[:, 1] - v[:, 0], v[:, 2] - v[:, 0])
        ne *= np.where((ne * dbar).sum(-1) < 0, -1.0, 1.0)[:, None]
        far = ((e - v[:, :1]) * ne[:, None]).sum(-1).max(axis=1)
        e0 = v[:, 0] + ne * (far / (ne * ne).sum(-1))[:, None]
    out = np.empty_like(v)
    for i in range(3):
        line = np.cross(normals[(i + 2) % 3], normals[i])  # sides (k, i) and (i, j) meet at v_i
        line *= np.where((line * dbar).sum(-1) < 0, -1.0, 1.0)[:, None]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = ((e0 - v[:, i]) * ne).sum(-1) / (line * ne).sum(-1)
        t = np.where(t > 0, t, np.nan)
        out[:, i] = v[:, i] + t[:, None] * line
    return out


VOLUMES = ("hull", "prism", "ernst")
"""``caustics.beam_bounds``'s volumes, compared by :func:`fill_measure` and :func:`_bounds_case`."""


def fill_measure(stage, camera, copies: int, samples: int, seed: int = 1) -> dict:
    """Pixels a rasteriser would touch for the beams' bounding volumes, on a sample of the beam copies
    wholly in front of the camera: the tight hull (convex hull of base and end vertices) and the two
    touching-plane prisms (:func:`prism_ends`; a beam whose prism does not exist takes the hull, as
    in the kernel), each projected and clipped to the frame; and the pixels where the beam really
    is, whose centre ray has a scan-plane chord through it in front of the camera
    (:func:`scan_chords`, float64; receivers not considered). ``<volume>_fill``: beam pixels over
    the volume's."""
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
    tips = vb + ends[b][..., None] * d[b]
    corners = {"hull": tips}
    fallbacks = {}
    for kind, cap in (("prism", "ends"), ("ernst", "parallel")):
        top = prism_ends(vb, d[b], ends[b], cap)
        missing = ~np.all(np.isfinite(top), axis=(1, 2))
        corners[kind] = np.where(missing[:, None, None], tips, top)
        fallbacks[kind] = missing

    def project(x):
        rel = x - pos
        z = rel @ fwd
        px = (rel @ right / (z * cam.tan_half_fov * cam.aspect) + 1.0) * 0.5 * w
        py = (1.0 - rel @ up / (z * cam.tan_half_fov)) * 0.5 * h
        return np.stack([px, py], -1), z

    projected = {kind: project(np.concatenate([vb, top], axis=1)) for kind, top in corners.items()}
    good = np.ones(len(vb), bool)
    for pts, z in projected.values():
        good &= np.all(z > 1e-3, axis=1) & np.all(np.isfinite(pts), axis=(1, 2))
    touched = dict.fromkeys(VOLUMES, 0.0)
    used = []
    for i in np.flatnonzero(good):
        areas = {kind: _convex_area_on_screen(projected[kind][0][i], w, h) for kind in VOLUMES}
        if max(areas.values()) <= 0.0:
            continue
        for kind in VOLUMES:
            touched[kind] += areas[kind]
        used.append(i)
        if len(used) >= samples:
            break
    # Where the beams are: every pixel of each hull's screen box, tested by its centre ray.
    used = np.array(used, np.int64)
    hp = projected["hull"][0]
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
    out = {"beams_measured": len(used), "beam_pixels": inside}
    for kind in VOLUMES:
        out[f"{kind}_pixels"] = touched[kind]
        out[f"{kind}_fill"] = inside / max(touched[kind], 1e-300)
    for kind, missing in fallbacks.items():
        out[f"{kind}_hull_fallback_fraction"] = float(missing[used].mean()) if len(used) else 0.0
    out["hull_over_prism"] = touched["hull"] / max(touched["prism"], 1e-300)
    out["hull_over_ernst"] = touched["hull"] / max(touched["ernst"], 1e-300)
    return out
