"""Spectral sampling, the sun's spectrum and the water's attenuation, as bin averages.

``optics.wavelengths = {min_nm, max_nm, bins}`` means K equal bins; ``wavelengths_nm`` are the bin
centres and every quantity is the average over its bin of the linear interpolant of its source
table. Sources (files under ``warpcaustics/data/``, provenance in its README):

- sun: ASTM G173-03 direct + circumsolar spectral irradiance [W m^-2 nm^-1] (SMARTS 2.9.2),
  on a plane perpendicular to the beam;
- ``pure`` water absorption: Pope & Fry (1997), Appl. Opt. 36, 8710 [1/m];
- ``pure`` water scattering: Zhang, Hu & He (2009), Opt. Express 17, 5698, seawater at 35 PSU and
  20 °C [1/m];
- ``clear_ocean``, ``coastal_ocean``, ``turbid_harbor``: the de la Fuente thesis's three types
  (see ``thesis_coefficients``);
- ``jerlov_*``: a and b of the Jerlov types from the ``jerlov`` package (Solonenko & Mobley 2015
  or Williamson & Hollins 2022, ``optics.jerlov_source``);
- ``none``: c = 0 (validation);
- refractive index n(λ) of seawater relative to air: Quan & Fry (1995), Appl. Opt. 34, 3477,
  ``n = n0 + (n1 + n2 T + n3 T²) S + n4 T² + (n5 + n6 S + n7 T)/λ + n8/λ² + n9/λ³`` (λ in nm,
  T in °C, S in ‰), coefficients from ``data/n_water_quan_fry_1995_coefficients.csv``.
"""

from __future__ import annotations

import functools
import math
import warnings
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from warpcaustics.config import OpticsConfig, SunConfig, SunSpectrum, WaterType
from warpcaustics.errors import ConfigError

DATA_DIR = Path(__file__).resolve().parents[1] / "data"
_SAMPLES_PER_NM = 10  # integration points per nm for bin averages of linear interpolants


