"""Irradiance statistics of floor maps, as the wave-focusing literature reports them (host, numpy).

Per frame: the mean, the coefficient of variation CV = std/mean, the probability density of E/Ē
and the fraction of the floor above ``flash_threshold``·Ē, for the band-integrated irradiance
[W m⁻²], for PAR [µmol photons m⁻² s⁻¹] and for the band at ``stats.wavelength_nm``, optionally
after averaging over a circular collector of diameter ``stats.collector_mm`` (a sensor sees the
mean over its window, not a point). Over an animation: the series E(t) at probe points, their CV,
the frequency of flashes (upward crossings of ``flash_threshold``·Ē per second) and their
spectrum. Gernez & Antoine (2009) report CV and flash statistics for an 8 mm collector.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import constants

from warpcaustics.config import StatsConfig

PAR_BAND_NM = (400.0, 700.0)
"""Photosynthetically available radiation: the photon flux from 400 to 700 nm."""

PDF_EDGES = np.linspace(0.0, 5.0, 51)
"""Bins of E/Ē for the probability density (E above 5Ē is counted in the last bin)."""

SUN_IN_VIEW = 0.1
"""A radiance sensor's texel holds the sun in its cone where the sun's part exceeds this share of the
sky's mean there (``sun_in_view`` of :func:`frame_statistics`). The whole beam is some 10³ times the
sky's light in a 4.5° cone, so a texel that takes any fair part of it counts; the threshold keeps
float32 rounding and the faintest slivers of the cone's edge from counting as sun."""


def par_weights(edges_nm: np.ndarray, band_nm: tuple[float, float] = PAR_BAND_NM) -> np.ndarray:
    """(K,) weights w_k with PAR = Σ_k E_k w_k [µmol m⁻² s⁻¹] for bin averages E_k [W m⁻² nm⁻¹]:
    w_k = ∫ λ/(h c N_A) dλ over the part of bin k inside the band (λ in m; CODATA constants from
    scipy.constants), ×1e6 for µmol, taking E constant across each bin."""
    lo = np.clip(edges_nm[:-1], *band_nm)
    hi = np.clip(edges_nm[1:], *band_nm)
    integral_nm2 = 0.5 * (hi**2 - lo**2)  # ∫ λ dλ over the overlap [nm²]
    return integral_nm2 * 1e-9 / (constants.h * constants.c * constants.Avogadro) * 1e6


def band_integrated(floor: np.ndarray, widths_nm: np.ndarray) -> np.ndarray:
    """(M, M) irradiance summed over the bands, Σ E_k Δλ_k [W m⁻²] (float64)."""
    return np.einsum("kij,k->ij", np.asarray(floor, np.float64), np.asarray(widths_nm, np.float64))


def par_map(floor: np.ndarray, edges_nm: np.ndarray) -> np.ndarray:
    """(M, M) PAR [µmol photons m⁻² s⁻¹] of a (K, M, M) floor map with bin edges ``edges_nm``."""
    return np.einsum("kij,k->ij", np.asarray(floor, np.float64), par_weights(np.asarray(edges_nm)))


def cv_without_noise(first: np.ndarray, second: np.ndarray, axis=None) -> tuple[np.ndarray, np.ndarray]:
    """(mean map, CV over ``axis``) of two maps of one field with independent noise (a Monte Carlo
    run with two seeds), the noise taken out: half the variance of their difference is one map's
    noise variance, and their mean carries half of that."""
    mean = 0.5 * (first + second)
    noise = 0.5 * (first - second).var(axis=axis)
    return mean, np.sqrt(np.maximum(mean.var(axis=axis) - 0.5 * noise, 0.0)) / mean.mean(axis=axis)


def collector_kernel(texel_m: float, diameter_m: float, supersample: int = 8) -> np.ndarray:
    """A disc of diameter ``diameter_m`` on texels of side ``texel_m``: each weight is the disc's
    share of its texel (``supersample``² points per texel), normalised to sum 1."""
    r = 0.5 * diameter_m / texel_m  # in texels
    half = int(math.ceil(r - 0.5)) if r > 0.5 else 0
    offsets = (np.arange(supersample) + 0.5) / supersample - 0.5
    centres = np.arange(-half, half + 1)
    sx = (centres[:, None] + offsets[None, :]).ravel()
    inside = (sx[:, None] ** 2 + sx[None, :] ** 2) <= r * r
    n = 2 * half + 1
    weights = inside.reshape(n, supersample, n, supersample).mean(axis=(1, 3))
    if weights.sum() == 0.0:  # a disc smaller than a sample spacing: the texel itself
        weights[half, half] = 1.0
    return weights / weights.sum()


