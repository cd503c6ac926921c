"""Photon footprint splats (``caustics.photon_splat = "footprint"``): still water at any photon
density, the flux kept, the exact answer of a sinusoid's facets, and closer to the exact beams than
texel photons on the floor and on a sphere."""

import numpy as np
import pytest

import warpcaustics as wc
from warpcaustics.reference import relative_l1

from helpers import CONFIGS, flat_floor_irradiance, flat_water_scene, fresnel_t_angles


@pytest.mark.parametrize(("subdivisions", "map_m"), [(3, 50), (2, 97), (5, 64), (7, 81), (1, 33)])
def test_still_water_is_analytic_in_every_texel_at_any_density(subdivisions, map_m, device):
    """A periodic still sea, sun 40° high, 3 m deep: every texel reads E_sun cosθ T(θ) e^{−cD/cosθ_t}
    whether or not a texel holds a whole number of photon spacings (the cells of a regular lattice
    tile the floor; exact clipping spreads each over the texels it covers; on a flat floor the cells
    are placed in float64). float32 fluxes and sums: 1e-6 (measured 4.9e-7 … 8.0e-7). Texel photons
    at the same densities are off by 70–130 % (the histogram's aliasing)."""
    scene = flat_water_scene(40.0, 3.0, "pure", **{
        "caustics.method": "photons", "caustics.photon_subdivisions": subdivisions,
        "caustics.map_resolution": map_m, "water.resolution": 32})
    result = wc.render(scene, device=device)
    expected = flat_floor_irradiance(result, 40.0, 3.0)
    uniform = np.broadcast_to(expected[:, None, None], result.floor_irradiance.shape)
    np.testing.assert_allclose(result.floor_irradiance, uniform, rtol=1e-6)


@pytest.mark.parametrize(("elevation", "subdivisions", "map_m"),
                         [(20.0, 5, 64), (45.0, 4, 64), (75.0, 2, 97)])
def test_still_pool_is_analytic_inside_its_walls(elevation, subdivisions, map_m, device):
    """The same in a walled pool (8 m, 3 m deep): every lit texel reads the analytic irradiance to
    1e-6 but those next to the walls' shadow (whose edge is not analytic), including the rows
    along the two walls the light runs towards. There a floor photon's cell that reaches past the
    map's edge gives its outside part to the wall its lattice neighbour landed on (20°: the row read
    +13 … +29 % when such photons kept the texel deposit), and a wall photon's cell that reaches
    below the floor gives that part, continued along the rays to the floor, to the floor (45°, 75°:
    −0.6 %, −21 … −46 % before). The surface quads at the walls are half cells, so their photons'
    strata are half as wide: a cell spanned by the step across that seam is scaled to its own stratum
    (``stratum_ratio``; the band where that light lands read 0.6 % off at 45° before)."""
    scene = flat_water_scene(elevation, 3.0, "pure", **{
        "caustics.method": "photons", "caustics.photon_subdivisions": subdivisions,
        "caustics.map_resolution": map_m, "water.resolution": 32, "water.model": "pool"})
    result = wc.render(scene, device=device)
    ratio = result.floor_irradiance / flat_floor_irradiance(result, elevation, 3.0)[:, None, None]
    dark = np.pad(ratio[0] < 0.5, 1, constant_values=False)
    near_dark = dark[1:-1, 1:-1] | dark[:-2, 1:-1] | dark[2:, 1:-1] | dark[1:-1, :-2] | dark[1:-1, 2:]
    lit = ~near_dark
    assert lit.sum() > 0.4 * map_m**2
    assert lit[0, :].sum() > map_m // 3 and lit[:, 0].sum() > map_m // 3  # the lee rows are lit, and checked
    np.testing.assert_allclose(ratio[:, lit], 1.0, rtol=0, atol=1e-6)


def test_footprints_keep_the_flux_on_a_rough_ocean(device):
    """No absorption, a rough FFT ocean (focusing, folds at the crests): the floor map's flux equals
    the flux that entered the water to 1e-6 (float32 fluxes and texels summed in float64; measured
    3.5e-7)."""
    scene = wc.load_scene(CONFIGS / "ocean.toml", {
        "caustics.method": "photons", "water.resolution": 64, "caustics.map_resolution": 64,
        "optics.water_type": "none", "optics.wavelengths": "rgb", "water.wind_speed_m_s": 8.0,
        "floor.depth_m": 6.0})
    result = wc.render(scene, device=device)
    assert result.photon_stats["landed"] == result.photon_stats["carrying"]
    np.testing.assert_allclose(result.floor_flux_w_nm, result.transmitted_flux_w_nm, rtol=1e-6)


