"""Refraction and Fresnel kernels against float64 references, grazing angles and TIR included."""

import numpy as np
import pytest
import warp as wp

from warpcaustics.kernels import geometry

from helpers import SHARED_WATER_DATA, fresnel_t_angles


@wp.kernel
def _refract_many(d: wp.array[wp.vec3], n: wp.array[wp.vec3], eta: float,
                  t_out: wp.array[wp.vec3], tr_out: wp.array[wp.float32]):
    i = wp.tid()
    t_out[i] = geometry.refract(d[i], n[i], eta)
    tr_out[i] = geometry.fresnel_transmittance(-wp.dot(n[i], d[i]), eta)


def _run(d, n, eta, device):
    t = wp.empty(len(d), dtype=wp.vec3, device=device)
    tr = wp.empty(len(d), dtype=wp.float32, device=device)
    wp.launch(_refract_many, dim=len(d),
              inputs=[wp.array(d.astype(np.float32), dtype=wp.vec3, device=device),
                      wp.array(n.astype(np.float32), dtype=wp.vec3, device=device), eta],
              outputs=[t, tr], device=device)
    return t.numpy().astype(np.float64), tr.numpy().astype(np.float64)


def _rays(theta, phi):
    """Unit directions travelling down (−z) at incidence angle θ onto the normal +z."""
    return np.stack([np.sin(theta) * np.cos(phi), np.sin(theta) * np.sin(phi), -np.cos(theta)], axis=1)


@pytest.mark.parametrize(("n1", "n2"), [(1.0, 1.333), (1.0, 1.5), (1.333, 1.0)])
def test_snell_and_fresnel_match_float64(device, n1, n2, rng):
    """Refracted angle obeys n1 sinθi = n2 sinθt in the plane of incidence; T matches Fresnel's equations."""
    theta = np.concatenate([[0.0, 1e-4], np.radians([10, 30, 45, 60, 80, 89, 89.9]),
                            rng.uniform(0, np.pi / 2 - 1e-3, 64)])
    phi = rng.uniform(0, 2 * np.pi, len(theta))
    d = _rays(theta, phi)
    normal = np.tile([0.0, 0.0, 1.0], (len(theta), 1))
    t, tr = _run(d, normal, n1 / n2, device)

    sin_t = n1 / n2 * np.sin(theta)
    ok = sin_t < 1.0
    expected_t = _rays(np.arcsin(np.minimum(sin_t, 1.0)), phi)
    # float32 kernel vs float64 reference: a few ulp on unit vectors.
    np.testing.assert_allclose(t[ok], expected_t[ok], atol=2e-6)
    np.testing.assert_allclose(tr, fresnel_t_angles(theta, n1, n2), atol=3e-6)
    # Beyond the critical angle: total internal reflection, no ray and no transmission.
    assert np.all(t[~ok] == 0.0) and np.all(tr[~ok] == 0.0)
    if n1 > n2:
        assert (~ok).sum() > 10, "the TIR branch must be exercised"


def test_refraction_with_tilted_normals(device, rng):
    """Vector Snell on random tilted normals: tangential n·sin conserved, t unit, coplanar with d and n."""
    count = 256
    n = rng.normal(size=(count, 3))
    n[:, 2] = np.abs(n[:, 2]) + 1.0
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    d = rng.normal(size=(count, 3))
    d[:, 2] = -np.abs(d[:, 2]) - 0.5
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    front = np.sum(n * d, axis=1) < 0
    n, d = n[front], d[front]
    t, tr = _run(d, n, 1.0 / 1.333, device)
    sin_i = np.linalg.norm(np.cross(d, n), axis=1)
    sin_t = np.linalg.norm(np.cross(t, n), axis=1)
    np.testing.assert_allclose(1.0 * sin_i, 1.333 * sin_t, atol=3e-6)
    np.testing.assert_allclose(np.linalg.norm(t, axis=1), 1.0, atol=2e-6)
    np.testing.assert_allclose(np.einsum("ij,ij->i", np.cross(d, n), t), 0.0, atol=3e-6)
    np.testing.assert_allclose(tr, fresnel_t_angles(np.arcsin(np.clip(sin_i, 0, 1)), 1.0, 1.333),
                               atol=3e-6)


def test_light_from_behind_transmits_nothing(device):
    """A vertex whose normal faces away from the sun (n·s <= 0) transmits no flux."""
    d = np.array([[0.0, 0.6, -0.8]])
    n = np.array([[0.0, 1.0, 0.0]])  # n·d > 0: the ray arrives from behind the surface
    _, tr = _run(d, n, 1.0 / 1.333, device)
    assert tr[0] == 0.0


def test_dispersion_follows_quan_fry(device):
    """With dispersion, the refraction angle at 450 and 650 nm matches Snell with Quan & Fry's n(λ)
    to 1e-6 rad; n(λ) itself equals the shared data's tabulated Quan–Fry values (20 °C, 35 ‰)."""
    import csv

    from warpcaustics.optics import spectra
    from warpcaustics.optics.refraction import refract_to_floor
    from warpcaustics.water import HeightfieldWater

    table = SHARED_WATER_DATA / "n_water_quan_fry_1995_computed.csv"
    if not table.exists():  # the shared data sit beside the checkout in CI and development
        pytest.skip("shared/data not beside this checkout")
    rows = {float(r["wavelength_nm"]): float(r["n_rel_air_T20_S35"]) for r in csv.DictReader(table.open())}
    n = spectra.quan_fry_index(np.array([450.0, 650.0]), 35.0, 20.0)
    np.testing.assert_allclose(n, [rows[450.0], rows[650.0]], atol=1e-6)  # the table has 6 decimals

    surface = HeightfieldWater(np.zeros((8, 8)), 4.0, device).at(0.0)
    elevation = np.radians(35.0)
    sun = np.array([np.cos(elevation), 0.0, np.sin(elevation)])
    visible = wp.full((8, 8), 1.0, dtype=wp.float32, device=device)
    depth = 10.0
    hits = refract_to_floor(surface, visible, n, sun, -depth, device).hit_xy.numpy()
    start = surface.positions.numpy()[0, 0, :2]
    offset = np.linalg.norm(hits[:, 0, 0].astype(np.float64) - start, axis=1)
    theta_t = np.arctan2(offset, depth)
    expected = np.arcsin(np.cos(elevation) / n)  # sin θi = cos(elevation), n_air = 1
    np.testing.assert_allclose(theta_t, expected, atol=1e-6)
    assert theta_t[0] < theta_t[1] - 1e-3  # blue bends more than red
