"""sky.sampling = "cones" (issue 32 item 3): each sky direction's floor map spread over the floor as
its cell of the sky would spread it (``optics/sky_cells.py``), so that a few directions give the
sky's continuum rather than caustic patterns of their own."""

import math

import numpy as np
import pytest

import warpcaustics as wc
from warpcaustics.batch.stats import cross_band_power
from warpcaustics.errors import ConfigError
from warpcaustics.optics.sky import CIE_CLEAR_TYPE, cie_relative_radiance
from warpcaustics.optics.sky_cells import cell_key, cell_multiplier, cell_shares, dense, sky_cells

from helpers import fresnel_t_angles

IOR = 1.34
SEA = {"water.model": "fft", "water.resolution": 32, "water.extent_m": 2.0, "water.depth_m": 50.0,
       "caustics.map_resolution": 32, "optics.wavelengths.bins": 1, "floor.depth_m": 3.0,
       "sky.model": "uniform", "sky.diffuse_fraction": 0.85, "sun.elevation_deg": 5.0,
       "optics.water_type": "none"}
FLAT = {"water.model": "flat", "water.extent_m": 4.0, "water.resolution": 8, "caustics.map_resolution": 8,
        "optics.wavelengths": [500.0], "floor.depth_m": 2.0, "sky.model": "uniform",
        "sky.diffuse_fraction": 0.3, "sky.sampling": "cones"}


def sixteen_directions(overrides: dict) -> tuple[np.ndarray, tuple, tuple]:
    """The SEA's 16 stratified sky directions (16, 3), the sun's direction and the directions as the
    cells' cache key (tuples)."""
    scene = wc.load_scene(None, {**SEA, "sky.directions": 16, **overrides})
    directions, _ = scene.sky_directions()
    return directions, cell_key(scene.sun_direction), cell_key(directions)