@functools.cache
def colour_science():
    """The ``colour`` module of colour-science, imported on first use so that ``import warpcaustics``
    stays light; the warnings it gives on import (optional packages it lacks) are silenced."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import colour
    return colour


@functools.cache
def _table(name: str, column: str) -> tuple[np.ndarray, np.ndarray]:
    path = DATA_DIR / name
    header = path.read_text(encoding="utf-8").splitlines()[0].split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    return data[:, 0], data[:, header.index(column)]


def sun_table() -> tuple[np.ndarray, np.ndarray]:
    return _table("solar_astm_g173_03.csv", "E_direct_circumsolar_W_m2_nm")


def pure_absorption_table() -> tuple[np.ndarray, np.ndarray]:
    return _table("aw_pope_fry_1997.csv", "a_w_per_m")


def pure_scattering_table() -> tuple[np.ndarray, np.ndarray]:
    return _table("bw_zhang2009_and_morel1974_computed.csv", "b_sw_ZHH2009_T20_S35_per_m")


@dataclass(frozen=True)
class SpectralBins:
    """K wavelength bins: equal bins whose values are bin averages, or listed wavelengths whose
    values are point samples (their bins only give the widths Δλ used in integrals)."""

    edges_nm: np.ndarray
    """(K+1,) bin edges [nm]."""
    samples_nm: np.ndarray | None = None
    """(K,) listed wavelengths [nm] for point sampling; None for bin averages."""

    @classmethod
    def uniform(cls, min_nm: float, max_nm: float, bins: int) -> SpectralBins:
        return cls(np.linspace(min_nm, max_nm, bins + 1))

    @classmethod
    def at(cls, wavelengths_nm: np.ndarray) -> SpectralBins:
        """Point samples at listed wavelengths; each bin (for Δλ) reaches half-way to its neighbours,
        the outer bins are symmetric about their wavelengths (a single wavelength gets 10 nm)."""
        c = np.asarray(wavelengths_nm, dtype=np.float64)
        if len(c) == 1:
            return cls(np.array([c[0] - 5.0, c[0] + 5.0]), c)
        inner = 0.5 * (c[1:] + c[:-1])
        return cls(np.concatenate([[2 * c[0] - inner[0]], inner, [2 * c[-1] - inner[-1]]]), c)

    @property
    def centres_nm(self) -> np.ndarray:
        """The wavelengths the values belong to: listed wavelengths, or the bin centres."""
        if self.samples_nm is not None:
            return self.samples_nm
        return 0.5 * (self.edges_nm[1:] + self.edges_nm[:-1])

    @property
    def widths_nm(self) -> np.ndarray:
        return np.diff(self.edges_nm)

    @property
    def span_nm(self) -> tuple[float, float]:
        """Wavelengths a table must cover: the bin edges, or the listed wavelengths."""
        if self.samples_nm is not None:
            return float(self.samples_nm[0]), float(self.samples_nm[-1])
        return float(self.edges_nm[0]), float(self.edges_nm[-1])

    def fine_grid(self) -> np.ndarray:
        """A 0.1 nm grid over the span (endpoints exact), for sampling functions of λ."""
        lo, hi = self.span_nm
        return np.linspace(lo, hi, max(2, int(round((hi - lo) * 10)) + 1))

    def check_covered(self, lo_nm: float, hi_nm: float, what: str) -> None:
        lo, hi = self.span_nm
        if lo < lo_nm or hi > hi_nm:
            raise ConfigError(
                f"optics.wavelengths = {lo:g}..{hi:g} nm lies outside the {what} data "
                f"({lo_nm:g}..{hi_nm:g} nm); narrow optics.wavelengths")

    def average(self, wavelength_nm: np.ndarray, values: np.ndarray, what: str) -> np.ndarray:
        """Per bin: the average over the bin of the table as a colour-science spectral distribution
        (linear interpolation, :func:`spectral_distribution`), or its value at the listed
        wavelength."""
        self.check_covered(wavelength_nm[0], wavelength_nm[-1], what)
        sd = spectral_distribution(wavelength_nm, values, what)
        if self.samples_nm is not None:
            return np.asarray(sd[self.samples_nm], dtype=np.float64)
        out = np.empty(len(self.edges_nm) - 1)
        for k, (a, b) in enumerate(zip(self.edges_nm[:-1], self.edges_nm[1:])):
            n = max(2, int(np.ceil((b - a) * _SAMPLES_PER_NM)))
            x = a + (np.arange(n) + 0.5) * (b - a) / n  # midpoint rule on a fine grid
            out[k] = np.asarray(sd[x], dtype=np.float64).mean()
        return out

    def distribution(self, values: np.ndarray, name: str):
        """(K,) per-bin values as a ``colour.SpectralDistribution`` on the render's wavelengths
        (bin centres, or the listed wavelengths): the form colour-science's own functions take. A
        single band, which colour-science cannot hold as one point, is its value at both edges of
        its bin."""
        values = np.asarray(values, dtype=np.float64)
        if len(values) == 1:
            return spectral_distribution(self.edges_nm, np.repeat(values, 2), name)
        return spectral_distribution(self.centres_nm, values, name)


def spectral_distribution(wavelength_nm: np.ndarray, values: np.ndarray, name: str):
    """A table as a ``colour.SpectralDistribution`` interpolated linearly between its points (the
    sources' own resolution, nothing invented between them; colour-science's default for regular
    tables, Sprague, is a higher-order polynomial that can overshoot between the points)."""
    colour = colour_science()
    return colour.SpectralDistribution(
        np.asarray(values, dtype=np.float64),
        np.asarray(wavelength_nm, dtype=np.float64),
        name=name,
        interpolator=colour.LinearInterpolator,
    )


@dataclass(frozen=True)
class WaterOptics:
    """Per-bin optical properties used by a render."""

    absorption_per_m: np.ndarray
    scattering_per_m: np.ndarray

    @property
    def attenuation_per_m(self) -> np.ndarray:
        """Beam attenuation c = a + b [1/m]: scattered light leaves the direct beam."""
        return self.absorption_per_m + self.scattering_per_m

    def distributions(self, bins: SpectralBins) -> dict:
        """a, b and c [1/m] as ``colour.SpectralDistribution``s aligned to the render's bins."""
        return {
            "a": bins.distribution(self.absorption_per_m, "absorption a [1/m]"),
            "b": bins.distribution(self.scattering_per_m, "scattering b [1/m]"),
            "c": bins.distribution(self.attenuation_per_m, "beam attenuation c [1/m]"),
        }


