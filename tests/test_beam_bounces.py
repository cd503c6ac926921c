"""Beams through glass receivers and off mirrors (``caustics.bounces`` with ``caustics.method =
"beams"``, Liktor & Dachsbacher 2011 §6): a flat glass slab's floor map against its analytic
texel averages (the lateral shift, the Fresnel losses), the bounced beams' edges against Snell's
law, and beams against photons on the same scenes."""

import math

import numpy as np
import pytest

import warpcaustics as wc
from warpcaustics.reference import relative_l1

from helpers import fresnel_t_angles

N_WATER = 1.333
N_GLASS = 1.5
HALF = 1.8
"""The slab's half width [m] (a 3.6 m square)."""
TOP, BOTTOM, DEPTH = 0.55, 1.05, 2.0
"""Depths of the slab's top and bottom faces and of the floor [m]."""
SLAB = {"mesh": "cube", "scale": [2 * HALF, 2 * HALF, BOTTOM - TOP],
        "translate_m": [0.0, 0.0, -0.5 * (TOP + BOTTOM)], "ior": N_GLASS}


def _still_sea(method, receivers, bounces, **extra):
    """A periodic still sea 8 m across, sun 30° high at azimuth 0 (the light runs along −x),
    a point sun, no absorption, 64² map."""
    return wc.load_scene(None, {
        "caustics.method": method, "water.model": "flat", "water.extent_m": 8.0, "water.resolution": 32,
        "caustics.map_resolution": 64, "floor.depth_m": DEPTH, "optics.ior": N_WATER,
        "optics.water_type": "none", "optics.wavelengths": "rgb", "sun.elevation_deg": 30.0,
        "sun.azimuth_deg": 0.0, "sun.angular_diameter_deg": 0.0, "caustics.bounces": bounces,
        "receivers": receivers, **extra})


def _angles():
    """tan θ_w, tan θ_g of the light in water and in glass, and T_wg(θ_w) T_gw(θ_g) (float64)."""
    sin_air = math.sin(math.radians(60.0))
    theta_w, theta_g = math.asin(sin_air / N_WATER), math.asin(sin_air / N_GLASS)
    t = (fresnel_t_angles(np.array([theta_w]), N_WATER, N_GLASS)[0]
         * fresnel_t_angles(np.array([theta_g]), N_GLASS, N_WATER)[0])
    return math.tan(theta_w), math.tan(theta_g), t


def _overlap(lo, hi, a, b):
    """Length of [lo, hi] ∩ [a, b], elementwise."""
    return np.clip(np.minimum(hi, b) - np.maximum(lo, a), 0.0, None)


def test_a_glass_slab_gives_the_analytic_floor_map(device):
    """Still water, the light at θ_w in the water and θ_g in the glass. Followed up from a floor
    point x (heights above the floor h), the straight light is blocked where x + h tan θ_w meets the
    slab; the light through its top and bottom faces reaches x ∈ (−a − h_b tan θ_w,
    a − h_b tan θ_w − t tan θ_g) with T_wg T_gw of the flat-water irradiance E0 — the light patch is
    moved by t (tan θ_w − tan θ_g) against a straight shadow, with dark margins t tan θ_w and
    t tan θ_g on its two sides. Each texel's average of that (float64, exact 1-D overlaps) against
    the beams' map, on rows well inside the slab's width, away from where the light through the
    slab's side faces lands: texels a beam width clear of every edge to 1e-4; all of them in
    relative L1 within what the sub-beams still across the edges lose (3 %)."""
    flat = wc.render(_still_sea("beams", [], 1), device=device)
    result = wc.render(_still_sea("beams", [SLAB], 2), device=device)
    e0 = flat.floor_irradiance[:, 32, 32].astype(np.float64)
    uniform = np.broadcast_to(e0[:, None, None], flat.floor_irradiance.shape)
    np.testing.assert_allclose(flat.floor_irradiance, uniform, rtol=1e-5)
    tw, tg, t_slab = _angles()
    h_top, h_bottom = DEPTH - TOP, DEPTH - BOTTOM
    blocked = (-HALF - h_top * tw, HALF - h_bottom * tw)
    through = (-HALF - h_bottom * tw, HALF - h_bottom * tw - (BOTTOM - TOP) * tg)
    texel = 8.0 / 64
    x0 = np.arange(64) * texel - 4.0
    x1 = x0 + texel
    direct = 1.0 - _overlap(x0, x1, *blocked) / texel
    passed = _overlap(x0, x1, *through) / texel
    expected = e0[:, None] * (direct + t_slab * passed)[None, :]
    # Light through the slab's side faces is left out of the columns: entering the sunward face
    # (47.5° from the vertical in the glass, 56.1° in the water after the bottom) it lands at
    # x ≈ −0.16 … 0.39; leaving the far face from inside (23.3° from the vertical) at −2.43 … −2.21.
    columns = (((x0 > -3.6) & (x1 < -2.5)) | ((x0 > -2.15) & (x1 < -0.3)) | ((x0 > 0.45) & (x1 < 2.5)))
    rows = slice(int((4.0 - 1.4) / texel), int((4.0 + 1.4) / texel))
    got = result.floor_irradiance[:, rows][:, :, columns].astype(np.float64)
    want = np.broadcast_to(expected[:, None, columns], got.shape)
    beam = 8.0 / 32
    edges = np.array([*blocked, *through])
    clear = np.all((x0[columns, None] - edges > beam) | (edges - x1[columns, None] > beam), axis=1)
    assert clear.sum() >= 20 and (passed[columns][clear] == 1.0).sum() >= 10
    np.testing.assert_allclose(got[..., clear], want[..., clear], rtol=1e-4)
    assert relative_l1(want, got) < 0.03
    assert 0.98 < t_slab < 1.0