def collector_average(field: np.ndarray, texel_m: float, diameter_m: float, *, periodic: bool) -> np.ndarray:
    """The mean of ``field`` (M, M) over a disc of ``diameter_m`` centred on each texel: a circular
    convolution on a periodic map; on a non-periodic one the disc is cut at the edges and its
    weights renormalised."""
    if diameter_m <= 0.0:
        return np.asarray(field, np.float64)
    kernel = collector_kernel(texel_m, diameter_m)
    m = field.shape[0]
    k = kernel.shape[0]
    half = k // 2
    f = np.asarray(field, np.float64)
    if periodic:
        # the disc folded onto the torus (it may be wider than the map), centred on texel (0, 0)
        folded = np.zeros((m, m))
        offsets = (np.arange(k) - half) % m
        np.add.at(folded, (offsets[:, None], offsets[None, :]), kernel)
        return np.fft.irfft2(np.fft.rfft2(f) * np.fft.rfft2(folded), s=f.shape)
    # zero-pad to avoid wrap-around; divide by the kernel's weight inside the map
    size = m + k
    pk = np.zeros((size, size))
    pk[:k, :k] = kernel
    pk = np.roll(pk, (-half, -half), axis=(0, 1))
    pkf = np.fft.rfft2(pk)
    pf = np.zeros((size, size))
    pf[:m, :m] = f
    ones = np.zeros((size, size))
    ones[:m, :m] = 1.0
    total = np.fft.irfft2(np.fft.rfft2(pf) * pkf, s=pf.shape)[:m, :m]
    norm = np.fft.irfft2(np.fft.rfft2(ones) * pkf, s=pf.shape)[:m, :m]
    return total / norm


def field_statistics(field: np.ndarray, flash_threshold: float) -> dict:
    """Mean, CV, the fraction of texels above ``flash_threshold``·mean and the probability density
    of E/Ē on :data:`PDF_EDGES` (integrates to 1)."""
    f = np.asarray(field, np.float64)
    mean = float(f.mean())
    if mean <= 0.0:
        return {"mean": mean, "cv": 0.0, "flash_fraction": 0.0, "pdf": [0.0] * (len(PDF_EDGES) - 1)}
    ratio = np.minimum(f / mean, PDF_EDGES[-1] - 1e-12)
    pdf, _ = np.histogram(ratio, bins=PDF_EDGES, density=True)
    return {
        "mean": mean,
        "cv": float(f.std() / mean),
        "flash_fraction": float(np.mean(f > flash_threshold * mean)),
        "pdf": pdf.tolist(),
    }


def tile_weights(texels: int, count: int) -> np.ndarray:
    """(count, texels) weights that average a row of ``texels`` equal texels over ``count`` equal
    intervals tiling the same length: each weight is the texel's overlap with the interval over the
    interval's length, so a texel that straddles two intervals is shared by its overlap (exact for a
    map constant over each texel)."""
    width = texels / count  # an interval in texels, not necessarily whole
    lo = np.arange(count)[:, None] * width
    left = np.arange(texels)[None, :]
    overlap = np.clip(np.minimum(lo + width, left + 1.0) - np.maximum(lo, left), 0.0, None)
    return overlap / width


def window_means(coarse: np.ndarray, count: int) -> dict:
    """Mean and CV of the means of a whole periodic patch's coarse map over its ``count`` × ``count``
    squares the size of the floor-map window (a square's edge may cross a texel: it takes the
    texel's share, :func:`tile_weights`): by the law of total variance, the patch's variance is the
    windows' mean variance within them plus this variance between them (``patch_windows`` of
    :func:`frame_statistics`)."""
    f = np.asarray(coarse, np.float64)
    rows, cols = (tile_weights(n, count) for n in f.shape[-2:])
    means = rows @ f @ cols.T
    mean = float(means.mean())
    return {"count": count * count, "mean": mean, "cv": float(means.std() / mean) if mean > 0.0 else 0.0}