def bins_for(optics: OpticsConfig) -> SpectralBins:
    """The render's bins: K equal bins, or bins around an explicit list of centres."""
    w = optics.wavelengths
    if w.list_nm:
        return SpectralBins.at(np.array(w.list_nm, dtype=np.float64))
    return SpectralBins.uniform(w.min_nm, w.max_nm, w.bins)


def sun_irradiance(bins: SpectralBins, sun: SunConfig | None = None,
                   base_dir: Path | None = None) -> np.ndarray:
    """Solar spectral irradiance per bin on a plane perpendicular to the beam [W m^-2 nm^-1].

    The shape is ASTM G173-03 direct + circumsolar (absolute), CIE D65 (colour-science), a
    blackbody (Planck's law through colour-science) or a user CSV; the scale makes Σ E Δλ equal
    ``sun.irradiance_w_m2``, or, when that is 0, the ASTM G173 integral over the same bins.
    """
    astm = bins.average(*sun_table(), what="ASTM G173 solar")
    if sun is None:
        return astm
    if sun.spectrum is SunSpectrum.ASTM_G173:
        shape = astm
    elif sun.spectrum is SunSpectrum.D65:
        d65 = colour_science().SDS_ILLUMINANTS["D65"]
        shape = bins.average(d65.wavelengths, d65.values, what="CIE D65")
    elif sun.spectrum is SunSpectrum.BLACKBODY:
        fine = bins.fine_grid()
        planck = colour_science().colorimetry.planck_law(fine * 1e-9, sun.temperature_k)
        shape = bins.average(fine, planck, what="Planck")
    else:
        shape = bins.average(*read_spectrum_csv(sun.file, base_dir), what=f"sun.file {sun.file!r}")
    total = sun.irradiance_w_m2 if sun.irradiance_w_m2 > 0 else float(np.sum(astm * bins.widths_nm))
    integral = float(np.sum(shape * bins.widths_nm))
    if not integral > 0:
        raise ConfigError(f"sun.spectrum = {sun.spectrum.value!r} has no energy in optics.wavelengths")
    return shape * (total / integral)


ASTM_G173_SUN_ZENITH_DEG = math.degrees(math.acos(1.0 / 1.5))
"""The sun's zenith angle of ASTM G173-03's reference conditions: air mass 1.5 = 1 / cos Z (48.19°)."""
ASTM_G173_TILT_DEG = 37.0
"""The tilt of its global spectrum's receiving plane, facing the sun (data/README.md)."""


def sky_diffuse_shape(bins: SpectralBins) -> np.ndarray:
    """The skylight's spectral shape per bin: the diffuse part of ASTM G173-03's global tilt
    spectrum, global − direct × cos(incidence), the incidence on its sun-facing 37° plane being the
    sun's zenith (48.19° at AM1.5) less the tilt, 11.19° (relative units; the ground-reflected light
    on that plane is part of it)."""
    wavelength, global_tilt = _table("solar_astm_g173_03.csv", "E_global_tilt37_W_m2_nm")
    _, direct = sun_table()
    incidence = math.radians(ASTM_G173_SUN_ZENITH_DEG - ASTM_G173_TILT_DEG)
    return bins.average(wavelength, global_tilt - direct * math.cos(incidence), what="ASTM G173 diffuse sky")


MAX_SPECTRUM_VALUE = 1e30
"""The largest wavelength or value a spectrum file may hold: past it the bins' integrals overflow."""


def _numbers_only(line: str) -> bool:
    """Whether a CSV line is data (every cell a number, the first a wavelength above 0) rather than a
    header (pandas writes column names 0,1 for an unnamed table)."""
    try:
        cells = [float(cell) for cell in line.split(",")]
    except ValueError:
        return False
    return bool(line.strip()) and cells[0] > 0.0


