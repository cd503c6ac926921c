"""Consistency across fields: settings that are each valid but do not go together, refused with a
one-line ConfigError that says what to change."""

from __future__ import annotations

import math

from warpcaustics.config.caustics import GREY_METHODS, BeamInterpolation, CausticsMethod, Intersection
from warpcaustics.config.light import SkyModel, SkySampling, SunSpectrum
from warpcaustics.config.optics import BeamSpread, Scattering
from warpcaustics.config.scene import FloorShape
from warpcaustics.config.schema import Config
from warpcaustics.config.water import WaterModel, WaterSpectrum
from warpcaustics.errors import ConfigError


def _check_consistency(cfg: Config) -> None:
    w = cfg.optics.wavelengths
    if any(b <= a for a, b in zip(w.list_nm, w.list_nm[1:])):
        raise ConfigError(f"optics.wavelengths = {list(w.list_nm)} must be strictly increasing")
    if w.max_nm <= w.min_nm:
        raise ConfigError(f"optics.wavelengths.max_nm = {w.max_nm} must exceed "
                          f"optics.wavelengths.min_nm = {w.min_nm}")
    _check_file_key("water.file", cfg.water.file, "water.model", cfg.water.model, WaterModel.HEIGHTFIELD,
                     "heights", "path.npy")
    if cfg.sun.spectrum is SunSpectrum.FILE and not cfg.sun.file:
        raise ConfigError("sun.file is missing; sun.spectrum = 'file' needs a CSV of wavelength [nm], "
                          "irradiance (set sun.file = \"sun.csv\")")
    _check_photon_scene(cfg)
    _check_wave_age(cfg)
    n = cfg.water.resolution
    if cfg.water.model is WaterModel.FFT and n is not None and (n & (n - 1)):
        raise ConfigError(f"water.resolution = {n} must be a power of two for water.model = 'fft' "
                          f"(e.g. {1 << max(2, round(math.log2(n)))})")


def _check_wave_age(cfg: Config) -> None:
    """Elfouhaily et al.'s JONSWAP fits hold for inverse wave ages up to 5: a shorter fetch is
    outside the spectrum's range."""
    w = cfg.water
    if w.model is not WaterModel.FFT or w.spectrum is not WaterSpectrum.ELFOUHAILY:
        return
    from warpcaustics.water.elfouhaily import OMEGA_C_RANGE, inverse_wave_age, shortest_fetch_m

    omega_c = inverse_wave_age(w.wind_speed_m_s, w.fetch_m)
    if omega_c > OMEGA_C_RANGE[1]:
        raise ConfigError(f"water.fetch_m = {w.fetch_m:g} gives an inverse wave age {omega_c:.3g}, above "
                          f"the {OMEGA_C_RANGE[1]:g} that water.spectrum = 'elfouhaily' is fitted to: use a "
                          f"fetch of at least {shortest_fetch_m(w.wind_speed_m_s):.4g} m at this wind")


def _check_file_key(key: str, file: str | None, selector: str, selected, reader, what: str,
                    example: str) -> None:
    """A file key is set exactly when its selector (``selector`` = ``selected``) is the value that
    reads it (``reader``)."""
    if selected is reader and not file:
        raise ConfigError(f"{key} is missing; {selector} = {reader.value!r} needs a .npy file of {what} "
                          f"(set {key} = \"{example}\")")
    if selected is not reader and file:
        raise ConfigError(f"{key} = {file!r} is only read by {selector} = {reader.value!r} (it is "
                          f"{selected.value!r}); remove it or set {selector} = \"{reader.value}\"")


def _check_vector(key: str, value: tuple[float, ...], lengths: tuple[int, ...]) -> None:
    if len(value) not in lengths:
        raise ConfigError(f"{key} = {list(value)} must have {' or '.join(map(str, lengths))} values")