def test_footprints_agree_with_beams_better_than_texels():
    """configs/ocean.toml (64² surface, 64² map, no absorption, point sun) against the beams' exact
    map of the same frame: footprint photons at 4 and 16 photons per texel are closer than texel
    photons at the same counts, by more than 2× (measured: docs/validation.md)."""
    base = {"water.resolution": 64, "caustics.map_resolution": 64, "optics.water_type": "none",
            "optics.wavelengths": "rgb", "sun.angular_diameter_deg": 0.0}
    beams = wc.render(wc.load_scene(CONFIGS / "ocean.toml", {**base, "caustics.method": "beams"}),
                      device="cpu").floor_irradiance
    l1 = {}
    for splat in ("texel", "footprint"):
        for s in (2, 4):
            scene = wc.load_scene(CONFIGS / "ocean.toml", {**base, "caustics.method": "photons",
                                                            "caustics.photon_splat": splat,
                                                            "caustics.photon_subdivisions": s})
            l1[splat, s] = relative_l1(wc.render(scene, device="cpu").floor_irradiance, beams)
    # measured 0.046 / 0.038 against 0.197 / 0.083; what is left is the photons' bilinear surface
    # patches against the beams' triangles, not noise (it hardly falls from 4 to 16 per texel)
    for s in (2, 4):
        assert l1["footprint", s] < 0.5 * l1["texel", s], l1


def test_footprints_on_a_sphere_agree_with_beams_better_than_texels():
    """configs/ocean.toml (64² surface) with a sphere (radius 1 m, 7,936 faces, centre 2.5 m down),
    no absorption: the flux on each of the sphere's faces from footprint photons, spread over the
    faces their cells cover, is closer to the beams' (another method) than the photons' face
    deposits at the same count — by more than 5× at 4 and 16 photons per cell — and the flux on
    floor and sphere together is what entered the water (float32 sums: 1e-5)."""
    centre = [0.0, 0.0, -2.5]
    base = {"water.resolution": 64, "caustics.map_resolution": 32, "optics.wavelengths": "rgb",
            "optics.water_type": "none",
            "receivers": [{"mesh": "sphere", "scale": 2.0, "translate_m": centre}]}
    beams = wc.render(wc.load_scene(CONFIGS / "ocean.toml", {**base, "caustics.method": "beams"}),
                      device="cpu")
    sphere = beams.face_receiver == 2
    reference = beams.face_flux_w_nm[sphere]
    l1 = {}
    for splat in ("texel", "footprint"):
        for s in (2, 4):
            result = wc.render(wc.load_scene(CONFIGS / "ocean.toml", {
                **base, "caustics.method": "photons", "caustics.photon_splat": splat,
                "caustics.photon_subdivisions": s}), device="cpu")
            l1[splat, s] = relative_l1(reference, result.face_flux_w_nm[sphere])
            total = result.floor_flux_w_nm + result.face_flux_w_nm.sum(axis=0)
            np.testing.assert_allclose(total, result.transmitted_flux_w_nm, rtol=1e-5)
    # measured 0.177 / 0.094 against 1.73 / 1.09 (a face holds ~1 photon at 4 per cell)
    for s in (2, 4):
        assert l1["footprint", s] < 0.2 * l1["texel", s], l1