def read_spectrum_csv(name: str, base_dir: Path | None, key: str = "sun.file",
                      quantity: str = "irradiance", upper: float = np.inf) -> tuple[np.ndarray, np.ndarray]:
    """A two-column CSV (header line, then wavelength [nm], value): one-line errors naming ``key``."""
    from warpcaustics.io.files import input_file

    path = input_file(key, name, base_dir, f"a CSV of wavelength_nm,{quantity}")
    try:
        with open(path, encoding="utf-8-sig") as fh:  # an editor's byte-order mark is not a cell
            first = fh.readline()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # an empty file: numpy warns, then we say it in one line
            data = np.loadtxt(path, delimiter=",", skiprows=0 if _numbers_only(first) else 1, ndmin=2,
                              encoding="utf-8-sig")
    except (OSError, ValueError) as exc:
        reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else exc
        raise ConfigError(f"{key} = {str(path)!r} cannot be read as CSV (header line, then "
                          f"wavelength_nm,{quantity}): {reason}") from None
    upper = min(upper, MAX_SPECTRUM_VALUE)
    if data.shape[1] > 2:  # which of the values is meant? (ASTM G173, say, holds three spectra)
        raise ConfigError(f"{key} = {str(path)!r} has {data.shape[1]} columns; it needs two, wavelength_nm,"
                          f"{quantity}: keep the one {quantity} column you mean")
    if data.shape[1] < 2 or len(data) < 2 or not np.all(np.diff(data[:, 0]) > 0) \
            or not np.all(np.isfinite(data[:, :2])) or np.any(data[:, 1] < 0) or np.any(data[:, 1] > upper) \
            or data[0, 0] <= 0.0 or np.any(data[:, 0] > MAX_SPECTRUM_VALUE):
        bound = f" and at most {upper:g}"
        raise ConfigError(f"{key} = {str(path)!r} needs two columns, wavelengths [nm] above 0, strictly "
                          f"increasing and finite, non-negative {quantity} values{bound}")
    return data[:, 0], data[:, 1]


THESIS_NODES_NM = (450.0, 550.0, 720.0)
"""Wavelengths at which the three water types of the de la Fuente thesis are given."""
THESIS_ABSORPTION_PER_M = (0.0150, 0.0638, 1.169)
"""Pure-water absorption of all three thesis types at THESIS_NODES_NM [1/m] (quoted in issue 4
from the de la Fuente thesis, which the project's seeds cite)."""
THESIS_SCATTERING_PER_M = {
    WaterType.CLEAR_OCEAN: (0.039, 0.035, 0.028),
    WaterType.COASTAL_OCEAN: (0.234, 0.20, 0.17),
    WaterType.TURBID_HARBOR: (0.96, 0.82, 0.71),
}
"""Scattering of each thesis type at THESIS_NODES_NM [1/m] (same source; the issue lists them
for 720/550/450 nm, reversed here into ascending wavelength)."""

JERLOV_NAMES = {
    WaterType.JERLOV_I: "I", WaterType.JERLOV_IA: "IA", WaterType.JERLOV_IB: "IB",
    WaterType.JERLOV_II: "II", WaterType.JERLOV_III: "III", WaterType.JERLOV_1C: "1C",
    WaterType.JERLOV_3C: "3C", WaterType.JERLOV_5C: "5C", WaterType.JERLOV_7C: "7C",
    WaterType.JERLOV_9C: "9C",
}
"""Our names of the Jerlov types → the ``jerlov`` package's names."""