def _check_periodic_floor(cfg: Config) -> None:
    """Under a periodic sea the floor must tile the patch too: the photons of the neighbouring
    tiles are folded into the patch, which is only right if the floor repeats with it."""
    if not cfg.water.periodic:
        return
    floor = cfg.floor
    if floor.shape is FloorShape.SLOPE:
        raise ConfigError(f"floor.shape = 'slope' does not repeat, but water.model = "
                          f"{cfg.water.model.value!r} is a periodic patch: use a water model that does not "
                          "tile (water.model = \"pool\", \"wavepool\" or \"procedural\") or a floor that "
                          "tiles (ripples, file)")
    if floor.shape is FloorShape.RIPPLES:
        a = math.radians(floor.ripple_direction_deg)
        m = math.cos(a) * cfg.water.extent_m / floor.ripple_wavelength_m
        n = math.sin(a) * cfg.water.extent_m / floor.ripple_wavelength_m
        mi, ni = round(m), round(n)
        if max(abs(m - mi), abs(n - ni)) > 1e-4:
            if mi == 0 and ni == 0:
                mi = 1
            wavelength = cfg.water.extent_m / math.hypot(mi, ni)
            direction = math.degrees(math.atan2(ni, mi))
            raise ConfigError(
                f"floor ripples (wavelength {floor.ripple_wavelength_m:g} m, direction "
                f"{floor.ripple_direction_deg:g}°) do not tile the periodic {cfg.water.extent_m:g} m patch; "
                f"the nearest that do: floor.ripple_wavelength_m = {wavelength:.12g}, "
                f"floor.ripple_direction_deg = {direction:.12g}")


def _check_map_window(cfg: Config) -> None:
    c = cfg.caustics
    _check_vector("caustics.map_center_m", c.map_center_m, (2,))
    if not c.map_extent_m:
        if any(c.map_center_m):
            raise ConfigError(f"caustics.map_center_m = {list(c.map_center_m)} places a window, but "
                              "caustics.map_extent_m is 0 (the whole patch); set caustics.map_extent_m")
        return
    if c.method is not CausticsMethod.FLUXRATIO:
        raise ConfigError(f"caustics.map_extent_m = {c.map_extent_m:g} (a floor-map window) works with "
                          f"caustics.method = \"fluxratio\" only (the method is {c.method.value!r}); set "
                          "caustics.method = \"fluxratio\", or caustics.map_extent_m = 0 for the whole patch")
    half = 0.5 * cfg.water.extent_m
    if c.map_extent_m > cfg.water.extent_m:
        raise ConfigError(f"caustics.map_extent_m = {c.map_extent_m:g} exceeds water.extent_m = "
                          f"{cfg.water.extent_m:g}; a window is part of the patch")
    x, y = c.map_center_m
    if cfg.water.periodic and 0.5 * cfg.water.extent_m < c.map_extent_m < cfg.water.extent_m:
        raise ConfigError(f"caustics.map_extent_m = {c.map_extent_m:g} is more than half the periodic "
                          f"{cfg.water.extent_m:g} m patch (a footprint could reach it from two periods); "
                          f"use at most {0.5 * cfg.water.extent_m:g} or the whole {cfg.water.extent_m:g}")
    if not cfg.water.periodic and max(abs(x), abs(y)) + 0.5 * c.map_extent_m > half:
        raise ConfigError(f"the floor-map window (caustics.map_center_m = {list(c.map_center_m)}, "
                          f"caustics.map_extent_m = {c.map_extent_m:g}) reaches past the "
                          f"{cfg.water.model.value!r} patch (|x|, |y| <= {half:g} m); move or shrink it")


