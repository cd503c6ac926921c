"""Liktor & Dachsbacher 2011 §4.3's bounding volumes (``caustics.beam_bounds``): each holds its
beam, the prism matches the benchmark's float64 construction, and the three give the same shafts."""

import sys
from pathlib import Path

import numpy as np
import pytest
import warp as wp

import warpcaustics as wc
from warpcaustics.kernels.caustics.beams import bounds

from helpers import CONFIGS

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from benchmarks.beam_fill import prism_ends  # noqa: E402  (float64, written apart from the kernel)

KINDS = {"hull": bounds.HULL, "prism": bounds.PRISM, "ernst": bounds.ERNST}


@wp.kernel
def _corners(
    base: wp.array2d[wp.vec3],
    direction: wp.array2d[wp.vec3],
    end_m: wp.array2d[wp.float32],
    kind: int,
    lower: wp.array2d[wp.vec3],
    upper: wp.array2d[wp.vec3],
    used: wp.array[wp.int32],
):
    b = wp.tid()
    lo, up, ok = bounds.bound_corners(base, direction, end_m, b, wp.vec3(0.0), kind)
    for i in range(3):
        lower[b, i] = lo[i]
        upper[b, i] = up[i]
    used[b] = ok


def _beams(count: int, spread: float, seed: int = 3):
    """Random beams under a surface: base triangles of ~10 cm, directions about straight down whose
    tilts (up to ``spread``) make some beams diverge, some focus and some flip over."""
    rng = np.random.default_rng(seed)
    centre = rng.uniform(-1, 1, (count, 1, 3)) * [1, 1, 0.02]
    base = centre + rng.normal(0, 0.05, (count, 3, 3)) * [1, 1, 0.1]
    d = np.array([0.0, 0.0, -1.0]) + rng.normal(0, spread, (count, 3, 3)) * [1, 1, 0]
    d /= np.linalg.norm(d, axis=-1, keepdims=True)
    ends = rng.uniform(1.0, 3.0, (count, 1)) + rng.uniform(-0.2, 0.2, (count, 3))
    return base, d, ends


def _run(base, d, ends, kind):
    n = len(base)
    lower = wp.empty((n, 3), dtype=wp.vec3, device="cpu")
    upper = wp.empty((n, 3), dtype=wp.vec3, device="cpu")
    used = wp.empty(n, dtype=wp.int32, device="cpu")
    wp.launch(_corners, dim=n, inputs=[wp.array(base, dtype=wp.vec3), wp.array(d, dtype=wp.vec3),
                                       wp.array(ends, dtype=wp.float32), kind],
              outputs=[lower, upper, used], device="cpu")
    return lower.numpy().astype(np.float64), upper.numpy().astype(np.float64), used.numpy()


def _beam_points(base, d, ends, samples: int = 200, seed: int = 5):
    """(B, S, 3) points of each beam (float64): a bilinear mix of its edge lines at random heights
    and barycentric weights, the corners included."""
    rng = np.random.default_rng(seed)
    w = rng.dirichlet([0.3, 0.3, 0.3], (len(base), samples))
    t = rng.uniform(0, 1, (len(base), samples, 1))
    w[:, :3] = np.eye(3)  # corners and ends: the extreme points
    t[:, :3], t[:, 3:6] = 0.0, 1.0
    w[:, 3:6] = np.eye(3)
    edge = base[:, None] + t[..., None] * (ends[:, None, :, None] * d[:, None])  # (B, S, 3, 3)
    return (w[..., None] * edge).sum(axis=2)


