"""Beam caustics (``caustics.method = "beams"``): warped beam volumes through the tile rasteriser.

Checked against what the beams did not produce: the analytic flat-water irradiance, energy
conservation, the flux-ratio map of issue 2, exact (BVH) photons and the analytic
single-scattering integral of a lit pool; the scan-plane chord against a float64 ray–prism chord is
in ``test_beam_chords.py``.
"""

import numpy as np
import pytest
import warp as wp
from test_photons import shaft_block, shaft_scene

import warpcaustics as wc
from warpcaustics.errors import ConfigError
from warpcaustics.kernels.caustics import beams as beam_kernels

from helpers import CONFIGS, flat_floor_irradiance, flat_water_scene, fresnel_t_angles

BEAMS = {"caustics.method": "beams"}


def _flat(elevation_deg, depth_m, water_type="pure", **extra):
    return flat_water_scene(elevation_deg, depth_m, water_type, **{**BEAMS, **extra})


@pytest.mark.parametrize("elevation_deg", [5.0, 20.0, 55.0, 90.0])
def test_flat_water_beams_match_analytic_irradiance(device, elevation_deg):
    """Flat water: every texel reads E_sun cosθ T(θ) exp(−c D / cosθ_t) (the issue asks 0.5 %; the
    exact clipping leaves only float32 rounding)."""
    result = wc.render(_flat(elevation_deg, 3.0), device=device)
    expected = flat_floor_irradiance(result, elevation_deg, 3.0)
    floor = result.floor_irradiance.astype(np.float64)
    np.testing.assert_allclose(floor, np.broadcast_to(expected[:, None, None], floor.shape), rtol=2e-5)
    assert result.beam_stats["dropped"] == 0


def test_flat_water_on_a_sloped_floor_in_a_pool_matches_analytic_irradiance():
    """A still pool over a sloped floor (point-sampled relief map): the irradiance on the slope's
    true area is E⊥ |d·n| attenuated over the path to each point, away from the walls' shadows."""
    elevation, slope = 70.0, 10.0
    scene = wc.load_scene(
        None,
        {
            **BEAMS,
            "water.model": "pool",
            "water.resolution": 32,
            "water.extent_m": 4.0,
            "caustics.map_resolution": 32,
            "floor.depth_m": 1.5,
            "floor.shape": "slope",
            "floor.slope_deg": slope,
            "floor.slope_azimuth_deg": 0.0,
            "sun.elevation_deg": elevation,
            "sun.azimuth_deg": 180.0,
            "optics.water_type": "clear_ocean",
            "optics.wavelengths": "rgb",
        },
    )
    result = wc.render(scene, device="cpu")
    theta = np.radians(90.0 - elevation)
    t = fresnel_t_angles(np.array([theta]), 1.0, 1.333)[0]
    sin_t = np.sin(theta) / 1.333
    d = np.array([sin_t, 0.0, -np.sqrt(1.0 - sin_t**2)])  # the sun in −x refracts towards +x
    n = np.array([np.sin(np.radians(slope)), 0.0, np.cos(np.radians(slope))])  # floor falls to +x
    x = (np.arange(32) + 0.5) * 4.0 / 32 - 2.0
    depth = 1.5 + np.tan(np.radians(slope)) * x  # below the surface at z = 0
    path = depth / -d[2]
    e_perp = result.sun_irradiance[:, None] * np.cos(theta) * t / -d[2]
    expected = e_perp * abs(d @ n) * np.exp(-result.attenuation_per_m[:, None] * path[None, :])
    # Away from the walls: x from the wall's shadow (sun in −x ⇒ the wall at x = −2 shadows nothing
    # under a flat surface, but the beams reaching x > 2 are cut) — keep the middle.
    inner = slice(4, 28)
    measured = result.floor_irradiance[:, inner, inner].astype(np.float64)
    np.testing.assert_allclose(measured, np.broadcast_to(expected[:, None, inner], measured.shape), rtol=1e-4)