def _check_sky(cfg: Config) -> None:
    sky = cfg.sky
    if sky.model is SkyModel.NONE:
        # cones without a sky spread nothing: a field config with its sky turned off still loads
        if sky.sampling is SkySampling.HALVES:
            raise ConfigError("sky.sampling = \"halves\" draws the sky's directions: set sky.model "
                              "(e.g. \"uniform\") or sky.sampling = \"stratified\"")
        if sky.diffuse_fraction:
            raise ConfigError(f"sky.diffuse_fraction = {sky.diffuse_fraction:g} needs a sky; set "
                              "sky.model = \"uniform\" (or sky.diffuse_fraction = 0)")
        return
    method = cfg.caustics.method
    if method is CausticsMethod.SUNMAP:
        raise ConfigError("sky.model with caustics.method = \"sunmap\": the sun map looks up the sun alone "
                          "(its halo stands in for the sky); set sky.model = \"none\"")
    if method in (CausticsMethod.PHOTONS, CausticsMethod.BOTH) and (
            cfg.caustics.intersection is Intersection.NEWTON):
        raise ConfigError("sky.model with caustics.intersection = \"newton\": the Newton guesses come from "
                          "the sun's light view, not the sky's; set caustics.intersection = \"exact\"")
    if sky.diffuse_fraction <= 0.0:
        raise ConfigError(f"sky.model = {sky.model.value!r} with sky.diffuse_fraction = 0 has no light; set "
                          "sky.diffuse_fraction (e.g. 0.15) or sky.model = \"none\"")
    if sky.sampling is SkySampling.HALVES:
        if sky.directions < 2 or sky.directions % 2:
            raise ConfigError(f"sky.sampling = \"halves\" splits the directions in two: set sky.directions "
                              f"to an even number of at least 2 (not {sky.directions})")
        if method is not CausticsMethod.FLUXRATIO or cfg.optics.scattering is Scattering.MULTIPLE:
            raise ConfigError("sky.sampling = \"halves\" keeps the halves' maps apart in caustics.method = "
                              "\"fluxratio\" with optics.scattering = \"single\" or \"small_angle\"; set "
                              "those or sky.sampling = \"stratified\"")
    if sky.sampling is SkySampling.CONES:
        if method is not CausticsMethod.FLUXRATIO or cfg.optics.scattering is Scattering.MULTIPLE:
            raise ConfigError("sky.sampling = \"cones\" spreads each direction's floor map in "
                              "caustics.method = \"fluxratio\" with optics.scattering = \"single\" or "
                              "\"small_angle\"; set those or sky.sampling = \"stratified\"")
        if not cfg.water.periodic:
            raise ConfigError(f"sky.sampling = \"cones\" spreads each direction's light over a periodic sea, "
                              f"not water.model = {cfg.water.model.value!r}; use water.model = \"fft\" or "
                              "sky.sampling = \"stratified\"")
    _check_sky_surface(cfg)


def _check_sky_surface(cfg: Config) -> None:
    """``sky.surface_resolution``: a power of two (it applies to cones on an FFT ocean and is left
    aside elsewhere, so that a field config's row with point directions or another sea still loads)."""
    ns = cfg.sky.surface_resolution
    if ns and (ns & (ns - 1) or ns < 4):
        raise ConfigError(f"sky.surface_resolution = {ns} must be a power of two of at least 4 (e.g. "
                          f"{max(4, 1 << round(math.log2(max(ns, 1))))}); 0 = the water's own grid")


def _check_scattering(cfg: Config) -> None:
    if cfg.optics.beam_spread is BeamSpread.WALK and cfg.optics.scattering is not Scattering.SMALL_ANGLE:
        raise ConfigError(f"optics.beam_spread = \"walk\" is how optics.scattering = \"small_angle\" "
                          f"spreads its scattered light (not {cfg.optics.scattering.value!r}); set "
                          "optics.scattering = \"small_angle\" or leave optics.beam_spread out")
    if cfg.optics.scattering is Scattering.SINGLE:
        return
    needs = []
    if cfg.caustics.method is not CausticsMethod.FLUXRATIO:
        needs.append(f"caustics.method = \"fluxratio\" (not {cfg.caustics.method.value!r})")
    if not cfg.water.periodic:
        needs.append(f"a periodic sea (not water.model = {cfg.water.model.value!r})")
    if cfg.optics.dispersion:
        needs.append("optics.dispersion = false")
    if needs:
        what = ("a reference random walk" if cfg.optics.scattering is Scattering.MULTIPLE
                else "the small-angle transfer, its mean from the random walk")
        raise ConfigError(f"optics.scattering = \"{cfg.optics.scattering.value}\" ({what}) needs "
                          + "; ".join(needs))