def sky_parts(result, per_band: bool) -> dict:
    """{field: a function of the (K, M, M) total and sky maps giving the field's (M, M) map}: the
    band-integrated sky's part and the direct sun's (the rest), and with ``per_band`` each band's
    (``bands_sky/…``, ``bands_direct/…``, keyed as ``bands/…``)."""
    widths = result.bin_widths_nm
    parts = {"sky_irradiance_w_m2": lambda total, sky: band_integrated(sky, widths),
             "direct_irradiance_w_m2": (
                 lambda total, sky: band_integrated(total, widths) - band_integrated(sky, widths))}
    if per_band:
        for k, nm in enumerate(result.wavelengths_nm):
            parts[f"bands_sky/{nm:g}nm_w_m2_nm"] = lambda total, sky, k=k: np.asarray(sky[k], np.float64)
            parts[f"bands_direct/{nm:g}nm_w_m2_nm"] = (
                lambda total, sky, k=k: np.asarray(total[k], np.float64) - np.asarray(sky[k], np.float64))
    return parts


def patch_windows(result, views: dict | None = None, parts: dict | None = None) -> dict[str, dict]:
    """{field: :func:`window_means` of its coarse map of the whole patch} where the map is a window
    of a periodic sea whose side divides the patch's
    (:attr:`~warpcaustics.result.RenderResult.coarse_floor_irradiance`), else {}: for each of
    ``views`` ({field: a function of a (K, M, M) map giving the field's (M, M) map}, as
    :func:`frame_statistics` takes them; by default the band-integrated irradiance) and, with a sky,
    each of ``parts`` (:func:`sky_parts`; by default the band-integrated sky and direct parts)."""
    coarse = result.coarse_floor_irradiance
    if coarse is None:
        return {}
    extent = result.scene.config.water.extent_m
    count = round(extent / result.map_extent_m)
    if count < 2 or abs(count * result.map_extent_m - extent) > 1e-6 * extent:
        return {}
    widths = result.bin_widths_nm
    views = views or {"irradiance_w_m2": lambda m: band_integrated(m, widths)}
    maps = {name: view(coarse) for name, view in views.items()}
    coarse_sky = result.coarse_sky_floor_irradiance
    if coarse_sky is not None:
        parts = sky_parts(result, per_band=False) if parts is None else parts
        maps.update({name: part(coarse, coarse_sky) for name, part in parts.items()})
    return {name: window_means(f, count) for name, f in maps.items()}