def test_beam_floor_map_conserves_flux_and_matches_the_flux_ratio_map():
    """configs/ocean.toml (128² surface, 64² map, rgb): with water_type none the floor receives
    the flux that entered the water to 1e-4; in pure water the map agrees with the flux-ratio map
    of issue 2 within 1 % relative L1 (measured: 7e-5)."""
    base = {"water.resolution": 128, "caustics.map_resolution": 64, "optics.wavelengths": "rgb"}
    beams = wc.render(
        wc.load_scene(CONFIGS / "ocean.toml", {**base, **BEAMS, "optics.water_type": "none"}), device="cpu"
    )
    np.testing.assert_allclose(beams.floor_flux_w_nm, beams.transmitted_flux_w_nm, rtol=1e-4)
    reference = wc.render(wc.load_scene(CONFIGS / "ocean.toml", base), device="cpu").floor_irradiance
    beams = wc.render(wc.load_scene(CONFIGS / "ocean.toml", {**base, **BEAMS}), device="cpu").floor_irradiance
    l1 = np.abs(beams - reference).sum() / np.abs(reference).sum()
    assert l1 < 0.01
    assert beams.std() > 0.2 * beams.mean()  # a real caustic pattern, not a flat map


def _sphere_bins(result, receiver, centre, bins=8):
    """Flux on a receiver summed over (elevation, azimuth) cells of its face centres around centre."""
    sel = result.face_receiver == receiver
    rel = result.face_centres_m[sel] - np.asarray(centre)
    elevation = np.arctan2(rel[:, 2], np.hypot(rel[:, 0], rel[:, 1]))
    azimuth = np.arctan2(rel[:, 1], rel[:, 0])
    cell = np.digitize(elevation, np.linspace(-np.pi / 2, np.pi / 2, bins + 1)[1:-1]) * bins + np.digitize(
        azimuth, np.linspace(-np.pi, np.pi, bins + 1)[1:-1]
    )
    flux = result.face_flux_w_nm[sel].sum(axis=1)
    return np.bincount(cell, weights=flux, minlength=bins * bins)


def test_beams_agree_with_exact_photons_on_the_floor_and_on_a_sphere():
    """configs/ocean.toml with a sphere (radius 1 m, centre 2.5 m down), water_type none: beams and
    exact photons at 16 per cell (256 per map texel, 32² map) agree within 3 % relative L1 on the
    floor, and on the sphere over 8×8 (elevation, azimuth) cells of its faces (≥ 64 photons each
    where lit); the light reaching the floor and the sphere adds up to what entered the water
    (measured with footprint photons: 0.48 %, 0.79 % and 4.6e-5 (texel photons: 0.59 %, 0.91 %);
    the sphere's 4×4 samples per face leave ~1e-4)."""
    centre = [0.0, 0.0, -2.5]
    base = {
        "water.resolution": 128,
        "caustics.map_resolution": 32,
        "optics.wavelengths": "rgb",
        "optics.water_type": "none",
        "receivers": [{"mesh": "sphere", "scale": 2.0, "translate_m": centre}],
    }
    photons = wc.render(
        wc.load_scene(
            CONFIGS / "ocean.toml", {**base, "caustics.method": "photons", "caustics.photon_subdivisions": 4}
        ),
        device="cpu",
    )
    beams = wc.render(wc.load_scene(CONFIGS / "ocean.toml", {**base, **BEAMS}), device="cpu")
    f_b, f_p = beams.floor_irradiance, photons.floor_irradiance
    assert np.abs(f_b - f_p).sum() / np.abs(f_p).sum() < 0.03
    s_b, s_p = _sphere_bins(beams, 2, centre), _sphere_bins(photons, 2, centre)
    assert np.abs(s_b - s_p).sum() / np.abs(s_p).sum() < 0.03
    total = beams.floor_flux_w_nm + beams.face_flux_w_nm.sum(axis=0)
    np.testing.assert_allclose(total, beams.transmitted_flux_w_nm, rtol=5e-4)