def test_bounced_beam_edges_follow_snell(device):
    """The bounced beams' edges, each followed to the floor, land t (tan θ_w − tan θ_g) further
    back along the light than the same edge would without the slab (float64 Snell here), and their
    transmittances are the edge's own times T_wg T_gw."""
    renderer = wc.Renderer(_still_sea("beams", [SLAB], 2), device)
    renderer.render(0.0)
    stage = renderer.method.caustics[0]
    tw, tg, t_slab = _angles()
    first = stage.primary_slots
    used = stage.bounces.used
    w = stage.weight.numpy()[first:first + used]
    source = stage.bounces.source.numpy()[:used]
    whole = stage.bounces.need.numpy()[source] == 1  # whole beams: their edges are the primary's
    keep = (w > 0) & whole
    filled = slice(0, first + used)  # the slots past the bounced beams of this pass are never written
    base = stage.base.numpy()[filled].astype(np.float64)
    direction = stage.direction.numpy()[filled].astype(np.float64)
    b2 = base[first:first + used][keep]
    d2 = direction[first:first + used][keep]
    b1, d1 = base[source[keep]], direction[source[keep]]
    land2 = b2 + ((-DEPTH - b2[..., 2]) / d2[..., 2])[..., None] * d2
    land1 = b1 + ((-DEPTH - b1[..., 2]) / d1[..., 2])[..., None] * d1
    inside = np.all(np.abs(land1[..., 0] + 1.0) < 1.2, axis=1) & np.all(np.abs(land1[..., 1]) < 1.4, axis=1)
    assert inside.sum() > 100
    shift = (BOTTOM - TOP) * (tw - tg)
    moved = (land2 - land1)[inside]
    np.testing.assert_allclose(moved[..., 0], shift, atol=2e-5)
    np.testing.assert_allclose(moved[..., 1:], 0.0, atol=2e-5)
    transmit = stage.transmit.numpy()
    ratio = transmit[first:first + used][keep][inside] / transmit[source[keep]][inside]
    np.testing.assert_allclose(ratio, t_slab, rtol=1e-5)


@pytest.mark.parametrize(("receiver", "elevation"), [
    (SLAB, 30.0),
    ({"mesh": "sphere", "scale": 0.6, "translate_m": [0.0, 0.0, -0.8], "ior": N_GLASS}, 65.0),
], ids=["slab", "glass-sphere"])
def test_beams_agree_with_photons_through_glass(receiver, elevation):
    """A walled pool 0.6 s after a 4 cm drop (32² surface, 64² map, no absorption), glass in it: the
    beams' floor map against the exact photons' (16×16 per cell, footprint splats; another method):
    relative L1 1.1 % (slab) and 1.0 % (ball), where the photons at 8×8 and 16×16 differ by
    0.65 % / 0.46 %; the floor's flux 0.6 % / 0.2 % under the photons', the light the sub-beams
    still across the objects' edges lose."""
    scene = wc.load_scene(None, {
        "caustics.method": "both", "water.model": "pool", "water.extent_m": 4.0, "water.resolution": 32,
        "floor.depth_m": DEPTH, "optics.ior": N_WATER, "optics.water_type": "none",
        "optics.wavelengths": "rgb", "sun.elevation_deg": elevation, "sun.azimuth_deg": 0.0,
        "sun.angular_diameter_deg": 0.0,
        "caustics.photon_subdivisions": 16, "caustics.map_resolution": 64, "caustics.bounces": 2,
        "receivers": [receiver],
        "water.drops": [{"time_s": 0.0, "x_m": 0.5, "y_m": -0.3, "radius_m": 0.15, "height_m": 0.04}]})
    beams = wc.render(scene, 0.6, device="cpu")  # caustics.method = "both": the photons' as its comparison
    photons = beams.comparison
    assert beams.beam_stats["bounced"] > 100
    assert relative_l1(photons.floor_irradiance, beams.floor_irradiance) < 0.015
    lost = 1.0 - beams.floor_flux_w_nm / photons.floor_flux_w_nm
    limit = 0.008 if receiver["mesh"] == "cube" else 0.003
    assert np.all((lost > 0.0) & (lost < limit))