def _check_view(cfg: Config) -> None:
    """A radiance sensor's field of view (``floor.view_*``): the sun's light through the flux-ratio
    deposit, the sky's traced back from each texel through the height field (caustics/view.py)."""
    f = cfg.floor
    if not f.view_fov_deg:
        for key in ("view_zenith_deg", "view_azimuth_deg"):
            if getattr(f, key):
                raise ConfigError(f"floor.{key} = {getattr(f, key):g} is only read by a radiance sensor: set "
                                  "floor.view_fov_deg (e.g. 4.5) or leave it out")
        return
    needs = []
    if cfg.caustics.method is not CausticsMethod.FLUXRATIO:
        needs.append(f"caustics.method = \"fluxratio\" (not {cfg.caustics.method.value!r})")
    if cfg.optics.scattering is not Scattering.SINGLE:
        needs.append(f"optics.scattering = \"single\" (not {cfg.optics.scattering.value!r}: the scattered "
                     "light's transfer is of irradiance)")
    if not cfg.water.periodic:
        needs.append(f"a periodic sea (not water.model = {cfg.water.model.value!r})")
    if cfg.water.choppiness:
        needs.append(f"water.choppiness = 0 (not {cfg.water.choppiness:g}: the sky is traced back "
                     "through a height field)")
    for key in ("npz", "netcdf"):
        if getattr(cfg.output, key):
            needs.append(f"output.{key} = false (its arrays are labelled irradiance and PAR; the EXR and "
                         "run.json hold the sensor's map)")
    if needs:
        raise ConfigError(f"floor.view_fov_deg = {f.view_fov_deg:g} (a radiance sensor) needs "
                          + "; ".join(needs))
    if f.view_zenith_deg + 0.5 * f.view_fov_deg > 90.0:
        raise ConfigError(f"floor.view_zenith_deg = {f.view_zenith_deg:g} with floor.view_fov_deg = "
                          f"{f.view_fov_deg:g} looks below the horizontal, at the upwelling light, which "
                          f"is not modelled; use a zenith of at most {90.0 - 0.5 * f.view_fov_deg:g}")


def _check_stats(cfg: Config) -> None:
    side, (cx, cy) = cfg.map_window
    half = 0.5 * side
    for i, p in enumerate(cfg.stats.probes):
        if abs(p.x_m - cx) > half or abs(p.y_m - cy) > half:
            raise ConfigError(f"stats.probes[{i}] = ({p.x_m:g}, {p.y_m:g}) m is off the floor map "
                              f"({side:g} m wide around ({cx:g}, {cy:g}) m); move it onto the map")
    wl = cfg.stats.wavelength_nm
    w = cfg.optics.wavelengths
    lo, hi = (w.list_nm[0], w.list_nm[-1]) if w.list_nm else (w.min_nm, w.max_nm)
    if wl is not None and not lo <= wl <= hi:
        raise ConfigError(f"stats.wavelength_nm = {wl:g} is outside the spectral bins ({lo:g}–{hi:g} nm); "
                          "pick a wavelength inside optics.wavelengths")
    if cfg.stats.collector_mm * 1e-3 > side:
        raise ConfigError(f"stats.collector_mm = {cfg.stats.collector_mm:g} is wider than the "
                          f"{side:g} m floor map; use a smaller collector")
    if cfg.output.netcdf:
        try:
            import xarray  # noqa: F401
        except ImportError:
            raise ConfigError("output.netcdf = true needs xarray: pip install 'warpcaustics[science]' "
                              "(or set output.netcdf = false)") from None