@pytest.mark.parametrize("pitch_deg, sees", [(0.0, 1), (35.0, -1), (-35.0, 0)], ids=["level", "up", "down"])
def test_beam_shafts_match_single_scattering_in_a_lit_pool(pitch_deg, sees):
    """The photon shaft scene (zenith sun over a still pool, clear ocean water) with beams: the
    scan-plane in-scattering equals ∫ σ_s p(θ) E_sun T e^{−c(ℓ(s)+s)} ds to the ray's end: chords
    tile each ray exactly, so only the midpoint rule and float32 are left (2.4e-5 measured on a 32²
    surface; photon lines are 1-3 % low on a 128² one)."""
    measured, expected = shaft_block(pitch_deg, sees, resolution=32, method="beams")
    np.testing.assert_allclose(measured, expected, rtol=1e-4)


def test_beam_shafts_looking_into_the_light_are_the_forward_peak():
    """The shaft scene's camera looking straight up, along the light (the view runs along the
    beams, within 0.3° at the centre): every pixel is the single-scattering integral (1e-4; measured
    6.3e-5), so the bright centre, 21× the image's mean, is the phase function's forward peak and
    not an artefact of the scan planes. (Photon lines on a 128² surface are 0.21–2.9× the integral
    here: a line seen end-on is no estimate of the radiance along it.)"""
    result, expected, sees = shaft_scene(90.0, resolution=32, method="beams", up=(1.0, 0.0, 0.0))
    assert np.all(sees == -1)  # the surface, seen from below
    np.testing.assert_allclose(result.camera_radiance, expected, rtol=1e-4)
    image = result.camera_radiance.sum(axis=0)
    assert image[22:26, 30:34].mean() > 10.0 * image.mean()


def test_rays_in_a_shadow_get_no_light():
    """A wide plate above the camera, zenith sun over flat water: the beams end on the plate, so
    every ray from the camera below it (to the floor in its shadow) gets no in-scattered light and
    sees a black floor; outside the shadow the floor reads E_sun T(0)."""
    overrides = {
        "floor.albedo": 0.5,
        "water.resolution": 32,
        "receivers": [{"mesh": "cube", "scale": [3.0, 3.0, 0.05], "translate_m": [0.0, 0.0, -1.0]}],
        "camera.enabled": True,
        "camera.position_m": [0.0, 0.0, -1.5],
        "camera.look_at_m": [0.0, 0.2, -3.0],
        "camera.width": 48,
        "camera.height": 32,
        "camera.fov_deg": 40.0,
    }
    result = wc.render(_flat(90.0, 3.0, "clear_ocean", **overrides), device="cpu")
    assert np.all(result.camera_gbuffer["receiver"] == 0)
    assert np.all(result.camera_radiance == 0.0)
    x = (np.arange(32) + 0.5) * 8.0 / 32 - 4.0
    open_floor = (np.abs(x)[:, None] > 1.6) | (np.abs(x)[None, :] > 1.6)
    shadow = (np.abs(x)[:, None] < 1.4) & (np.abs(x)[None, :] < 1.4)
    assert np.all(result.floor_irradiance[:, shadow] == 0.0)
    expected = flat_floor_irradiance(result, 90.0, 3.0)
    np.testing.assert_allclose(result.floor_irradiance[:, open_floor].mean(axis=1), expected, rtol=1e-4)


def test_camera_sees_a_uniformly_lit_floor_as_uniform():
    """Flat water, no absorption, a grey floor seen obliquely, no shafts: every pixel's radiance is
    albedo · E_sun cosθ T(θ) / π (the point-in-beam gather on the G-buffer)."""
    overrides = {
        "floor.albedo": 0.5,
        "caustics.shafts": False,
        "camera.enabled": True,
        "camera.position_m": [-1.0, -2.0, -1.0],
        "camera.look_at_m": [0.5, 0.5, -3.0],
        "camera.width": 96,
        "camera.height": 64,
        "camera.fov_deg": 60.0,
    }
    result = wc.render(_flat(60.0, 3.0, "none", **overrides), device="cpu")
    e = flat_floor_irradiance(result, 60.0, 3.0)
    seen = result.camera_gbuffer["receiver"] == 0
    assert seen.sum() > 4000
    measured = result.camera_radiance[:, seen] * np.pi / 0.5 / e[:, None]
    np.testing.assert_allclose(measured, 1.0, atol=1e-4)


