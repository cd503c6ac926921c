"""The beams' scan-plane chord (``beam_kernels.scan_chord``) and their sample in a section
(``clamped_sample``), checked against a float64 ray–prism chord: straight (unwarped) beams, rays
across them, along them and nearly along them, and sections narrower than float32 can square."""

import numpy as np
import pytest
import warp as wp

from warpcaustics.kernels.caustics import beams as beam_kernels


@wp.kernel
def _chords(
    base: wp.array2d[wp.vec3],
    direction: wp.array2d[wp.vec3],
    end_m: wp.array2d[wp.float32],
    origins: wp.array[wp.vec3],
    rays: wp.array[wp.vec3],
    ends: wp.array2d[wp.vec3],
    out: wp.array[wp.vec2],
):
    i = wp.tid()
    beam_kernels.fill_ends(base, direction, end_m, i, ends)
    corners = beam_kernels.edge_corners(base, direction, ends, i)
    a, b = beam_kernels.scan_chord(corners, wp.vec3(0.0), origins[i], rays[i])
    out[i] = wp.vec2(a, b)


def _prism_chord(v, d, ends, o, ray):
    """float64 reference: the ray's [s_a, s_b] inside the straight prism (three side planes through
    the base edges along d, the base plane and the plane through the edge ends)."""
    return _prism_chord_planes(v, d, ends, o, ray)[:2]


def _prism_chord_planes(v, d, ends, o, ray):
    """:func:`_prism_chord` and the unit normals of the planes that set s_a and s_b (zero where
    none does)."""
    lo, hi = -np.inf, np.inf
    n_lo, n_hi = np.zeros(3), np.zeros(3)
    planes = []
    for i in range(3):
        a, b, c = v[i], v[(i + 1) % 3], v[(i + 2) % 3]
        n = np.cross(b - a, d)
        planes.append((a, n if n @ (c - a) > 0 else -n))
    nb = np.cross(v[1] - v[0], v[2] - v[0])
    planes.append((v[0], nb if nb @ d > 0 else -nb))
    e = v + ends[:, None] * d
    ne = np.cross(e[1] - e[0], e[2] - e[0])
    planes.append((e[0], -ne if ne @ d > 0 else ne))
    for p, n in planes:  # keep (x − p)·n ≥ 0
        a0, k = (o - p) @ n, ray @ n
        if abs(k) < 1e-300:
            if a0 < 0:
                return 1.0, 0.0, n_lo, n_hi
            continue
        root = -a0 / k
        if k > 0 and root > lo:
            lo, n_lo = root, n / np.linalg.norm(n)
        elif k < 0 and root < hi:
            hi, n_hi = root, n / np.linalg.norm(n)
    return lo, hi, n_lo, n_hi


PRISM_BASE = np.array([[0.0, 0.0, 0.1], [0.6, 0.1, 0.0], [0.2, 0.7, 0.05]])
PRISM_ENDS = np.array([2.0, 2.3, 1.8])
"""The straight test beams' base vertices [m] and edge lengths [m] (a tilted end plane)."""
PRISM_DIRECTION = np.array([0.2, -0.1, -1.0]) / np.linalg.norm([0.2, -0.1, -1.0])
"""The straight test prism's unit edge direction (13° from the vertical)."""