def cosine_weighted(n: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """(sinθ, φ) of n cosine-weighted random directions: uniform in the projected disk."""
    rng = np.random.default_rng(seed)
    return np.sqrt(rng.random(n)), 2 * math.pi * rng.random(n)


@pytest.mark.parametrize("sky_type, depth, texel, m, step", [(None, 3.0, 0.1, 64, 2), (12, 3.0, 0.1, 64, 2),
                                                             (None, 1.0, 0.5, 8, 1)])
def test_a_cells_multiplier_is_its_directions_mean_shift(sky_type, depth, texel, m, step):
    """B̂_j(k) against a Monte Carlo written apart: 400 000 cosine-weighted random directions (uniform
    in the projected disk), each in the cell of its nearest stratified direction of 16, weighted by
    the sky's radiance and the angle form of Fresnel's transmittance, refracted by Snell's law in
    angles, their floor offsets' phases e^{ik·D(t − t_j)} averaged — for three cells (by the zenith,
    half-way, by the horizon) and frequencies where |B̂| runs from ~0.9 to ~0.1: within 0.03. The
    Monte Carlo's standard error is ≤ 0.006; the multiplier's own error is its dense set's 256
    points a cell, which cut the cells' edges coarsely: against 3 million samples it is ≤ 0.016 at
    the horizon's cell (0.008 with 1024 points a cell), ≤ 0.005 elsewhere. The frequencies of all
    four quadrants are checked: the multiplier sums half of them and mirrors the rest (B̂(−k) =
    conj B̂(k)); on an 8² grid whose Nyquist row and column (which keep their own sums: their
    mirror on the grid is not −k) hold values in that range too."""
    directions, sun, key = sixteen_directions({})
    cells = sky_cells(key, sky_type, sun, IOR)
    r, phi = cosine_weighted(400_000, 7)
    p = np.stack([r * np.cos(phi), r * np.sin(phi)], axis=1)
    owner = np.argmin(((p[:, None, :] - directions[None, :, :2]) ** 2).sum(-1), axis=1)
    theta = np.arcsin(r)
    weight = fresnel_t_angles(theta, 1.0, IOR)
    if sky_type is not None:
        up = np.stack([p[:, 0], p[:, 1], np.cos(theta)], axis=1)
        weight = weight * cie_relative_radiance(sky_type, up, sun)
    theta_w = np.arcsin(r / IOR)
    offset = np.tan(theta_w)[:, None] * p / np.maximum(r, 1e-300)[:, None]  # along the light's azimuth
    k = 2 * math.pi * np.fft.fftfreq(m, texel)  # 0.98 rad/m apart on the 64² grids
    quadrants = set()
    for j in (0, 8, 15):
        mine = owner == j
        theta_j = math.asin(math.hypot(*directions[j, :2]))
        t_j = math.tan(math.asin(math.sin(theta_j) / IOR)) * directions[j, :2] / math.sin(theta_j)
        table = dense(cell_multiplier(directions[j], *cells[j], 16, depth, IOR, texel, m), m)
        checked = 0
        reach = min(12, m // 2 + 1)
        for iy in range(-reach + 1, reach, step):
            for ix in range(-reach + 1, reach, step):
                iy, ix = iy % m, ix % m  # numpy's fft2 order: m // 2 is the Nyquist row or column
                b = table[iy, ix]
                if not 0.1 < abs(b) < 0.95:
                    continue
                if 2 * iy == m or 2 * ix == m:
                    quadrants.add("nyquist row" if 2 * iy == m else "nyquist column")
                elif iy and ix:
                    quadrants.add((k[iy] > 0, k[ix] > 0))
                phase = np.exp(1j * depth * (k[ix] * (offset[mine, 0] - t_j[0])
                                             + k[iy] * (offset[mine, 1] - t_j[1])))
                mc = np.sum(weight[mine] * phase) / np.sum(weight[mine])
                assert abs(b - mc) < 0.03, (j, iy, ix, b, mc)
                checked += 1
        assert checked >= 3, j
        assert table[0, 0] == pytest.approx(1.0, abs=1e-6)
    assert len(quadrants) == (6 if m == 8 else 4), quadrants  # with both Nyquist lines on the 8² grid


def test_a_cells_share_is_the_light_its_directions_transmit():
    """Each direction's share (``cell_shares``) times its own flat-water Fresnel transmittance against
    a Monte Carlo written apart: 400 000 cosine-weighted random directions, each in the cell of its
    nearest stratified direction of 16, weighted by the CIE clear sky's radiance with the sun 5°
    high and the angle form of Fresnel's transmittance — each cell's transmitted light over the
    sky's whole radiance, within 0.006 (the Monte Carlo's standard error ≤ 0.001; the dense set's
    256 points a cell cut the cells' edges coarsely). The shares differ from the directions' own
    radiance over their sum by up to 2.5× at the horizon's brightest cell."""
    directions, sun, key = sixteen_directions({"sky.model": "cie_clear"})
    shares = cell_shares(key, CIE_CLEAR_TYPE, sun, IOR)
    r, phi = cosine_weighted(400_000, 11)
    up = np.stack([r * np.cos(phi), r * np.sin(phi), np.sqrt(1.0 - r * r)], axis=1)
    owner = np.argmin(((up[:, None, :2] - directions[None, :, :2]) ** 2).sum(-1), axis=1)
    radiance = cie_relative_radiance(CIE_CLEAR_TYPE, up, sun)
    transmitted = radiance * fresnel_t_angles(np.arcsin(r), 1.0, IOR)
    expected = np.bincount(owner, weights=transmitted, minlength=16) / radiance.sum()
    own_t = fresnel_t_angles(np.arccos(directions[:, 2]), 1.0, IOR)
    np.testing.assert_allclose(shares * own_t, expected, atol=0.006)
    point = cie_relative_radiance(CIE_CLEAR_TYPE, directions, sun)
    assert np.max(point / point.sum() / shares) > 2.0


@pytest.mark.parametrize("count", [8, 16])
def test_cones_over_still_water_have_the_sky_continuum_s_mean(count):
    """The CIE clear sky with the sun 5° high (85 % of the light) over still water, 2 m deep, in
    cones: the floor's sky part is E_sky ∫ L cosθ T(θ) e^{−cD/cosθ_w} dΩ / ∫ L cosθ dΩ (float64
    quadrature on a 1500 × 1500 grid of zenith and azimuth, Fresnel in angle form) within 0.5 %
    (measured 0.28 % with 8 directions, 0.14 % with 16: the paths' attenuation across a cell) —
    where the same directions as points miss it by 3.6 % and 1.0 %, and by 5.9 % with 32."""
    scene = wc.load_scene(None, {**FLAT, "sky.model": "cie_clear", "sky.diffuse_fraction": 0.85,
                                 "sun.elevation_deg": 5.0, "sky.directions": count})
    r = wc.render(scene, device="cpu")
    c, n, depth = float(r.attenuation_per_m[0]), float(r.ior[0]), 2.0
    grid = 1500
    theta = (np.arange(grid) + 0.5) * (math.pi / 2) / grid
    phi = (np.arange(grid) + 0.5) * (2 * math.pi) / grid
    t, p = np.meshgrid(theta, phi, indexing="ij")
    up = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1).reshape(-1, 3)
    radiance = cie_relative_radiance(CIE_CLEAR_TYPE, up, scene.sun_direction).reshape(t.shape)
    horizontal = radiance * (np.cos(t) * np.sin(t))
    through = fresnel_t_angles(theta, 1.0, n) * np.exp(-c * depth / np.cos(np.arcsin(np.sin(theta) / n)))
    e_sky = float(scene.sky_irradiance(r.sun_irradiance)[0])
    expected = e_sky * (horizontal * through[:, None]).sum() / horizontal.sum()
    assert float(r.sky_floor_irradiance[0].mean()) == pytest.approx(expected, rel=0.005)


def test_the_splatted_multiplier_is_the_sum_s():
    """Where the points' discs are under a few texels the multiplier comes from the points splatted on
    the grid (``SPLAT_ABOVE``): against the sum over points for three cells of 16 at 0.3, 1 and 3 m,
    within 0.05 at every frequency and 0.012 rms (measured ≤ 0.040 and 0.003–0.009)."""
    directions, sun, key = sixteen_directions({})
    cells = sky_cells(key, None, sun, IOR)
    for depth, texel, m in ((3.0, 0.02, 128), (1.0, 0.01, 128), (0.3, 0.004, 256)):
        for j in (0, 8, 15):
            summed = dense(cell_multiplier(directions[j], *cells[j], 16, depth, IOR, texel, m,
                                           splat_above=1 << 40), m)
            splatted = dense(cell_multiplier(directions[j], *cells[j], 16, depth, IOR, texel, m,
                                             splat_above=0), m)
            gap = np.abs(summed - splatted)
            assert gap.max() < 0.05 and np.sqrt(np.mean(gap**2)) < 0.012, (depth, j, gap.max())


def test_cones_keep_the_sky_s_mean_and_wash_out_its_directions():
    """On a 32² FFT sea over 2 m (the whole periodic patch as the map), the sun 5° high with 85 % sky,
    3 m deep: the cones' map has the mean of 4096 stratified directions, the sky's continuum, within
    0.5 % (each cone brings what its cell transmits; the spread moves light, keeps it), and
    its power spectrum of E/Ē − 1 in octave bands (0.5 to 32 cycles per m) is the sky's of 4096
    stratified directions — within 5 % in the three coarsest bands, where 4096 directions have
    converged (1024 give the same to 2 %); in the two finest, 4096 directions still carry their own
    patterns (1024 have 1.4× and 1.7× their power), and the cones lie between 0.95× the
    continuum extrapolated from them, (4 P₄₀₉₆ − P₁₀₂₄)/3, and 1.05× P₄₀₉₆ (measured: 0.97–1.00× the
    4096 directions in the three coarsest bands, 1.00× and 0.97× in the finest two) — where 16
    stratified directions carry more than 3× (up to ~30×) the cones' power in the middle bands."""

    def render(directions, sampling):
        scene = wc.load_scene(None, {**SEA, "sky.directions": directions, "sky.sampling": sampling})
        f = wc.render(scene, device="cpu").floor_irradiance[0].astype(np.float64)
        return f, cross_band_power(f, f, 2.0, periodic=True) / f.mean() ** 2

    cones, cones_power = render(16, "cones")
    _, stratified_power = render(16, "stratified")
    _, p1024 = render(1024, "stratified")
    continuous, p4096 = render(4096, "stratified")
    assert cones.mean() == pytest.approx(continuous.mean(), rel=0.005)
    np.testing.assert_allclose(cones_power[:3], p4096[:3], rtol=0.05)
    continuum = (4.0 * p4096 - p1024) / 3.0
    assert np.all(cones_power[3:] > 0.95 * continuum[3:]), (cones_power, continuum)
    assert np.all(cones_power[3:] < 1.05 * p4096[3:]), (cones_power, p4096)
    assert np.all(stratified_power[1:4] > 3.0 * cones_power[1:4])


@pytest.mark.parametrize("scattering", ["single", "small_angle"])
def test_a_window_s_cones_are_the_whole_patch_s(scattering):
    """A 0.5 m window of a 2 m periodic sea (32² cells) at the whole map's 3.1 cm texels: its cones
    (the spread's large scales from the whole patch's coarse map, the window's own detail taken as
    periodic) against the same texels of the whole patch's map, where the spread is one periodic
    convolution: relative L1 within 1 % (measured 0.46 % and 0.33 %; the stratified sky's window
    under the small-angle transfer alone, 0.48 %) and CV within 1 % (measured 0.5 % and 0.1 %), with
    single and with small-angle scattering (whose transfer then takes the spread maps)."""
    sea = {**SEA, "sky.directions": 16, "sky.sampling": "cones", "optics.scattering": scattering,
           "optics.water_type": "jerlov_II", "sun.elevation_deg": 30.0, "sky.diffuse_fraction": 0.5,
           "caustics.map_resolution": 64}
    whole = wc.render(wc.load_scene(None, sea), device="cpu").floor_irradiance[0]
    window = wc.render(wc.load_scene(None, {**sea, "caustics.map_extent_m": 0.5,
                                            "caustics.map_resolution": 16}), device="cpu").floor_irradiance[0]
    crop = whole[24:40, 24:40].astype(np.float64)
    assert np.abs(window - crop).sum() / crop.sum() < 0.01
    assert window.std() / window.mean() == pytest.approx(crop.std() / crop.mean(), rel=0.01)


@pytest.mark.parametrize(("overrides", "needle"), [
    ({"caustics.method": "photons"}, 'caustics.method = "fluxratio"'),
    ({"optics.scattering": "multiple"}, '"single" or "small_angle"'),
    ({"water.model": "pool"}, "periodic sea"),
])
def test_cones_errors_are_one_line(overrides, needle):
    with pytest.raises(ConfigError, match=needle):
        wc.load_scene(None, {**FLAT, **overrides})


@pytest.mark.parametrize(("overrides", "resolution"), [
    ({}, 16), ({"water.resolution": 8}, 8), ({"sky.sampling": "stratified"}, 32),
    ({"water.model": "flat"}, 32), ({"sky.model": "none", "sky.diffuse_fraction": 0.0}, 32),
])
def test_a_sky_surface_applies_to_cones_over_an_fft_ocean(overrides, resolution):
    """``sky.surface_resolution`` = 16 on the 32² sea: the sky's surface is 16², or the water's own
    grid where that is coarser; point directions, another sea or no sky leave it aside (a field
    config's budget rows still load)."""
    scene = wc.load_scene(None, {**SEA, "sky.sampling": "cones", "sky.surface_resolution": 16, **overrides})
    assert scene.sky_resolution == resolution


def test_a_sky_surface_that_is_no_power_of_two_is_one_line():
    with pytest.raises(ConfigError, match="sky.surface_resolution = 24 must be a power of two"):
        wc.load_scene(None, {**SEA, "sky.sampling": "cones", "sky.surface_resolution": 24})


@pytest.mark.parametrize("scattering", ["single", "small_angle"])
def test_the_sky_s_coarser_surface_leaves_the_sun_s_light_alone(scattering):
    """``sky.surface_resolution`` = 32 on a 64² sea: the sky's passes (and with the small-angle
    transfer its walk for the mean) take the sea's waves cut to 32², the sun's the whole sea — the
    sun's part of the map (floor − sky) is the whole grid's to float32 rounding with single
    scattering, the sky's mean within 1 % of the whole grid's (measured +0.13 % and −0.06 %). A
    value at or above the water's grid is the water's own grid: the same map to the bit. The sky's
    shading is kept at the coarser grid."""
    sea = {**SEA, "water.resolution": 64, "sky.directions": 16, "sky.sampling": "cones",
           "optics.scattering": scattering, "optics.water_type": "jerlov_II", "sun.elevation_deg": 30.0,
           "sky.diffuse_fraction": 0.5}
    renders = {ns: wc.render(wc.load_scene(None, {**sea, "sky.surface_resolution": ns}), device="cpu")
               for ns in (0, 32, 64)}
    whole, coarse = renders[0], renders[32]
    assert wc.load_scene(None, {**sea, "sky.surface_resolution": 32}).sky_resolution == 32
    np.testing.assert_array_equal(renders[64].floor_irradiance, whole.floor_irradiance)
    assert "sky_water" in coarse.timings_s and "sky_water" not in whole.timings_s
    if scattering == "single":
        np.testing.assert_allclose(coarse.floor_irradiance - coarse.sky_floor_irradiance,
                                   whole.floor_irradiance - whole.sky_floor_irradiance,
                                   atol=1e-6 * whole.floor_irradiance.max())  # float32 sum and difference
    assert not np.array_equal(coarse.sky_floor_irradiance, whole.sky_floor_irradiance)
    assert coarse.sky_floor_irradiance.mean() == pytest.approx(whole.sky_floor_irradiance.mean(), rel=0.01)
    renderer = wc.Renderer(wc.load_scene(None, {**sea, "sky.surface_resolution": 32}), "cpu")
    kept = (16, 32, 32) if scattering == "small_angle" else (32, 32)  # the walk takes each direction's
    assert renderer.light.sky_visible.shape == kept and renderer.sky_water.resolution == 32


def test_cones_without_a_sky_spread_nothing():
    """A field config in cones with its sky turned off (as the sensor benchmark does) loads and
    renders the sun alone."""
    scene = wc.load_scene(None, {**FLAT, "sky.model": "none", "sky.diffuse_fraction": 0.0})
    r = wc.render(scene, device="cpu")
    assert r.sky_floor_irradiance is None and np.all(np.isfinite(r.floor_irradiance))


def test_the_spread_moves_a_pattern_where_the_cell_s_directions_draw_it():
    """The rigid shift, sign included: a point sun's floor map on a 32² FFT sea over 2 m, 1 m deep,
    from 60° elevation (256² map, 7.8 mm texels), spread by a 'cell' of 16 directions 2° away from it
    (elevation 57°–59°, azimuth 0°–4°: floor offsets of 1–4 cm), against the mean of the 16 maps
    rendered from those directions (each over its own mean): relative rms difference under 0.2 of
    the pattern's own rms (measured 0.115; 0.085 and 0.166 for cells 1° and 4° away — the patterns
    of directions a few degrees apart differ in shape, not only in place), where the mirror-image
    shift (the multiplier's conjugate) misses by 1.37 and the unspread map by 1.58."""
    sea = {**SEA, "sky.model": "none", "sky.diffuse_fraction": 0.0, "sun.angular_diameter_deg": 0.0,
           "floor.depth_m": 1.0, "caustics.map_resolution": 256}

    def sun_map(elevation, azimuth):
        scene = wc.load_scene(None, {**sea, "sun.elevation_deg": elevation, "sun.azimuth_deg": azimuth})
        f = wc.render(scene, device="cpu").floor_irradiance[0].astype(np.float64)
        return f / f.mean(), scene.sun_direction

    base, d0 = sun_map(60.0, 0.0)
    maps, points = [], []
    for elevation in np.linspace(57.0, 59.0, 4):
        for azimuth in np.linspace(0.0, 4.0, 4):
            f, d = sun_map(elevation, azimuth)
            maps.append(f)
            points.append(d)
    mean = np.mean(maps, axis=0)
    # count = 4096: discs too small to matter, the 16 directions' shifts alone
    multiplier = dense(cell_multiplier(d0, np.array(points), np.ones(16), 4096, 1.0, IOR, 2.0 / 256, 256),
                       256)
    spectrum = np.fft.fft2(base)
    spread = np.fft.ifft2(spectrum * multiplier).real
    mirrored = np.fft.ifft2(spectrum * np.conj(multiplier)).real
    scale = np.std(mean)

    def miss(f):
        return float(np.sqrt(np.mean((f - mean) ** 2)) / scale)

    assert miss(spread) < 0.2, miss(spread)
    assert miss(mirrored) > 5.0 * miss(spread), (miss(mirrored), miss(spread))
    assert miss(base) > 5.0 * miss(spread), (miss(base), miss(spread))