@pytest.mark.parametrize(
    "config, overrides",
    [
        (CONFIGS / "ocean_floor.toml", {"water.resolution": 32}),
        (
            CONFIGS / "pool.toml",
            {
                "water.resolution": 32,
                "camera.enabled": True,
                "camera.position_m": [-1.5, -1.5, -0.6],
                "camera.look_at_m": [1.0, 0.5, -1.4],
                "optics.water_type": "coastal_ocean",
            },
        ),
    ],
    ids=["periodic-sea", "walled-pool"],
)
def test_the_cpu_tile_walk_gives_the_per_pixel_shafts_to_the_bit(config, overrides):
    """The volume pass's two thread layouts (a thread per pixel for the GPU, per 8×8 tile for the
    CPU, which walks a tile's beam list once and tests each beam's box at the tile's pixels)
    give the same radiance to the bit and test the same (pixel, beam) pairs, on a periodic sea
    (3×3 copies) and in a walled pool, with a frame whose sides are not whole tiles."""
    scene = wc.load_scene(
        config,
        {**BEAMS, **overrides, "caustics.shafts": True, "optics.wavelengths": "rgb", "camera.width": 60,
         "camera.height": 44, "caustics.map_resolution": 32},
    )
    renderer = wc.Renderer(scene, "cpu")
    renderer.render(0.0)
    camera = renderer.method.camera
    assert camera.shaft_threads == "tile"
    tiles = camera.shafts.numpy().copy()
    tile_fill = camera.beam_fill()
    camera.shaft_threads = "pixel"
    camera.render_beams(renderer.method.caustics[0], True)
    pixels = camera.shafts.numpy()
    assert tile_fill == camera.beam_fill()
    assert tile_fill["inside_pairs"] > 1000 and (pixels > 0).mean() > 0.3
    np.testing.assert_array_equal(tiles, pixels)


def test_grazing_sun_folds_and_degenerate_beams_stay_finite():
    """A choppy ocean (folding surface, inverted and degenerate beams) under a grazing sun, seen by
    the camera with shafts: everything stays finite, beams facing away are dropped and counted,
    and the floor gets the flux that entered the water."""
    scene = wc.load_scene(
        CONFIGS / "ocean_floor.toml",
        {
            **BEAMS,
            "water.resolution": 64,
            "water.extent_m": 20.0,
            "water.choppiness": 3.0,
            "water.phillips_amplitude": 5e-2,
            "water.small_wave_m": 0.5,
            "floor.depth_m": 8.0,
            "caustics.map_resolution": 32,
            "sun.elevation_deg": 2.0,
            "optics.wavelengths": "rgb",
            "optics.water_type": "none",
            "floor.shape": "flat",
            "camera.width": 32,
            "camera.height": 24,
        },
    )
    result = wc.render(scene, device="cpu")
    assert result.fold_fraction > 0.0
    assert result.beam_stats["dropped"] > 0
    assert np.isfinite(result.floor_irradiance).all() and np.isfinite(result.camera_radiance).all()
    # Sections of near-horizontal rays span many periods: every copy is gathered, so the flux stays
    # (measured 5.4e-5 short, as the flux-ratio map's 4.4e-5).
    np.testing.assert_allclose(result.floor_flux_w_nm, result.transmitted_flux_w_nm, rtol=1e-3)


def test_smooth_interpolation_hides_beam_edges_and_keeps_the_flux():
    """A coarse ocean (32² surface) on a fine map (8 texels per cell), water_type none: the smooth
    (Ernst) interpolation conserves the flux like the flat beams (the ring densities of the
    vertices share each beam's flux exactly on a plane) and its largest jump between neighbouring
    texels is under a fifth of the flat map's (measured: 0.42 vs 5.9 × the mean)."""
    base = {
        **BEAMS,
        "water.resolution": 32,
        "caustics.map_resolution": 256,
        "optics.wavelengths": "rgb",
        "optics.water_type": "none",
    }
    jumps = {}
    for interp in ("flat", "smooth"):
        r = wc.render(
            wc.load_scene(CONFIGS / "ocean.toml", {**base, "caustics.beam_interpolation": interp}),
            device="cpu",
        )
        np.testing.assert_allclose(r.floor_flux_w_nm, r.transmitted_flux_w_nm, rtol=1e-4)
        f = r.floor_irradiance[1].astype(np.float64)
        jumps[interp] = max(np.abs(np.diff(f, axis=0)).max(), np.abs(np.diff(f, axis=1)).max()) / f.mean()
    assert jumps["smooth"] < 0.2 * jumps["flat"]


