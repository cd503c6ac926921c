"""Water types: the thesis's published numbers, the jerlov package's values, Jerlov's Kd table."""

import csv
from pathlib import Path

import numpy as np
import pytest

import warpcaustics as wc
from warpcaustics.config import JerlovSource, OpticsConfig, WaterType
from warpcaustics.optics import spectra

from helpers import SHARED_WATER_DATA, fresnel_t_angles


@pytest.mark.parametrize(("water_type", "published_b"), [
    (WaterType.CLEAR_OCEAN, (0.028, 0.035, 0.039)),
    (WaterType.COASTAL_OCEAN, (0.17, 0.20, 0.234)),
    (WaterType.TURBID_HARBOR, (0.71, 0.82, 0.96)),
])
def test_thesis_types_reproduce_their_published_numbers(water_type, published_b):
    """At 720, 550 and 450 nm the thesis types give exactly a = (1.169, 0.0638, 0.0150) 1/m and
    their published b (the numbers as quoted in issue 4, typed here independently of the code)."""
    a, b = spectra.thesis_coefficients(water_type, np.array([720.0, 550.0, 450.0]))
    np.testing.assert_allclose(a, [1.169, 0.0638, 0.0150], rtol=1e-12)
    np.testing.assert_allclose(b, published_b, rtol=1e-12)


@pytest.mark.parametrize(("name", "source"), [
    ("I", "solonenko2015"), ("IA", "solonenko2015"), ("IB", "williamson2022"), ("II", "williamson2022"),
    ("III", "williamson2022"), ("1C", "williamson2022"), ("3C", "williamson2022"),
    ("5C", "williamson2022"), ("7C", "solonenko2015"), ("9C", "solonenko2015"),
    ("IB", "solonenko2015"), ("II", "solonenko2015")])
def test_jerlov_types_are_the_packages_values(name, source):
    """jerlov_<name> over 1 nm bins equals the jerlov package's a and b at the bin centres (its own
    interpolation; the bin average of a piecewise-linear curve differs only in bins holding a node);
    ``auto`` takes measured Williamson 2022 values where they exist, else Solonenko 2015."""
    import warnings

    import jerlov

    bins = spectra.SpectralBins.uniform(400.0, 700.0, 300)
    auto = source == ("williamson2022" if name in ("IB", "II", "III", "1C", "3C", "5C") else "solonenko2015")
    optics = OpticsConfig(water_type=WaterType(f"jerlov_{name}"),
                          jerlov_source=JerlovSource("auto" if auto else source))
    ours = spectra.water_optics(optics, bins)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        water = jerlov.water(name, source=source)
        a, b = water.a(bins.centres_nm), water.b(bins.centres_nm)
    np.testing.assert_allclose(ours.absorption_per_m, a, rtol=2e-3)
    np.testing.assert_allclose(ours.scattering_per_m, b, rtol=2e-3)


def test_jerlov_package_kd_matches_jerlov_1976_table():
    """The jerlov package's Kd (source jerlov1976) equals Jerlov (1976) Table XXVII as transcribed in
    shared/data (`kd_jerlov_1976_tableXXVII.csv`), every type at every printed wavelength."""
    import warnings

    import jerlov

    table = SHARED_WATER_DATA / "kd_jerlov_1976_tableXXVII.csv"
    if not table.exists():
        pytest.skip("shared/data not beside this checkout")
    rows = list(csv.DictReader(table.open()))
    columns = {"I": "Kd_I_per_m", "IA": "Kd_IA_per_m", "IB": "Kd_IB_per_m", "II": "Kd_II_per_m",
               "III": "Kd_III_per_m", "1C": "Kd_C1_per_m", "3C": "Kd_C3_per_m", "5C": "Kd_C5_per_m",
               "7C": "Kd_C7_per_m", "9C": "Kd_C9_per_m"}
    compared = 0
    for name, column in columns.items():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            water = jerlov.water(name, source="jerlov1976")
        for row in rows:
            if row[column] in ("", "nan"):
                continue
            wl = float(row["wavelength_nm"])
            assert water.kd(np.array([wl]))[0] == pytest.approx(float(row[column]), rel=1e-9), (name, wl)
            compared += 1
    assert compared > 100