@pytest.mark.parametrize("kind", ["prism", "ernst"])
def test_prisms_hold_their_beams(kind):
    """Every point of a beam (its corners, ends and points of its warped sides) lies inside the
    volume the kernel builds: on the inner side of each side plane (through a base edge and its
    corner line's top) and below the cap. Beams whose prism is unbounded fall back to the hull."""
    base, d, ends = _beams(400, 0.15)
    lower, upper, used = _run(base, d, ends, KINDS[kind])
    assert 0.5 < used.mean() < 1.0  # most beams get a prism; the flipped ones fall back
    fell = used == 0
    np.testing.assert_allclose(upper[fell], base[fell] + ends[fell][..., None] * d[fell], atol=1e-6)
    ok = ~fell
    pts = _beam_points(base, d, ends)[ok]
    lo, up = lower[ok], upper[ok]
    scale = np.linalg.norm(up - lo, axis=-1).max(axis=1)[:, None]
    for i in range(3):
        j, k = (i + 1) % 3, (i + 2) % 3
        n = np.cross(lo[:, j] - lo[:, i], up[:, i] - lo[:, i])
        n *= np.sign(((lo[:, k] - lo[:, i]) * n).sum(-1))[:, None]
        n /= np.linalg.norm(n, axis=-1, keepdims=True)
        # the side is a plane: the neighbouring corner line's top lies on it
        assert np.abs(((up[:, j] - lo[:, i]) * n).sum(-1) / scale[:, 0]).max() < 1e-4
        side = ((pts - lo[:, i, None]) * n[:, None]).sum(-1)
        assert (side / scale).min() > -1e-4
    cap = np.cross(up[:, 1] - up[:, 0], up[:, 2] - up[:, 0])
    cap *= np.sign((cap * d.sum(axis=1)[ok]).sum(-1))[:, None]
    cap /= np.linalg.norm(cap, axis=-1, keepdims=True)
    assert (((pts - up[:, 0, None]) * cap[:, None]).sum(-1) / scale).max() < 1e-4
    if kind == "ernst":  # capped parallel to the base, at the farthest end
        nb = np.cross(lo[:, 1] - lo[:, 0], lo[:, 2] - lo[:, 0])
        nb /= np.linalg.norm(nb, axis=-1, keepdims=True)
        assert np.abs(np.abs((cap * nb).sum(-1)) - 1).max() < 1e-4


def test_prism_matches_the_float64_construction():
    """``prism``'s corners are the benchmark's float64 touching-plane prism (benchmarks/beams.py,
    written apart from the kernel), and the kernel keeps exactly the beams whose float64 prism is
    bounded in front of its base (every corner line meeting the cap beyond its base vertex)."""
    base, d, ends = _beams(400, 0.05)
    lower, upper, used = _run(base, d, ends, bounds.PRISM)
    ref = prism_ends(base, d, ends)
    finite = np.all(np.isfinite(ref), axis=(1, 2))
    ahead = np.all(((np.nan_to_num(ref) - base) * d.sum(axis=1)[:, None]).sum(-1) > 0, axis=1)
    np.testing.assert_array_equal(used == 1, finite & ahead)
    ok = used == 1
    assert 0.5 < ok.mean() < 1.0  # both kinds of beam are in the sample
    size = np.linalg.norm(ref - base, axis=-1)
    err = np.linalg.norm(upper - ref, axis=-1)[ok] / size[ok]
    # float32 rounding, amplified where a corner line meets the cap at a glancing angle
    assert np.quantile(err, 0.99) < 1e-5 and err.max() < 1e-3
    np.testing.assert_array_equal(lower, base.astype(np.float32))


def test_hull_is_the_beams_own_corners():
    base, d, ends = _beams(50, 0.15)
    lower, upper, used = _run(base, d, ends, bounds.HULL)
    assert used.all()
    np.testing.assert_allclose(upper, base + ends[..., None] * d, atol=1e-6)


@pytest.mark.parametrize(
    ("config", "overrides"),
    [
        (CONFIGS / "ocean_floor.toml", {"water.resolution": 32}),
        (CONFIGS / "pool.toml", {"water.resolution": 32, "camera.enabled": True,
                                 "camera.position_m": [-1.5, -1.5, -0.6],
                                 "camera.look_at_m": [1.0, 0.5, -1.4],
                                 "optics.water_type": "coastal_ocean"}),
    ],
    ids=["periodic-sea", "walled-pool"],
)
def test_every_volume_gives_the_same_shafts(config, overrides):
    """The volume only chooses which pixels are tested; the scan-plane chords are exact, so the
    three give the same shafts to the bit and the same chords, from at least the hull's boxes."""
    shafts, fills = {}, {}
    for kind in KINDS:
        scene = wc.load_scene(config, {"caustics.method": "beams", **overrides, "caustics.shafts": True,
                                       "optics.wavelengths": "rgb", "camera.width": 60, "camera.height": 44,
                                       "caustics.map_resolution": 32, "caustics.beam_bounds": kind})
        renderer = wc.Renderer(scene, "cpu")
        renderer.render(0.0)
        shafts[kind] = renderer.method.camera.shafts.numpy().copy()
        fills[kind] = renderer.method.camera.beam_fill()
    assert (shafts["hull"] > 0).mean() > 0.3
    for kind in ("prism", "ernst"):
        np.testing.assert_array_equal(shafts[kind], shafts["hull"])
        assert fills[kind]["inside_pairs"] == fills["hull"]["inside_pairs"]
        assert fills[kind]["box_pixels"] >= fills["hull"]["box_pixels"]
        assert fills[kind]["oriented_box_pairs"] >= fills["hull"]["oriented_box_pairs"]