def test_scan_plane_chord_of_a_straight_prism_is_exact():
    """A straight (unwarped) beam: the scan-plane chord equals the exact ray–prism chord within
    1e-5 m for rays that cross it obliquely, along it, and that miss it."""
    rng = np.random.default_rng(5)
    v, ends, d = PRISM_BASE, PRISM_ENDS, PRISM_DIRECTION
    targets = v.mean(axis=0) + rng.uniform(-0.5, 0.5, (400, 3)) + d * rng.uniform(0.0, 2.0, (400, 1))
    origins = rng.uniform(-3.0, 3.0, (400, 3)) + np.array([0.0, 0.0, -1.0])
    rays = targets - origins
    rays /= np.linalg.norm(rays, axis=1, keepdims=True)
    # Rays along the beam: one inside the base triangle, one outside.
    origins = np.vstack([origins, v.mean(axis=0) - 3.0 * d, v[0] - 3.0 * d + np.array([-0.2, -0.2, 0.0])])
    rays = np.vstack([rays, d, d])
    got = _straight_prism_chords(v, d, ends, origins, rays)
    hits = 0
    for i in range(len(rays)):
        lo, hi = _prism_chord(v, d, ends, origins[i], rays[i])
        g_lo, g_hi = got[i]
        if hi - lo > 1e-4:
            hits += 1
            assert abs(g_lo - lo) < 1e-5 and abs(g_hi - hi) < 1e-5, (i, lo, hi, g_lo, g_hi)
        elif hi - lo < -1e-4:
            assert g_hi - g_lo < 1e-5, (i, lo, hi, g_lo, g_hi)  # a miss stays a miss
    assert hits > 50
    assert got[-2, 1] - got[-2, 0] > 1.0 and got[-1, 1] <= got[-1, 0]


def _straight_prism_chords(v, d, ends, origins, rays) -> np.ndarray:
    """(s_a, s_b) per ray from ``scan_chord`` (float32) for the straight prism of base v, edge
    direction d and edge lengths ends."""
    n = len(rays)
    out = wp.zeros(n, dtype=wp.vec2, device="cpu")
    wp.launch(
        _chords,
        dim=n,
        inputs=[
            wp.array(np.repeat(v[None], n, axis=0).astype(np.float32), dtype=wp.vec3, device="cpu"),
            wp.array(np.broadcast_to(d, (n, 3, 3)).astype(np.float32), dtype=wp.vec3, device="cpu"),
            wp.array(np.repeat(ends[None], n, axis=0).astype(np.float32), dtype=wp.float32, device="cpu"),
            wp.array(origins.astype(np.float32), dtype=wp.vec3, device="cpu"),
            wp.array(rays.astype(np.float32), dtype=wp.vec3, device="cpu"),
        ],
        outputs=[wp.zeros((n, 4), dtype=wp.vec3, device="cpu"), out],
        device="cpu",
    )
    return out.numpy().astype(np.float64)


NEAR_AXIS_BEAMS = {"13° from the vertical": tuple(PRISM_DIRECTION), "47° from the vertical": (0.7, 0.5, -0.8)}
"""Edge directions of the straight beams :func:`near_axis_chord_errors` tries (refracted sunlight
leaves the surface up to 48.6° from the vertical)."""


def near_axis_chord_errors(direction, n: int = 2000, seed: int = 11) -> np.ndarray:
    """For the rays, 1°–10° off a straight beam's axis and from 4 m before the point they aim at,
    that cross the beam: ``scan_chord``'s error at each end of the chord times |ray · n̂|, n̂ the
    normal of the prism face that sets that end, i.e. the error across that face (the larger end).
    The float64 reference (:func:`_prism_chord_planes`) gets the inputs the kernel gets, rounded
    to float32."""
    def f32(x):
        return np.asarray(x, dtype=np.float32).astype(np.float64)

    rng = np.random.default_rng(seed)
    v = f32(PRISM_BASE)
    axis = np.array(direction) / np.linalg.norm(direction)
    d = f32(axis)
    ends = f32(PRISM_ENDS)
    side = np.cross(axis, [1.0, 0.0, 0.0])
    side /= np.linalg.norm(side)
    up = np.cross(axis, side)
    angle = np.radians(rng.uniform(1.0, 10.0, n))
    turn = rng.uniform(0.0, 2.0 * np.pi, n)
    rays = f32(np.cos(angle)[:, None] * axis + np.sin(angle)[:, None] * (
        np.cos(turn)[:, None] * side + np.sin(turn)[:, None] * up))
    targets = v.mean(axis=0) + rng.uniform(-0.25, 0.25, (n, 3)) + axis * rng.uniform(0.2, 1.6, (n, 1))
    origins = f32(targets - 4.0 * rays)
    got = _straight_prism_chords(v, d, ends, origins, rays)
    across = []
    for i in range(n):
        lo, hi, n_lo, n_hi = _prism_chord_planes(v, d, ends, origins[i], rays[i])
        if hi - lo > 1e-4:
            across.append(max(abs(got[i, 0] - lo) * abs(rays[i] @ n_lo),
                              abs(got[i, 1] - hi) * abs(rays[i] @ n_hi)))
    return np.array(across)