@pytest.mark.parametrize("water_type", ["clear_ocean", "turbid_harbor", "jerlov_IB", "jerlov_5C"])
def test_beer_lambert_per_wavelength_for_water_types(water_type, device):
    """Still water over each water type: every band follows E_sun cosθ T(θ) exp(−c(λ) D / cosθ_t)
    against float64 (1e-5: float32 exponentials and flux sums)."""
    depth = 3.0
    scene = wc.load_scene(None, {"water.model": "flat", "water.resolution": 16, "water.extent_m": 4.0,
                                 "caustics.map_resolution": 16, "sun.elevation_deg": 50.0,
                                 "floor.depth_m": depth, "optics.water_type": water_type})
    result = wc.render(scene, device=device)
    theta = np.radians(40.0)
    cos_t = np.sqrt(1 - (np.sin(theta) / 1.333) ** 2)
    expected = (result.sun_irradiance * np.cos(theta) * fresnel_t_angles(np.array([theta]), 1.0, 1.333)[0]
                * np.exp(-result.attenuation_per_m * depth / cos_t))
    np.testing.assert_allclose(result.floor_irradiance.mean(axis=(1, 2)), expected, rtol=1e-5)


def test_iops_are_colour_spectral_distributions_on_the_render_shape():
    """The render's a, b, c are colour-science SpectralDistributions on its bins (a regular shape
    for equal bins, the listed wavelengths otherwise) holding the arrays the kernels used, and a bin
    average through colour's linear interpolator equals a float64 numpy one (1e-12)."""
    colour = pytest.importorskip("colour")
    scene = wc.load_scene(None, {"water.model": "flat", "water.resolution": 8, "caustics.map_resolution": 8,
                                 "optics.water_type": "jerlov_IB"})
    result = wc.render(scene, device="cpu")
    iops = result.water_iops()
    assert all(isinstance(sd, colour.SpectralDistribution) for sd in iops.values())
    width = result.bin_widths_nm[0]
    assert iops["c"].shape == colour.SpectralShape(result.wavelengths_nm[0], result.wavelengths_nm[-1], width)
    np.testing.assert_array_equal(iops["c"].values, result.attenuation_per_m)
    np.testing.assert_allclose(iops["a"].values + iops["b"].values, iops["c"].values, rtol=1e-15)
    listed_cfg = wc.config.WavelengthConfig(list_nm=(450.0, 510.0, 640.0))
    listed = spectra.bins_for(OpticsConfig(wavelengths=listed_cfg))
    assert list(spectra.water_optics(OpticsConfig(), listed).distributions(listed)["a"].wavelengths) == [
        450.0, 510.0, 640.0]
    one = wc.render(wc.load_scene(None, {"water.model": "flat", "water.resolution": 8,
                                         "caustics.map_resolution": 8, "optics.wavelengths": [510.0]}),
                    device="cpu").water_iops()["c"]  # one band: its value across its bin
    assert list(one.wavelengths) == [505.0, 515.0] and one[510.0] == pytest.approx(one.values[0])
    wl, aw = spectra.pure_absorption_table()
    bins = spectra.SpectralBins.uniform(412.0, 688.0, 23)
    n = int(np.ceil(bins.widths_nm[0] * 10))  # the midpoint rule's 10 points per nm
    midpoint = [np.interp(lo + (np.arange(n) + 0.5) * (hi - lo) / n, wl, aw).mean()
                for lo, hi in zip(bins.edges_nm[:-1], bins.edges_nm[1:])]
    np.testing.assert_allclose(bins.average(wl, aw, "Pope & Fry"), midpoint, rtol=1e-12)
    # and the rule against the exact integral of the interpolant (trapezoids on its knots): 1e-4
    exact = []
    for lo, hi in zip(bins.edges_nm[:-1], bins.edges_nm[1:]):
        x = np.unique(np.concatenate([[lo, hi], wl[(wl > lo) & (wl < hi)]]))
        exact.append(np.trapezoid(np.interp(x, wl, aw), x) / (hi - lo))
    np.testing.assert_allclose(bins.average(wl, aw, "Pope & Fry"), exact, rtol=1e-4)