def _check_sunmap(cfg: Config) -> None:
    """The approximate methods' own settings."""
    c = cfg.caustics
    if c.method in GREY_METHODS and cfg.optics.dispersion:
        raise ConfigError(f"optics.dispersion = true needs a method that refracts each band: "
                          f"caustics.method = {c.method.value!r} traces one index for all bands; set "
                          "optics.dispersion = false or caustics.method = \"fluxratio\", \"beams\" or "
                          "\"photons\"")
    if c.method is CausticsMethod.WAVE3D and c.wave3d_cells_per_wavelength > c.wave3d_resolution / 6:
        raise ConfigError(f"caustics.wave3d_cells_per_wavelength = {c.wave3d_cells_per_wavelength:g} makes "
                          f"the wave longer than a sixth of the patch at caustics.wave3d_resolution = "
                          f"{c.wave3d_resolution} (its direction could not be kept); "
                          + (f"use at most {c.wave3d_resolution / 6:g} or raise caustics.wave3d_resolution"
                             if c.wave3d_resolution / 6 >= 4.0 else "raise caustics.wave3d_resolution to at "
                             f"least {math.ceil(6 * c.wave3d_cells_per_wavelength)} (24 for the fewest "
                             "cells per wavelength, 4)"))
    disk = cfg.sun.angular_diameter_deg
    if c.sunmap_halo_deg <= disk:
        raise ConfigError(f"caustics.sunmap_halo_deg = {c.sunmap_halo_deg:g} must exceed "
                          f"sun.angular_diameter_deg = {disk:g} (the halo surrounds the disk)")


def _check_beam_levels(cfg: Config) -> None:
    """Adaptive beams refine quads of 2^levels cells of a periodic sea."""
    levels = cfg.caustics.beam_levels
    if not levels:
        return
    if not cfg.water.periodic:
        raise ConfigError(f"caustics.beam_levels = {levels} needs a periodic sea (water.model fft, flat "
                          f"or heightfield), not the non-periodic {cfg.water.model.value!r}; set "
                          "caustics.beam_levels = 0")
    n = cfg.water.resolution
    if n is not None and n % (1 << levels):
        raise ConfigError(f"caustics.beam_levels = {levels} needs water.resolution divisible by "
                          f"{1 << levels} (it is {n}); lower caustics.beam_levels or change water.resolution")
    if cfg.caustics.beam_interpolation is BeamInterpolation.SMOOTH:
        raise ConfigError("caustics.beam_interpolation = 'smooth' needs the uniform grid of beams; set "
                          "caustics.beam_levels = 0 or caustics.beam_interpolation = 'flat'")


def _check_soft_fade(cfg: Config) -> None:
    """The soft fade acts on the beams' light shafts in the camera image alone."""
    c = cfg.caustics
    if c.beam_soft_fade_m and not (c.method in (CausticsMethod.BEAMS, CausticsMethod.BOTH)
                                   and cfg.camera.enabled and c.shafts):
        raise ConfigError(f"caustics.beam_soft_fade_m = {c.beam_soft_fade_m:g} fades the beams' light shafts "
                          "in the camera image: it needs caustics.method = \"beams\" (or \"both\"), "
                          "camera.enabled and caustics.shafts; or set it to 0")


def _check_eikonal_threshold(cfg: Config) -> None:
    c = cfg.caustics
    depth = c.eikonal_threshold_depth_m
    if depth is not None and c.method is not CausticsMethod.EIKONAL:
        raise ConfigError(f"caustics.eikonal_threshold_depth_m = {depth:g} post-processes the eikonal "
                          "caustic texture: it needs caustics.method = \"eikonal\"; or leave it unset")