@wp.kernel
def _tiny_section_samples(
    width_m: wp.array[wp.float32], d_out: wp.array[wp.vec3], path_out: wp.array[wp.float32]
):
    """clamped_sample on a straight prism along −z whose base is a right triangle of the given leg
    length at the origin, sampled at the section's centroid 2 m down."""
    n = wp.tid()
    w = width_m[n]
    c = beam_kernels.BeamCorners()
    c.v0 = wp.vec3(0.0, 0.0, 0.0)
    c.v1 = wp.vec3(w, 0.0, 0.0)
    c.v2 = wp.vec3(0.0, w, 0.0)
    c.d0 = wp.vec3(0.0, 0.0, -1.0)
    c.d1 = wp.vec3(0.0, 0.0, -1.0)
    c.d2 = wp.vec3(0.0, 0.0, -1.0)
    c.transmit = wp.vec3(1.0)
    c.coef = wp.vec3(0.5 * w * w, 0.0, 0.0)
    c.end_point = wp.vec3(0.0, 0.0, -10.0)
    c.end_normal = wp.vec3(0.0, 0.0, -1.0)
    c.inv_dz = wp.vec3(-1.0)
    s = beam_kernels.clamped_sample(c, wp.vec3(w / 3.0, w / 3.0, -2.0))
    d_out[n] = s.d
    path_out[n] = s.path_m


def test_clamped_sample_stays_finite_in_a_section_narrower_than_float32_can_square():
    """A sample's direction comes from the unnormalised barycentrics, whose sum is the section's
    doubled area: for sections down to 1e-30 m wide it still comes out the unit edge direction
    and the path the 2 m down (a 1e-12 m section once gave an infinite direction, |d|² ~ 1e-48
    underflowing to 0)."""
    widths = np.array([1.0, 1e-3, 1e-6, 1e-9, 1e-12, 1e-20, 1e-30], np.float32)
    d = wp.zeros(len(widths), dtype=wp.vec3, device="cpu")
    path = wp.zeros(len(widths), dtype=wp.float32, device="cpu")
    wp.launch(_tiny_section_samples, dim=len(widths), inputs=[wp.array(widths, device="cpu")],
              outputs=[d, path], device="cpu")
    np.testing.assert_allclose(d.numpy(), np.tile([0.0, 0.0, -1.0], (len(widths), 1)), atol=1e-7)
    np.testing.assert_allclose(path.numpy(), 2.0, rtol=1e-7)


@pytest.mark.parametrize("beam", NEAR_AXIS_BEAMS)
def test_scan_plane_chord_stays_exact_for_rays_nearly_along_the_beam(beam):
    """Rays 1°–10° off a straight beam's axis: the scan plane, and the line across the ray in it
    that the chord's ends are measured from, must stay on the ray. Such a chord is ill-conditioned
    (a chord end moves by an error across the face that sets it divided by the sine of the ray's
    angle to that face), so the test bounds the error across the face, by 4 float32 ulps of the
    coordinates, about 4 m (4 × 4.8e-7 m). A plane normal formed as d̄ − (v·d̄) v put these 1.5e-5
    and 2.6e-5 m off (chord ends up to 1.4 mm off), ends measured along v × d̄ itself (not
    perpendicular to the ray to rounding) 3.1e-6 m on the tilted beam; the kernels give 9.2e-7 and
    6.7e-7 m, as the plane before its per-copy frame did."""
    across = near_axis_chord_errors(NEAR_AXIS_BEAMS[beam])
    assert len(across) > 500
    assert across.max() < 4 * 4.8e-7, across.max()