def frame_statistics(result, cfg: StatsConfig) -> dict:
    """The statistics of one frame's floor map: total irradiance [W m⁻²] (with a sky, also its
    direct-sun and sky parts alone; with a radiance sensor, ``floor.view_fov_deg``, the map's ∫ L dω
    under the same names), PAR [µmol m⁻² s⁻¹] (not with a radiance sensor) and, if
    ``cfg.wavelength_nm`` is set, the band holding it [W m⁻² nm⁻¹], and with ``cfg.per_band`` every
    band (``bands``; with a sky, each band's sky and direct-sun parts too, ``bands_sky`` and
    ``bands_direct``), after the collector.
    Where the sky's map comes in two halves (``result.sky_floor_irradiance_even``), each of these
    but the direct sun's also has ``continuous_sky`` (:func:`continuous_sky_moments`, with
    its octave-band cross-powers ``band_cov``) and the frame's ``cv_continuous_sky``
    (:func:`continuous_sky_cv`). Where the map is a window of a periodic sea that tiles the patch,
    every field also has ``patch_windows``: the means over the whole patch's windows, from its
    coarse map (:func:`window_means`). With a radiance sensor and a sky, each direct-sun part also has
    ``sun_in_view``: the share of texels whose cone holds the sun (:data:`SUN_IN_VIEW`)."""
    widths = result.bin_widths_nm
    views = {"irradiance_w_m2": lambda m: band_integrated(m, widths)}
    edges = result.bins.edges_nm if result.bins is not None else None
    covered = None
    scene = getattr(result, "scene", None)
    radiance = scene is not None and bool(scene.config.floor.view_fov_deg)  # ∫ L dω: no PAR of it
    if edges is not None and edges[0] < PAR_BAND_NM[1] and edges[-1] > PAR_BAND_NM[0] and not radiance:
        views["par_umol_m2_s"] = lambda m: par_map(m, edges)
        # PAR counts only what the bins hold: say so when they cover less than 400-700 nm
        covered = [max(float(edges[0]), PAR_BAND_NM[0]), min(float(edges[-1]), PAR_BAND_NM[1])]
    band = band_index(result.wavelengths_nm, edges, cfg.wavelength_nm)
    if band is not None:
        views[f"band_{result.wavelengths_nm[band]:g}nm_w_m2_nm"] = lambda m: np.asarray(m[band], np.float64)
    if cfg.per_band:
        for k, nm in enumerate(result.wavelengths_nm):
            views[f"bands/{nm:g}nm_w_m2_nm"] = lambda m, k=k: np.asarray(m[k], np.float64)
    fields = {name: view(result.floor_irradiance) for name, view in views.items()}
    sky = result.sky_floor_irradiance
    halves = {}  # field → (its sky part, the sky's even half)
    parts = sky_parts(result, cfg.per_band)
    if sky is not None:  # the direct sun's part and the sky's, each alone
        fields.update({name: part(result.floor_irradiance, sky) for name, part in parts.items()})
        even = result.sky_floor_irradiance_even
        if even is not None:
            halves = {name: (view(sky), view(even)) for name, view in views.items()}
            halves["sky_irradiance_w_m2"] = (fields["sky_irradiance_w_m2"], band_integrated(even, widths))
    texel = result.map_extent_m / result.floor_irradiance.shape[-1]

    def collector(f: np.ndarray) -> np.ndarray:
        return collector_average(f, texel, cfg.collector_mm * 1e-3, periodic=result.map_periodic)

    out = {
        "collector_mm": cfg.collector_mm,
        "flash_threshold": cfg.flash_threshold,
        "pdf_edges": PDF_EDGES.tolist(),
        "par_band_nm": covered,
    }
    patch = patch_windows(result, views, parts)
    for name, f in fields.items():
        averaged = collector(f)
        stats = field_statistics(averaged, cfg.flash_threshold)
        if name in patch:
            stats["patch_windows"] = patch[name]
        if name in halves:
            sky_part, even_part = (collector(h) for h in halves[name])
            stats["continuous_sky"] = continuous_sky_moments(
                averaged, sky_part, even_part, extent_m=result.map_extent_m, periodic=result.map_periodic)
            stats["cv_continuous_sky"] = continuous_sky_cv([stats["continuous_sky"]])
        if radiance and sky is not None and "direct" in name:
            sky_mean = float(collector(fields[name.replace("direct", "sky")]).mean())
            stats["sun_in_view"] = float(np.mean(averaged > SUN_IN_VIEW * sky_mean))
        group, _, band_name = name.rpartition("/")
        (out.setdefault(group, {}) if group else out)[band_name] = stats
    return out


def octave_band_edges(m: int, extent_m: float) -> np.ndarray:
    """Edges [cycles per m] of octave bands of spatial frequency for an M × M map over ``extent_m``:
    from the map's fundamental 1/extent (the lowest non-zero frequency) doubling until the last band
    holds the Nyquist limit's corner, √2 M/(2 extent)."""
    top = math.sqrt(2.0) * m / (2.0 * extent_m)
    count = max(int(math.ceil(math.log2(top * extent_m))), 1)
    return np.exp2(np.arange(count + 1)) / extent_m


def cross_band_power(a: np.ndarray, b: np.ndarray, extent_m: float, *, periodic: bool) -> np.ndarray:
    """The cross-power Re(Â B̂*) of two (M, M) maps, their means taken out, summed over
    :func:`octave_band_edges` and scaled so that the bands add up to the maps' covariance over the
    texels (Parseval); ``a`` = ``b`` gives the power spectrum, which adds up to the variance. A map
    that does not repeat (a window) is tapered by a Hann window first (its edges would otherwise
    leak power into every band), the power rescaled by the taper's mean square."""
    a = np.asarray(a, np.float64) - np.mean(a)
    b = np.asarray(b, np.float64) - np.mean(b)
    m = a.shape[-1]
    scale = 1.0 / a.size**2
    if not periodic:
        hann = np.sin(np.pi * (np.arange(m) + 0.5) / m) ** 2
        taper = np.outer(hann, hann)
        a, b = a * taper, b * taper
        scale /= float(np.mean(taper**2))
    cross = (np.fft.fft2(a) * np.conj(np.fft.fft2(b))).real * scale
    k = np.fft.fftfreq(m, d=extent_m / m)
    radius = np.hypot(*np.meshgrid(k, k))
    edges = octave_band_edges(m, extent_m)
    band = np.minimum(np.digitize(radius, edges) - 1, len(edges) - 2)  # k = 0 falls below: −1
    return np.bincount(band[band >= 0], weights=cross[band >= 0], minlength=len(edges) - 1)