def _facet_profile(heights, extent_m, depth_m, sun, m, ior=1.333, steps=4000):
    """float64 reference: the texel averages (m texels over the period) of the floor irradiance
    / E_sun under a periodic 1-D height profile as the photons' surface model has it: heights
    straight between the samples (at cell centres), normals linear between the samples' unit
    normals (central differences), each normalised. Each facet is cut into ``steps`` pieces whose
    flux (E_sun (−h′, 0, 1)·s per unit length, times Fresnel's T at the piece's normal) is spread
    evenly between the landing points of its ends (Snell's law in vector form)."""
    n = len(heights)
    dx = extent_m / n
    x = (np.arange(n) + 0.5) * dx - extent_m / 2
    h = np.asarray(heights, np.float64)
    slope = (np.roll(h, -1) - np.roll(h, 1)) / (2 * dx)
    normals = np.stack([-slope, np.zeros(n), np.ones(n)], axis=1)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    s = np.asarray(sun, np.float64) / np.linalg.norm(sun)
    t = np.linspace(0.0, 1.0, steps + 1)
    mid = 0.5 * (t[1:] + t[:-1])
    eta = 1.0 / ior
    lo, hi, flux = [], [], []
    for i in range(n):
        j = (i + 1) % n
        normal = (1 - t)[:, None] * normals[i] + t[:, None] * normals[j]
        normal /= np.linalg.norm(normal, axis=1, keepdims=True)
        cos_i = normal @ s
        d = -eta * s + (eta * cos_i - np.sqrt(1 - eta**2 * (1 - cos_i**2)))[:, None] * normal
        land = x[i] + t * dx + (h[i] + t * (h[j] - h[i]) + depth_m) * d[:, 0] / -d[:, 2]
        normal = (1 - mid)[:, None] * normals[i] + mid[:, None] * normals[j]
        normal /= np.linalg.norm(normal, axis=1, keepdims=True)
        transmitted = fresnel_t_angles(np.arccos(np.clip(normal @ s, -1.0, 1.0)), 1.0, ior)
        flux.append(np.array([-(h[j] - h[i]) / dx, 0.0, 1.0]) @ s * transmitted * dx / steps)
        lo.append(np.minimum(land[:-1], land[1:]))
        hi.append(np.maximum(land[:-1], land[1:]))
    lo, hi, flux = np.concatenate(lo), np.concatenate(hi), np.concatenate(flux)
    shift = np.floor((lo + extent_m / 2) / extent_m) * extent_m  # each piece's start into the period
    lo, hi = lo - shift, hi - shift
    periods = int(np.ceil((hi.max() + extent_m / 2) / extent_m))
    edges = -extent_m / 2 + np.arange(m * periods + 1) * extent_m / m
    width = np.maximum(hi - lo, 1e-300)
    below = np.array([np.sum(flux * np.clip((e - lo) / width, 0.0, 1.0)) for e in edges])
    return np.diff(below).reshape(periods, m).sum(axis=0) / (extent_m / m)


@pytest.mark.parametrize(("elevation_deg", "depth_m"), [(90.0, 1.0), (55.0, 3.0)])
def test_a_sinusoid_matches_the_exact_answer_of_its_facets(tmp_path, elevation_deg, depth_m):
    """Three periods of a 0.1 m sinusoid on 32 samples over 4 m (focal depth ~1.8 m), a point sun
    overhead over a floor 1 m down (before the focus) and 55° high over one 3 m down (past it,
    folds), no absorption, 64² map: the photons' floor profile against the float64 answer of the
    same facets (:func:`_facet_profile`). Relative L1 within the photon method's stated error:
    3 % at the default 4×4 per cell, 1.5 % at 8×8 (measured 0.44 % / 1.64 %, 0.10 % / 0.59 %), and
    falling towards the reference with the count (16×16: 0.013 % / 0.21 %)."""
    extent, n, m = 4.0, 32, 64
    x = (np.arange(n) + 0.5) * extent / n - extent / 2
    heights = (0.1 * np.sin(2 * np.pi * 3 * x / extent)).astype(np.float32)
    np.save(tmp_path / "sinusoid.npy", np.tile(heights, (n, 1)))
    base = {"water.model": "heightfield", "water.file": str(tmp_path / "sinusoid.npy"),
            "water.extent_m": extent,
            "sun.elevation_deg": elevation_deg, "sun.azimuth_deg": 0.0, "sun.angular_diameter_deg": 0.0,
            "floor.depth_m": depth_m, "optics.water_type": "none", "optics.wavelengths.bins": 1,
            "caustics.method": "photons", "caustics.map_resolution": m}
    l1 = {}
    for s in (4, 8, 16):
        scene = wc.load_scene(None, {**base, "caustics.photon_subdivisions": s})
        result = wc.render(scene, device="cpu")
        reference = _facet_profile(heights, extent, depth_m, scene.sun_direction, m)
        l1[s] = relative_l1(reference, result.floor_irradiance[0].mean(axis=0) / result.sun_irradiance[0])
    assert l1[4] <= 0.03 and l1[8] <= 0.015, l1
    assert l1[16] < 0.5 * l1[8], l1