def test_jerlov_source_without_the_type_is_a_clear_error():
    """Asking Williamson 2022 for a type it does not have names the types it has."""
    with pytest.raises(wc.WarpcausticsError, match="has IB, II, III, 1C, 3C, 5C"):
        wc.load_scene(None, {"optics.water_type": "jerlov_I", "optics.jerlov_source": "williamson2022"})


def test_bio_optical_model_terms():
    """Case-1 water: with no chlorophyll and no CDOM it is pure seawater; the particle absorption at a
    tabulated wavelength is A_p·Chl^E_p of Bricaud et al. 1998 (read here from shared/data), CDOM adds
    a(440)·e^(−S(λ−440)), and particle scattering adds 0.416·Chl^0.766 (Morel & Maritorena 2001)."""
    table = SHARED_WATER_DATA / "ap_aph_bricaud_1998_Ap_Ep_Aphi_Ephi.csv"
    if not table.exists():
        pytest.skip("shared/data not beside this checkout")
    row = next(r for r in csv.DictReader(table.open()) if r["wavelength_nm"] == "440")
    lam = np.array([440.0, 550.0])
    a0, b0 = spectra.bio_optical_coefficients(0.0, 0.0, 0.0176, lam)
    np.testing.assert_allclose(a0, np.interp(lam, *spectra.pure_absorption_table()), rtol=1e-12)
    np.testing.assert_allclose(b0, np.interp(lam, *spectra.pure_scattering_table()), rtol=1e-12)
    chl, cdom, slope = 2.0, 0.05, 0.015
    a, b = spectra.bio_optical_coefficients(chl, cdom, slope, lam)
    particles_440 = float(row["Ap"]) * chl ** float(row["Ep"])
    assert a[0] - a0[0] == pytest.approx(particles_440 + cdom, rel=1e-9)
    assert b - b0 == pytest.approx(np.full(2, 0.416 * chl**0.766), rel=1e-9)
    a_cdom_only, _ = spectra.bio_optical_coefficients(0.0, cdom, slope, lam)
    assert a_cdom_only[1] - a0[1] == pytest.approx(cdom * np.exp(-slope * 110.0), rel=1e-9)


def test_more_chlorophyll_darkens_the_floor():
    """The floor under greener water receives less light in every band (more absorption and
    scattering out of the beam)."""
    base = {"water.model": "flat", "water.resolution": 8, "caustics.map_resolution": 8,
            "floor.depth_m": 10.0, "optics.water_type": "bio_optical"}
    clear = wc.render(wc.load_scene(None, {**base, "optics.chlorophyll_mg_m3": 0.05}), device="cpu")
    green = wc.render(wc.load_scene(None, {**base, "optics.chlorophyll_mg_m3": 5.0}), device="cpu")
    assert np.all(green.floor_irradiance.mean(axis=(1, 2)) < clear.floor_irradiance.mean(axis=(1, 2)))


def test_shipped_data_are_the_shared_files_and_load_unchanged():
    """Every CSV shipped in warpcaustics/data is byte-identical to its source in shared/data (where
    the provenance is written), and the loaders return the CSV's own numbers."""
    data = Path(spectra.DATA_DIR)
    if not SHARED_WATER_DATA.exists():
        pytest.skip("shared/data not beside this checkout")
    shipped = sorted(data.glob("*.csv"))
    assert len(shipped) >= 6
    shared = SHARED_WATER_DATA.parent  # water/ and sky/ (the CIE standard general skies)
    for path in shipped:
        (source,) = [f for f in (shared / "water" / path.name, shared / "sky" / path.name) if f.exists()]
        assert path.read_bytes() == source.read_bytes(), path.name
    rows = list(csv.DictReader((SHARED_WATER_DATA / "aw_pope_fry_1997.csv").open()))
    wl, a = spectra.pure_absorption_table()
    np.testing.assert_array_equal(wl, [float(r["wavelength_nm"]) for r in rows])
    np.testing.assert_array_equal(a, [float(r["a_w_per_m"]) for r in rows])
    rows = list(csv.DictReader((SHARED_WATER_DATA / "solar_astm_g173_03.csv").open()))
    wl, e = spectra.sun_table()
    np.testing.assert_array_equal(e, [float(r["E_direct_circumsolar_W_m2_nm"]) for r in rows])