def thesis_coefficients(water_type: WaterType,
                        wavelength_nm: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """a(λ), b(λ) of a thesis type: exactly the published values at 450, 550 and 720 nm.

    The thesis gives nothing in between, so: absorption follows the shape of Pope & Fry's
    pure-water absorption, scaled by a factor interpolated linearly between the nodes' ratios
    (held at the end ratios outside), so that it passes through the three published values;
    scattering is a power law in λ between neighbouring nodes (log-log interpolation, the end
    segments extended), the usual spectral form of particle scattering.
    """
    lam = np.asarray(wavelength_nm, dtype=np.float64)
    pf_lam, pf_a = pure_absorption_table()
    nodes = np.array(THESIS_NODES_NM)
    ratio = np.array(THESIS_ABSORPTION_PER_M) / np.interp(nodes, pf_lam, pf_a)
    a = np.interp(lam, pf_lam, pf_a) * np.interp(lam, nodes, ratio)
    log_b = np.log(np.array(THESIS_SCATTERING_PER_M[water_type]))
    x = np.log(lam)
    seg = np.clip(np.searchsorted(nodes, lam) - 1, 0, len(nodes) - 2)
    x0, x1 = np.log(nodes[seg]), np.log(nodes[seg + 1])
    b = np.exp(log_b[seg] + (x - x0) * (log_b[seg + 1] - log_b[seg]) / (x1 - x0))
    return a, b


def jerlov_water(water_type: WaterType, source: str):
    """The ``jerlov`` package's Water object for one of our Jerlov type names."""
    import jerlov

    name = JERLOV_NAMES[water_type]
    if source == "auto":
        # Measured a and b where they exist (the package's own default), else the Kd inversion.
        source = "williamson2022" if name in jerlov.SOURCES["williamson2022"].water_types else "solonenko2015"
    covered = jerlov.SOURCES[source].water_types
    if name not in covered:
        raise ConfigError(f"optics.water_type = {water_type.value!r} is not in the {source} data "
                          f"(it has {', '.join(covered)}); set optics.jerlov_source = 'solonenko2015'")
    return jerlov.water(name, source=source)


def bricaud_1998_table() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(λ, A_p, E_p) of Bricaud et al. (1998): particle absorption a_p = A_p·Chl^E_p."""
    wl, a_p = _table("ap_aph_bricaud_1998_Ap_Ep_Aphi_Ephi.csv", "Ap")
    _, e_p = _table("ap_aph_bricaud_1998_Ap_Ep_Aphi_Ephi.csv", "Ep")
    return wl, a_p, e_p


@functools.cache
def _bio_optical_parameter(model: str, name: str) -> float:
    import csv

    with (DATA_DIR / "bio_optical_model_parameters.csv").open(encoding="utf-8") as f:
        for row in csv.DictReader(f):
            if row["model"].startswith(model) and row["parameter"] == name:
                return float(row["value_or_expression"])
    raise KeyError(f"{model} {name}")  # pragma: no cover - the shipped file has them


def bio_optical_coefficients(chlorophyll_mg_m3: float, cdom_440_per_m: float, cdom_slope_per_nm: float,
                             wavelength_nm: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """a(λ), b(λ) of case-1 water with chlorophyll and CDOM [1/m].

    a = a_w (Pope & Fry 1997) + A_p(λ)·Chl^E_p(λ) (particles, Bricaud et al. 1998)
        + a_CDOM(440)·exp(−S(λ − 440));
    b = b_w (Zhang et al. 2009, seawater) + b_p, with b_p(550) = 0.416·Chl^0.766 (Morel & Maritorena
    2001). The sourced data give no spectral shape for b_p itself (their exponent ν belongs to the
    backscattering ratio), so b_p is held at its 550 nm value.
    """
    lam = np.asarray(wavelength_nm, dtype=np.float64)
    wl, a_p, e_p = bricaud_1998_table()
    particles = 0.0
    if chlorophyll_mg_m3 > 0:
        particles = np.interp(lam, wl, a_p) * chlorophyll_mg_m3 ** np.interp(lam, wl, e_p)
    a = (np.interp(lam, *pure_absorption_table()) + particles
         + cdom_440_per_m * np.exp(-cdom_slope_per_nm * (lam - 440.0)))
    coefficient = _bio_optical_parameter("Morel & Maritorena 2001", "bp550_coefficient")
    exponent = _bio_optical_parameter("Morel & Maritorena 2001", "bp550_exponent")
    b = np.interp(lam, *pure_scattering_table()) + coefficient * chlorophyll_mg_m3**exponent
    return a, b


def water_optics(optics: OpticsConfig, bins: SpectralBins) -> WaterOptics:
    """Absorption and scattering of ``optics.water_type``, averaged over each bin."""
    water_type = optics.water_type
    jerlov_source = optics.jerlov_source.value
    if water_type is WaterType.NONE:
        zero = np.zeros(len(bins.centres_nm))
        return WaterOptics(zero, zero.copy())
    if water_type is WaterType.PURE:
        a = bins.average(*pure_absorption_table(), what="Pope & Fry 1997 absorption")
        b = bins.average(*pure_scattering_table(), what="Zhang 2009 scattering")
        return WaterOptics(a, b)
    lo_nm, hi_nm = bins.span_nm
    fine = bins.fine_grid()
    if water_type is WaterType.BIO_OPTICAL:
        if lo_nm < 400.0 or hi_nm > 700.0:
            raise ConfigError(f"optics.wavelengths = {lo_nm:g}..{hi_nm:g} nm lies outside the Bricaud "
                              f"1998 data (400..700 nm) of optics.water_type = 'bio_optical'")
        a, b = bio_optical_coefficients(optics.chlorophyll_mg_m3, optics.cdom_440_per_m,
                                        optics.cdom_slope_per_nm, fine)
        return WaterOptics(bins.average(fine, a, "bio-optical"), bins.average(fine, b, "bio-optical"))
    if water_type in THESIS_SCATTERING_PER_M:
        pf_lam = pure_absorption_table()[0]
        bins.check_covered(pf_lam[0], pf_lam[-1], "Pope & Fry 1997 absorption (the thesis types' shape)")
        a, b = thesis_coefficients(water_type, fine)
        return WaterOptics(bins.average(fine, a, "thesis"), bins.average(fine, b, "thesis"))
    water = jerlov_water(water_type, jerlov_source)
    jerlov_source = water.source.key
    bins.check_covered(*water.range_nm, f"{jerlov_source} {water_type.value}")
    with warnings.catch_warnings():
        # The package warns where its values are interpolated or extrapolated; docs/physics.md
        # lists those caveats per source.
        warnings.simplefilter("ignore")
        a = np.asarray(water.a(fine), dtype=np.float64)
        b = np.asarray(water.b(fine), dtype=np.float64)
    if not (np.all(np.isfinite(a)) and np.all(np.isfinite(b))):
        raise ConfigError(f"the {jerlov_source} data for {water_type.value} have gaps inside "
                          f"optics.wavelengths; narrow the range or choose another optics.jerlov_source")
    return WaterOptics(bins.average(fine, a, jerlov_source), bins.average(fine, b, jerlov_source))


@functools.cache
def _quan_fry_coefficients() -> dict[str, float]:
    rows = (DATA_DIR / "n_water_quan_fry_1995_coefficients.csv").read_text(encoding="utf-8").splitlines()[1:]
    return {name: float(value) for name, value in (row.split(",") for row in rows)}


def quan_fry_index(wavelength_nm: np.ndarray, salinity_psu: float, temperature_c: float) -> np.ndarray:
    """Refractive index of seawater relative to air, Quan & Fry (1995) [-]."""
    c = _quan_fry_coefficients()
    lam = np.asarray(wavelength_nm, dtype=np.float64)
    s, t = salinity_psu, temperature_c
    return (c["n0"] + (c["n1"] + c["n2"] * t + c["n3"] * t * t) * s + c["n4"] * t * t
            + (c["n5"] + c["n6"] * s + c["n7"] * t) / lam + c["n8"] / lam**2 + c["n9"] / lam**3)


def refractive_index(optics: OpticsConfig, bins: SpectralBins) -> np.ndarray:
    """(K,) refractive index per bin: Quan & Fry at the bin centres, or ``optics.ior`` throughout."""
    if optics.dispersion:
        return quan_fry_index(bins.centres_nm, optics.salinity_psu, optics.temperature_c)
    return np.full(len(bins.centres_nm), optics.ior)