def test_both_methods_write_both_results_and_their_difference(tmp_path):
    """``caustics.method = "both"``: the beams' result carries the photons' as its comparison; the
    frame is saved with the photons' files and the beams − photons floor map, and run.json records
    their relative L1 and the photons' flux."""
    import json

    import OpenEXR

    from warpcaustics.io.exr import spectral_channel_name

    overrides = {
        "caustics.method": "both",
        "water.resolution": 32,
        "caustics.map_resolution": 32,
        "optics.wavelengths": "rgb",
        "camera.width": 32,
        "camera.height": 24,
    }
    result = wc.render(wc.load_scene(CONFIGS / "ocean_floor.toml", overrides), device="cpu")
    other = result.comparison
    assert result.beam_stats is not None and other is not None and other.photon_stats is not None
    assert other.camera_radiance.shape == result.camera_radiance.shape
    paths = result.save(tmp_path)
    for key in ("exr", "photons_exr", "photons_png", "camera_photons_exr", "difference_exr"):
        assert paths[key].exists(), key
    with OpenEXR.File(str(paths["difference_exr"])) as exr:
        band = np.asarray(exr.channels()[spectral_channel_name(result.wavelengths_nm[1])].pixels)
    expected = (result.floor_irradiance[1] - other.floor_irradiance[1])[::-1]
    np.testing.assert_allclose(band, expected, atol=1e-6 * np.abs(result.floor_irradiance).max())
    entry = json.loads((tmp_path / "run.json").read_text())["frames"][0]["comparison"]
    l1 = np.abs(result.floor_irradiance - other.floor_irradiance).sum() / np.abs(other.floor_irradiance).sum()
    assert entry["floor_relative_l1_beams_vs_photons"] == pytest.approx(l1, rel=1e-5)
    assert "frame_0000_beams_minus_photons.exr" in entry["files"]