def continuous_sky_moments(total: np.ndarray, sky: np.ndarray, even: np.ndarray, *,
                           extent_m: float | None = None, periodic: bool = True) -> dict:
    """What one frame gives towards the CV with the sky's part taken as its continuum (issue 32).
    A sky of D directions adds D caustic patterns, whose sum fluctuates more than a real sky's
    continuum of directions does (docs/validation.md: the excess falls with D). With
    ``sky.sampling = "halves"`` the directions are two independently drawn halves, each (twice its
    map) an unbiased estimate of the continuum: A = direct + 2·even, B = direct + 2·odd, whose
    errors are independent given the surface. ``total``, ``sky`` (its sky part) and ``even`` (the
    first half's part) are maps of one field. Returns the means of A and B and their covariance
    over the texels (signed: pooled by :func:`continuous_sky_cv`) and, given the map's
    ``extent_m``, the covariance split over octave bands of spatial frequency (``band_cov``, at
    ``band_edges_cycles_per_m``; :func:`cross_band_power`): E[Â B̂*] = |Ŝ|² of the field with the
    continuum's sky, so the bands are its power spectrum free of the directions' noise (pooled by
    :func:`continuous_sky_spectrum`)."""
    total, sky, even = (np.asarray(x, np.float64) for x in (total, sky, even))
    direct = total - sky
    a = direct + 2.0 * even
    b = direct + 2.0 * (sky - even)
    mean_a, mean_b = float(a.mean()), float(b.mean())
    out = {"mean_a": mean_a, "mean_b": mean_b, "cov": float(np.mean((a - mean_a) * (b - mean_b)))}
    if extent_m is not None:
        out["band_edges_cycles_per_m"] = octave_band_edges(a.shape[-1], extent_m).tolist()
        out["band_cov"] = cross_band_power(a, b, extent_m, periodic=periodic).tolist()
    return out


def continuous_sky_spectrum(frames: list[dict]) -> dict | None:
    """The power spectrum of E/Ē − 1 with the sky's continuum in octave bands, pooled over frames
    (each :func:`continuous_sky_moments` with ``band_cov``): the mean of the frames' band
    cross-powers over Ē² (Ē as in :func:`continuous_sky_cv`). The bands add up to the within-frame
    part of CV² (the frames' means moving adds the rest). A band can come out below 0 by chance
    (its noise); it is reported as it is. None without frames, bands or light."""
    frames = [f for f in frames if "band_cov" in f]
    if not frames:
        return None
    mean = float(np.mean([0.5 * (f["mean_a"] + f["mean_b"]) for f in frames]))
    if mean <= 0.0:
        return None
    power = np.mean([f["band_cov"] for f in frames], axis=0) / mean**2
    return {"band_edges_cycles_per_m": frames[0]["band_edges_cycles_per_m"], "relative_power": power.tolist()}


def continuous_sky_cv(frames: list[dict]) -> float | None:
    """The CV with the sky's continuum over one frame or several (each :func:`continuous_sky_moments`):
    the halves' errors being independent, E[E_A E_B] = E[E²] of the continuum's field and
    E[Ē_A] E[Ē_B] = Ē², so Var = mean(μ_A μ_B + Cov) − mean(μ_A)·mean(μ_B), and CV = √max(Var, 0)/Ē
    with Ē = mean((μ_A + μ_B)/2) — free of the directions' own noise in expectation (a few frames or
    a small map can come out below 0 by chance, hence the max). None without frames or light."""
    if not frames:
        return None
    mean_a = np.array([f["mean_a"] for f in frames])
    mean_b = np.array([f["mean_b"] for f in frames])
    cov = np.array([f["cov"] for f in frames])
    mean = float(np.mean(0.5 * (mean_a + mean_b)))
    if mean <= 0.0:
        return None
    var = float(np.mean(mean_a * mean_b + cov) - mean_a.mean() * mean_b.mean())
    return math.sqrt(max(var, 0.0)) / mean


def band_index(
    centres_nm: np.ndarray, edges_nm: np.ndarray | None, wavelength_nm: float | None
) -> int | None:
    """The bin holding ``wavelength_nm`` (None: not asked, or outside the bins)."""
    if wavelength_nm is None or edges_nm is None:
        return None
    k = int(np.searchsorted(edges_nm, wavelength_nm, side="right")) - 1
    return k if 0 <= k < len(centres_nm) else None