def _check_bounces(cfg: Config) -> None:
    """Glass and mirror receivers need bounces, which the beams and the exact photons implement."""
    c = cfg.caustics
    special = [i for i, r in enumerate(cfg.receivers) if r.ior is not None or r.specular]
    for i in special:
        r = cfg.receivers[i]
        if r.ior is not None and r.specular:
            raise ConfigError(f"receivers[{i}] sets both ior and specular; a receiver is glass (ior) or a "
                              "mirror (specular), not both")
    if c.bounces > 1:
        photons = c.method in (CausticsMethod.PHOTONS, CausticsMethod.BOTH)
        if not (c.method is CausticsMethod.BEAMS or (photons and c.intersection is Intersection.EXACT)):
            raise ConfigError(f"caustics.bounces = {c.bounces} is implemented for caustics.method = "
                              "\"beams\", and for \"photons\" and \"both\" with caustics.intersection = "
                              f"\"exact\" (the method is {c.method.value!r}, {c.intersection.value!r}); "
                              "or set caustics.bounces = 1")
        if not special:
            raise ConfigError(f"caustics.bounces = {c.bounces} has nothing to bounce off: give a receiver "
                              "ior (glass) or specular = true; or set caustics.bounces = 1")
    elif special:
        key = "ior" if cfg.receivers[special[0]].ior is not None else "specular"
        raise ConfigError(f"receivers[{special[0]}].{key} needs caustics.bounces = 2 or 3 (with 1 the light "
                          "stops at the first receiver); or remove it")


def _check_photon_scene(cfg: Config) -> None:
    """Receivers other than a flat floor, and the camera, need the photon or beam method."""
    _check_beam_levels(cfg)
    _check_soft_fade(cfg)
    _check_eikonal_threshold(cfg)
    _check_sunmap(cfg)
    _check_map_window(cfg)
    _check_sky(cfg)
    _check_scattering(cfg)
    _check_view(cfg)
    _check_stats(cfg)
    photons = cfg.caustics.method.uses_receivers
    needs = []
    grid = cfg.caustics.method in (CausticsMethod.EIKONAL, CausticsMethod.WAVE3D)  # their 3-D texture
    if cfg.floor.shape is not FloorShape.FLAT and not grid:
        needs.append(f"floor.shape = {cfg.floor.shape.value!r}")
    if cfg.receivers:
        needs.append("[[receivers]]")
    if cfg.camera.enabled:
        needs.append("camera.enabled = true")
    if needs and not photons:
        relief = " (a floor relief alone: or \"eikonal\", \"wave3d\")" if needs[0].startswith("floor") else ""
        raise ConfigError(f"{', '.join(needs)} needs caustics.method = \"photons\" or \"beams\"{relief} "
                          f"(the method is {cfg.caustics.method.value!r})")
    _check_file_key("floor.file", cfg.floor.file, "floor.shape", cfg.floor.shape, FloorShape.FILE,
                     "floor relief", "floor.npy")
    _check_periodic_floor(cfg)
    _check_vector("floor.albedo", cfg.floor.albedo, (1, 3))
    for i, r in enumerate(cfg.receivers):
        _check_vector(f"receivers[{i}].scale", r.scale, (1, 3))
        _check_vector(f"receivers[{i}].rotate_deg", r.rotate_deg, (3,))
        _check_vector(f"receivers[{i}].translate_m", r.translate_m, (3,))
        _check_vector(f"receivers[{i}].albedo", r.albedo, (1, 3))
    cam = cfg.camera
    for name in ("position_m", "look_at_m", "up"):
        _check_vector(f"camera.{name}", getattr(cam, name), (3,))
    view = [b - a for a, b in zip(cam.position_m, cam.look_at_m)]
    if math.hypot(*view) == 0.0:
        raise ConfigError("camera.look_at_m equals camera.position_m; look at another point")
    up = cam.up
    if math.hypot(*up) < 1e-12:  # the camera's float32 vectors would lose it (1e-200 became zero)
        raise ConfigError(f"camera.up = {list(up)} is too short to give a direction (length under 1e-12); "
                          "give one of ordinary length, e.g. [0.0, 0.0, 1.0]")
    cross = (view[1] * up[2] - view[2] * up[1], view[2] * up[0] - view[0] * up[2],
             view[0] * up[1] - view[1] * up[0])
    if math.hypot(*cross) <= 1e-9 * math.hypot(*view) * max(math.hypot(*up), 1e-300):
        raise ConfigError(f"camera.up = {list(up)} is parallel to the view direction; choose another up")
    _check_bounces(cfg)