def test_adaptive_beams_refine_where_the_light_bends_and_keep_the_flux():
    """caustics.beam_levels (Liktor & Dachsbacher 2011 §4.2): still water needs no refinement (every
    leaf stays at the top level and the floor is still analytic); a zero tolerance refines
    everything and gives back the uniform grid's map exactly; in between, fewer beams than the
    uniform grid carry all the flux, and the map error shrinks as the tolerance does."""
    flat = wc.Renderer(_flat(55.0, 3.0, **{"caustics.beam_levels": 3, "water.resolution": 64}), "cpu")
    r = flat.render(0.0)
    assert flat.method.caustics[0].level_counts[3] == (64 // 8) ** 2 and r.beam_stats["beams"] == 2 * 8 * 8
    expected = flat_floor_irradiance(r, 55.0, 3.0)
    np.testing.assert_allclose(
        r.floor_irradiance, np.broadcast_to(expected[:, None, None], r.floor_irradiance.shape), rtol=2e-5
    )

    base = {
        **BEAMS,
        "water.resolution": 128,
        "caustics.map_resolution": 64,
        "optics.wavelengths": "rgb",
        "optics.water_type": "none",
    }
    uniform = wc.render(wc.load_scene(CONFIGS / "ocean.toml", base), device="cpu")
    l1, counts = [], []
    for tol in (0.0, 0.1, 1.0):
        r = wc.render(
            wc.load_scene(
                CONFIGS / "ocean.toml", {**base, "caustics.beam_levels": 2, "caustics.beam_tolerance": tol}
            ),
            device="cpu",
        )
        np.testing.assert_allclose(r.floor_flux_w_nm, r.transmitted_flux_w_nm, rtol=1e-4)
        l1.append(
            np.abs(r.floor_irradiance - uniform.floor_irradiance).sum() / uniform.floor_irradiance.sum()
        )
        counts.append(r.beam_stats["beams"])
    assert l1[0] == 0.0 and counts[0] == uniform.beam_stats["beams"]
    assert l1[0] < l1[1] < l1[2] and counts[0] > counts[1] > counts[2]


def test_adaptive_beams_refine_near_the_camera_and_refuse_what_they_cannot_do():
    """Near the camera a quad is split until its beam spans at most 16 pixels; walled pools, the
    smooth interpolation and resolutions not divisible by 2^levels are refused in one line."""
    overrides = {
        "caustics.beam_levels": 3,
        "water.resolution": 64,
        "caustics.beam_tolerance": 1e6,
        "caustics.shafts": False,
    }
    far = wc.Renderer(_flat(70.0, 3.0, **overrides), "cpu")
    far.render(0.0)
    near = wc.Renderer(
        _flat(
            70.0,
            3.0,
            **overrides,
            **{
                "camera.enabled": True,
                "camera.position_m": [0.0, 0.0, -0.5],
                "camera.look_at_m": [1.0, 0.0, -1.0],
                "camera.width": 64,
                "camera.height": 48,
            },
        ),
        "cpu",
    )
    near.render(0.0)
    far_beams, near_beams = far.method.caustics[0], near.method.caustics[0]
    assert far_beams.leaf_count == 64 and near_beams.leaf_count > far_beams.leaf_count
    assert near.method.caustics[0].level_counts[0] > 0
    for bad, match in (
        ({"water.model": "pool"}, "needs a periodic sea"),
        ({"caustics.beam_interpolation": "smooth"}, "needs the uniform grid"),
        ({"water.resolution": 36}, "divisible by 8"),
    ):
        with pytest.raises(ConfigError, match=match):
            wc.load_scene(None, {**BEAMS, "caustics.beam_levels": 3, **bad})


def test_beams_on_rippled_sand_keep_the_flux_and_agree_with_photons():
    """Ripples that tile the patch under a rough ocean (water_type none, 64² surface, 64² map): each
    texel's two mesh triangles are clipped exactly against the beams' cuts through their planes, so
    the flux stays within the shadow decisions' rounding (a piece is lit or not as its centroid is),
    and the map agrees with exact photons at 64 per cell (64 per texel). Measured: flux −1.9e-4,
    L1 4.5 % (3.8 % against 256 photons per cell)."""
    common = {
        "water.resolution": 64,
        "caustics.map_resolution": 64,
        "optics.water_type": "none",
        "optics.wavelengths": "rgb",
        "floor.shape": "ripples",
        "floor.ripple_amplitude_m": 0.1,
        "floor.ripple_wavelength_m": 16.0 / np.hypot(7, 26),
        "floor.ripple_direction_deg": np.degrees(np.arctan2(26, 7)),
    }
    beams = wc.render(wc.load_scene(CONFIGS / "ocean.toml", {**common, **BEAMS}), device="cpu")
    photons = wc.render(
        wc.load_scene(
            CONFIGS / "ocean.toml",
            {**common, "caustics.method": "photons", "caustics.photon_subdivisions": 8},
        ),
        device="cpu",
    )
    np.testing.assert_allclose(beams.floor_flux_w_nm, beams.transmitted_flux_w_nm, rtol=1e-3)
    l1 = np.abs(beams.floor_irradiance - photons.floor_irradiance).sum() / photons.floor_irradiance.sum()
    assert l1 < 0.06


@wp.kernel
def _count_inside(tri: wp.array[wp.vec2], points: wp.array[wp.vec2], counts: wp.array[wp.int32]):
    i = wp.tid()
    total = int(0)  # noqa: UP018 (a Warp loop variable needs its type)
    for t in range(tri.shape[0] // 3):
        inside, lam = beam_kernels.inside_triangle(tri[3 * t], tri[3 * t + 1], tri[3 * t + 2], points[i])
        if inside:
            total += 1
    counts[i] = total


def test_points_on_shared_edges_and_vertices_count_in_exactly_one_beam():
    """The watertight inside test: a 4×4 grid of quads split as the surface is (both windings), with
    query points on the grid's vertices, on its edges and diagonals and inside its cells: every
    point inside the grid lies in exactly one triangle."""
    tris = []
    for j in range(4):
        for i in range(4):
            a, b, c, d = (i, j), (i + 1, j), (i, j + 1), (i + 1, j + 1)
            tris += [a, b, d, a, d, c] if (i + j) % 2 == 0 else [a, d, b, a, c, d]  # mixed windings
    q = np.arange(0, 17) * 0.25
    pts = np.stack(np.meshgrid(q, q), -1).reshape(-1, 2)
    pts = pts[np.all((pts > 0) & (pts < 4), axis=1)]  # the grid's border belongs to no neighbour
    counts = wp.zeros(len(pts), dtype=wp.int32, device="cpu")
    wp.launch(
        _count_inside,
        dim=len(pts),
        inputs=[
            wp.array(np.asarray(tris, np.float32), dtype=wp.vec2, device="cpu"),
            wp.array(pts.astype(np.float32), dtype=wp.vec2, device="cpu"),
        ],
        outputs=[counts],
        device="cpu",
    )
    assert np.all(counts.numpy() == 1)


def test_adaptive_beams_follow_the_waves_from_frame_to_frame():
    """One Renderer, frames at several times: the adaptive leaves change with the waves, the buffers
    are reused, and every frame keeps its flux (slots past a frame's beams carry nothing)."""
    renderer = wc.Renderer(
        wc.load_scene(
            CONFIGS / "ocean.toml",
            {
                **BEAMS,
                "caustics.beam_levels": 2,
                "water.resolution": 64,
                "caustics.map_resolution": 64,
                "optics.water_type": "none",
                "optics.wavelengths": "rgb",
            },
        ),
        "cpu",
    )
    counts = []
    for t in (0.0, 0.7, 1.4, 0.2):
        r = renderer.render(t)
        counts.append(r.beam_stats["beams"])
        np.testing.assert_allclose(r.floor_flux_w_nm, r.transmitted_flux_w_nm, rtol=1e-6)
    assert len(set(counts)) > 1


def test_soft_fade_scales_a_chord_by_its_near_faces_distance_to_the_receiver():
    """Liktor & Dachsbacher 2011 §5.2 (caustics.beam_soft_fade_m): a camera 0.5 m above a black
    floor looks straight down under a zenith sun, so each ray runs inside one vertical beam from the
    camera (the chord's near face, s = 0) to the floor: with a fade of F its shaft is scaled by
    min(depth / F, 1), the G-buffer's depth to the floor. Off (0, the default) is the unfaded image
    to the bit; a fade shorter than the floor's distance changes nothing; a longer one only removes
    light."""
    view = {"floor.albedo": 0.0, "camera.enabled": True, "camera.position_m": [0.1, 0.1, -1.0],
            "camera.look_at_m": [0.1, 0.1, -2.0], "camera.up": [0.0, 1.0, 0.0], "camera.fov_deg": 10.0,
            "camera.width": 16, "camera.height": 16, "water.resolution": 16, "sun.angular_diameter_deg": 0.0}
    images = {}
    for fade in (0.0, 0.25, 1.0):
        scene = _flat(90.0, 1.5, "clear_ocean", **view, **{"caustics.beam_soft_fade_m": fade})
        result = wc.render(scene, device="cpu")
        images[fade] = result.camera_radiance.astype(np.float64)
        depth = result.camera_gbuffer["depth"]
    default = wc.render(_flat(90.0, 1.5, "clear_ocean", **view), device="cpu")  # the key left out
    np.testing.assert_array_equal(default.camera_radiance, images[0.0].astype(np.float32))
    assert np.all(images[0.0] > 0.0) and np.all(np.isfinite(depth)) and depth.max() < 0.51
    np.testing.assert_allclose(images[0.25], images[0.0], rtol=1e-6)  # every floor is 0.5 m away
    np.testing.assert_allclose(images[1.0], images[0.0] * np.minimum(depth / 1.0, 1.0)[None], rtol=1e-4)