def probe_values(result, cfg: StatsConfig) -> np.ndarray:
    """(P,) the collector-averaged, band-integrated irradiance [W m⁻²] at the probe points
    (nearest texel)."""
    total = band_integrated(result.floor_irradiance, result.bin_widths_nm)
    m = total.shape[0]
    texel = result.map_extent_m / m
    averaged = collector_average(
        total, texel, cfg.collector_mm * 1e-3, periodic=result.map_periodic
    )
    values = []
    cx, cy = result.map_center_m
    for x, y in probe_points(cfg, result.map_center_m):
        i = min(max(int((x - cx + 0.5 * result.map_extent_m) / texel), 0), m - 1)
        j = min(max(int((y - cy + 0.5 * result.map_extent_m) / texel), 0), m - 1)
        values.append(averaged[j, i])
    return np.array(values)


def probe_points(cfg: StatsConfig, map_center_m: tuple[float, float]) -> list[tuple[float, float]]:
    """(x, y) [m] of the probes: ``stats.probes``, or the floor map's centre."""
    return [(p.x_m, p.y_m) for p in cfg.probes] or [tuple(map_center_m)]


def integrate_series(series: np.ndarray, dt_s: float, integration_s: float) -> np.ndarray:
    """(T', P) the samples' running mean over the last ``integration_s`` [s]: the integral of the
    piecewise-linear E(t) through the samples (spaced ``dt_s``) over [t − T, t], divided by T, at
    each sample t with a whole window behind it (the first ⌈T/dt⌉ samples are dropped). T = 0
    returns the series itself; a window shorter than a sample spacing averages between neighbours."""
    e = np.asarray(series, np.float64)
    if integration_s <= 0.0:
        return e
    steps = integration_s / dt_s
    first = int(math.ceil(steps - 1e-9))
    if first >= e.shape[0]:
        raise ValueError(f"stats.integration_s = {integration_s} needs more than {first} samples "
                         f"{dt_s} s apart; the animation has {e.shape[0]}")
    # cumulative trapezoid integral of the piecewise-linear interpolant, in units of dt
    cumulative = np.concatenate([np.zeros((1,) + e.shape[1:]), np.cumsum(0.5 * (e[1:] + e[:-1]), axis=0)])
    ends = np.arange(first, e.shape[0])
    # The window [n − steps, n]: its whole intervals [n − k, n], then the last `frac` of the interval
    # before them, integrated on its own (not as a difference of running integrals, which cancels
    # when the window is a sliver of a spacing).
    k = int(math.floor(steps + 1e-9))
    frac = max(steps - k, 0.0)
    whole = cumulative[ends] - cumulative[ends - k]
    if frac > 0.0:
        right, left = e[ends - k], e[np.maximum(ends - k - 1, 0)]
        whole = whole + frac * right - 0.5 * frac * frac * (right - left)
    return whole / steps


def series_statistics(series: np.ndarray, dt_s: float, flash_threshold: float) -> dict:
    """Statistics of time series E(t) (T, P) sampled every ``dt_s``: per probe the mean, CV, the
    flash frequency (upward crossings of ``flash_threshold``·mean per second) and the one-sided
    power spectrum of E/Ē − 1 (periodogram, Hann window) with its frequencies and the strongest."""
    e = np.asarray(series, np.float64)
    t = e.shape[0]
    mean = e.mean(axis=0)
    safe = np.where(mean > 0, mean, 1.0)
    above = e > flash_threshold * safe
    crossings = np.sum(~above[:-1] & above[1:], axis=0)
    duration = (t - 1) * dt_s
    freqs = np.fft.rfftfreq(t, dt_s)
    window = np.hanning(t)[:, None]
    spectrum = np.abs(np.fft.rfft((e / safe - 1.0) * window, axis=0)) ** 2 / (window**2).sum() * dt_s
    # one-sided: every bin but 0 (and Nyquist, which exists for an even length) counts twice
    spectrum[1 : (t + 1) // 2] *= 2.0
    peak = freqs[1:][np.argmax(spectrum[1:], axis=0)] if t > 2 else np.zeros(e.shape[1])
    return {
        "mean": mean.tolist(),
        "cv": (e.std(axis=0) / safe).tolist(),
        "flash_frequency_hz": (crossings / duration if duration > 0 else np.zeros_like(mean)).tolist(),
        "frequencies_hz": freqs.tolist(),
        "power_spectrum": spectrum.T.tolist(),
        "peak_frequency_hz": np.asarray(peak).tolist(),
    }
