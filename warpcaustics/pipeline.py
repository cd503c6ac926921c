"""One frame end to end: water → refraction → caustics → a :class:`RenderResult`.

The :class:`Renderer` composes the stages of a scene (the water model, the light and the water's
optics, the caustic method registered under ``caustics.method``) and runs them frame by frame; it
holds no per-method logic (``warpcaustics/caustics/stage.py`` has the interface).
"""

from __future__ import annotations

import functools
import numbers
from contextlib import contextmanager

import numpy as np
import warp as wp

from warpcaustics import device as devices
from warpcaustics.caustics.registry import METHODS
from warpcaustics.caustics.stage import Frame, Lighting, StageOutput, Stopwatch, sky_bytes
from warpcaustics.config import BeamSpread, Scattering, SkyModel, SkySampling
from warpcaustics.errors import ConfigError, WarpcausticsError
from warpcaustics.optics import spectra
from warpcaustics.optics.refraction import (
    height_blocks,
    height_range,
    horizon_buffer,
    horizon_bytes,
    sun_visibility,
)
from warpcaustics.result import RenderResult
from warpcaustics.scene import Scene
from warpcaustics.water import WATER_MODELS, make_water, water_bytes

__all__ = ["RenderResult", "Renderer", "render", "scene_bytes"]


def keeps_sky_shading(cfg) -> bool:
    """Whether the crests' shading from each sky direction is kept, (D, N, N), rather than one
    (N, N) buffer reused per direction: the random walk takes the directions in turn, and a method
    may revisit them (:attr:`CausticStage.keeps_sky_shading`)."""
    return cfg.optics.scattering is not Scattering.SINGLE or METHODS[cfg.caustics.method].keeps_sky_shading


def scene_bytes(scene: Scene, device: str = "cuda") -> int:
    """Device memory one frame of this scene needs on ``device`` [bytes] (what differs by device:
    the FFT ocean's scratch array, allocated on CUDA only)."""
    cfg = scene.config
    n = scene.water_resolution
    k = len(spectra.bins_for(cfg.optics).centres_nm)
    groups = k if cfg.optics.dispersion else 1
    stage = METHODS[cfg.caustics.method].bytes_needed(scene, k, groups)
    ns = scene.sky_resolution
    shading = horizon_bytes(n) if WATER_MODELS[cfg.water.model].periodic else 0  # the sweep's lattice
    # the sky's own surface (its waves cut to a coarser grid) and its sweep's lattice
    sky_surface = water_bytes(cfg, ns, device) + horizon_bytes(ns) if ns != n else 0
    sky = sky_bytes(cfg, ns, keeps_sky_shading(cfg)) + sky_surface
    return water_bytes(cfg, n, device) + stage + sky + shading


HOST_BYTES_PER_PIXEL = 200
"""Host memory post-processing takes per floor texel or camera pixel whatever the bands [bytes]: the
float64 XYZ and RGB planes of the colour conversion and the writers' buffers (tracemalloc's peak of
render + save_frame at M = 1024 with 4 and 16 bins: 195 + 4 K bytes a texel, docs/benchmarks.md)."""

HOST_BYTES_PER_BAND = 28
"""Host memory per texel or pixel and band [bytes]: the float64 read-backs a method sums its light
passes in (24; photons at K = 8 peaked at 24 K) and the float32 result (4)."""


HOST_BYTES_PER_SPREAD_PHOTON = 700
"""Host memory per photon of the walked beam spread (``optics.beam_spread = "walk"``) at its peak
[bytes]: tracemalloc's peak of ``walk_column`` with 3 bands was 651–669 bytes a photon at b·D ≈ 4
(2¹⁶ and 2¹⁸ photons) and 470 at b·D ≈ 0.4; 4 more per band for the band weights. The walks it keeps
(``column_spread``'s cache of 20) hold up to 32 + 4 per band more each (float64 offsets, float32
weights and memory)."""


def walks_spread(cfg) -> bool:
    """Whether the small-angle transfer walks its beam spread (``optics.beam_spread_photons`` each):
    the config takes ``walk`` only with ``optics.scattering = "small_angle"`` (config/checks.py)."""
    return cfg.optics.beam_spread is BeamSpread.WALK


def host_bytes(scene: Scene) -> int:
    """Host memory one frame's read-back and post-processing need at their peak [bytes], with the
    walked beam spread's photons where the transfer walks it."""
    cfg = scene.config
    k = len(spectra.bins_for(cfg.optics).centres_nm)
    camera = cfg.camera.width * cfg.camera.height if cfg.camera.enabled else 0
    pixels = cfg.caustics.map_resolution**2 + camera
    walk = 0
    if walks_spread(cfg):
        from warpcaustics.optics.beam_spread import SPREAD_CACHE

        sky = cfg.sky.directions if cfg.sky.model is not SkyModel.NONE else 0
        # each direction walks three times (its depth and the two of the path's derivative)
        kept = min(SPREAD_CACHE, 3 * (len(scene.sun_disk_directions()) + sky))
        walk = cfg.optics.beam_spread_photons * (HOST_BYTES_PER_SPREAD_PHOTON + 4 * k + kept * (32 + 4 * k))
    return pixels * (HOST_BYTES_PER_PIXEL + HOST_BYTES_PER_BAND * k) + walk


MAX_TIME_S = 1e9
"""The largest render time either way [s], about 32 years: past ~3e38 float32 overflows (and a
random-phase sea looks the same at any time, so nothing is lost by the bound)."""


def check_time(name: str, time_s: float) -> None:
    """Refuse a render time that is not finite or beyond :data:`MAX_TIME_S`, in one line naming
    ``name`` (a flag or an argument)."""
    if not isinstance(time_s, numbers.Real) or isinstance(time_s, bool):
        raise ConfigError(f"{name} = {time_s!r} must be a number of seconds, e.g. 0.0")
    if not (abs(time_s) <= MAX_TIME_S):  # NaN and inf too; an integer past float's range compares
        from warpcaustics.config.fields import _describe

        raise ConfigError(f"{name} = {_describe(time_s)} must be a finite number of seconds within "
                          f"±{MAX_TIME_S:g}")


def check_scene_config(scene: Scene) -> None:
    """A Scene built by hand (``Scene(config)``, or a config changed with ``dataclasses.replace``)
    skips load_scene's validation: its config is validated again here (a round trip through the
    checks, a few ms), so that a value load_scene refuses (a zero resolution had crashed the process
    inside a kernel) is the same one line here."""
    from warpcaustics.config import Config

    if not isinstance(scene.config, Config):
        raise ConfigError(f"Scene(config) takes a Config; got {type(scene.config).__name__} "
                          f"{scene.config!r:.60}: build scenes with warpcaustics.load_scene(path)")
    try:
        try:
            _validated(scene.config)
        except TypeError:  # a field set by hand to a list: not hashable, so checked without the cache
            _validated.__wrapped__(scene.config)
    except ConfigError as exc:
        raise ConfigError(f"the scene's config is not valid: {exc} (build scenes with "
                          "warpcaustics.load_scene(path), which checks every key)") from None


@functools.lru_cache(maxsize=64)
def _validated(cfg) -> bool:
    """``cfg`` through the checks once per process (a frozen Config is hashable: a config equal to one
    checked before is valid), so that every frame's Renderer does not pay the round trip again."""
    from warpcaustics.config import config_to_dict
    from warpcaustics.config.loading import config_from_dict

    config_from_dict(config_to_dict(cfg))
    return True


class Renderer:
    """Renders frames of one scene on one device; holds the water model, the light and the caustic
    method's buffers.

    Use one Renderer for an animation so the ocean spectrum is built once and the stateful pools
    carry their state over between frames.
    """

    def __init__(self, scene: Scene, device: str | None = None):
        if not isinstance(scene, Scene):
            raise ConfigError(f"a render takes a Scene from warpcaustics.load_scene(path); got "
                              f"{type(scene).__name__} {scene!r:.60}")
        check_scene_config(scene)
        cfg = scene.config
        self.scene = scene
        self.device = devices.resolve_device(device, config_value=cfg.device.value)
        self.bytes_needed = scene_bytes(scene, self.device)
        self.host_bytes = host_bytes(scene)
        """Host memory of a frame's read-back and post-processing [bytes] (on the CPU device as well)."""
        self.memory_fix = memory_fix(cfg)
        if wp.get_device(self.device).is_cpu:
            devices.check_fits(self.device, self.bytes_needed + self.host_bytes, self.memory_fix)
        else:
            devices.check_fits(self.device, self.bytes_needed, self.memory_fix)
            devices.check_fits("cpu", self.host_bytes, self.memory_fix)
        with _memory_errors(self.device, self.bytes_needed, self.memory_fix):
            self.water = make_water(cfg, self.device, scene.heights, scene.floor_relief)
            n = scene.water_resolution
            self.visible = wp.empty((n, n), dtype=wp.float32, device=self.device)
            self.horizon = horizon_buffer(n, self.device) if self.water.periodic else None
            ns = scene.sky_resolution
            self.sky_water = self.water if ns == n else self.water.truncated(ns)
            """The surface the sky's directions are refracted through (``sky.surface_resolution``)."""
            self.sky_horizon = self.horizon if ns == n else horizon_buffer(ns, self.device)
            self.light = Lighting.prepare(scene, self.device, keep_sky_shading=keeps_sky_shading(cfg))
            self.method = METHODS[cfg.caustics.method](scene, self.water, self.light, self.device)

    @property
    def bins(self) -> spectra.SpectralBins:
        return self.light.bins

    @property
    def sun_irradiance(self) -> np.ndarray:
        return self.light.sun_irradiance

    @property
    def attenuation_per_m(self) -> np.ndarray:
        return self.light.attenuation_per_m

    @property
    def ior(self) -> np.ndarray:
        return self.light.ior

    def render(self, time_s: float = 0.0) -> RenderResult:
        """Render the floor caustics at ``time_s`` [s] (finite, at most :data:`MAX_TIME_S` either way)."""
        check_time("time_s", time_s)
        with self.memory_errors():
            return self._render(float(time_s))

    def memory_errors(self):
        """A context in which a failed allocation — Warp's on the device, numpy's on the host (the
        read-backs, the colour conversion, the writers) — becomes one line that states the need."""
        return _memory_errors(self.device, self.bytes_needed + self.host_bytes, self.memory_fix)

    def check_above_floor(self, lowest: float, time_s: float) -> None:
        """Refuse a frame whose surface reaches down to the floor (``lowest`` its lowest point [m])."""
        floor_z = self.method.floor_top_z
        if lowest <= floor_z:
            raise WarpcausticsError(
                f"floor.depth_m = {self.scene.config.floor.depth_m} is too shallow: the water surface "
                f"reaches z = {lowest:.3f} m at t = {time_s:g} s, the floor z = {floor_z:.3f} m; "
                "make the floor deeper or the waves lower")

    def _render(self, time_s: float) -> RenderResult:
        cfg = self.scene.config
        dev = self.device
        watch = Stopwatch(dev)
        with watch.stage("water"):
            surface = self.water.at(time_s)
            lowest, highest = height_range(surface, dev)
        self.check_above_floor(lowest, time_s)
        sky = None
        if self.sky_water is not self.water:
            with watch.stage("sky_water"):
                sky_surface = self.sky_water.at(time_s)
                sky_range = height_range(sky_surface, dev)
            self.check_above_floor(sky_range[0], time_s)
            sky = Frame(surface=sky_surface, visible=None, time_s=time_s, lowest=sky_range[0],
                        highest=sky_range[1], watch=watch, horizon=self.sky_horizon)
        with watch.stage("shading"):
            blocks = None if surface.periodic else height_blocks(surface, dev)  # the march's, on walled water
            visible = sun_visibility(surface, self.scene.sun_direction, highest, dev, out=self.visible,
                                     blocks=blocks, lowest_m=lowest, horizon=self.horizon)
        if cfg.sky.sampling is SkySampling.HALVES:  # the config check ensures a sky
            self.light.draw_sky(self.scene, time_s, dev)
        frame = Frame(surface=surface, visible=visible, time_s=time_s, lowest=lowest, highest=highest,
                      watch=watch, height_blocks=blocks, horizon=self.horizon, sky=sky)
        self.method.check_frame(frame)
        out = self.method.render(frame)
        check_finite(out, time_s)
        with watch.stage("surface_readback"):
            positions = surface.positions.numpy()
            normals = surface.normals.numpy()
            folds = float(np.mean(surface.jacobian.numpy() <= 0.0)) if surface.jacobian is not None else 0.0
        light = self.light
        common = dict(
            scene=self.scene, time_s=time_s, device=dev, wavelengths_nm=light.bins.centres_nm,
            bin_widths_nm=light.bins.widths_nm, attenuation_per_m=light.attenuation_per_m, ior=light.ior,
            sun_irradiance=light.sun_irradiance, surface_positions=positions, surface_normals=normals,
            bins=light.bins, fold_fraction=folds, timings_s=watch.timings)

        def result(o) -> RenderResult:
            comparison = None if o.comparison is None else result(o.comparison)
            return RenderResult(floor_irradiance=o.floor, transmitted_flux_w_nm=o.transmitted,
                                method=o.method, comparison=comparison, **common, **o.extra)

        return result(out)


FINITE_FIELDS = ("floor", "transmitted", "camera_radiance", "sky_floor_irradiance",
                 "sky_floor_irradiance_even", "face_flux_w_nm")
"""What a frame must hold as finite numbers: its floor map, flux, camera image, sky map, face flux."""


def check_finite(out: StageOutput, time_s: float) -> None:
    """Refuse a frame whose maps or images hold NaN or inf (a scene beyond what float32 resolves),
    so that no such file is written and the run is not marked complete."""
    for stage in (out, out.comparison):
        if stage is None:
            continue
        for name in FINITE_FIELDS:
            value = getattr(stage, name, None) if name in ("floor", "transmitted") else stage.extra.get(name)
            if value is not None and not np.all(np.isfinite(value)):
                raise WarpcausticsError(
                    f"the {stage.method} {name.replace('_', ' ')} at t = {time_s:g} s is not finite (NaN or "
                    "inf): the scene's numbers are beyond what the float32 kernels resolve; bring its "
                    "lengths, depths and angles nearer to those of configs/")


_MEMORY_FIX = "lower water.resolution, caustics.map_resolution or optics.wavelengths.bins"


def memory_fix(cfg) -> str:
    """What to lower when a scene does not fit: a grid method's 3-D grid comes first, the walked
    beam spread's photons (where the transfer walks it) next."""
    grid_key = METHODS[cfg.caustics.method].memory_key
    fix = f"lower {grid_key}, water.resolution or caustics.map_resolution" if grid_key else _MEMORY_FIX
    if cfg.camera.enabled and cfg.camera.width * cfg.camera.height >= cfg.caustics.map_resolution**2:
        fix = fix.replace("lower ", "lower camera.width × camera.height, ", 1)  # the image is the most
    return fix.replace("lower ", "lower optics.beam_spread_photons, ", 1) if walks_spread(cfg) else fix


@contextmanager
def _memory_errors(device: str, needed: int, fix: str = _MEMORY_FIX):
    """Turn Warp's allocation failures into a one-line DeviceError that states the need."""
    try:
        yield
    except MemoryError:  # numpy's _ArrayMemoryError among them
        raise devices.out_of_memory(device, needed, fix) from None
    except RuntimeError as exc:
        text = str(exc).lower()
        if "alloc" in text or "out of memory" in text:
            raise devices.out_of_memory(device, needed, fix) from None
        raise


def render(scene: Scene, time_s: float = 0.0, device: str | None = None) -> RenderResult:
    """Render the floor caustics of ``scene`` at ``time_s`` [s].

    ``device``: ``"cpu"``, ``"cuda"``, ``"cuda:N"`` or None (``$WARPCAUSTICS_DEVICE``, then the
    config's ``device``, then CUDA if available else CPU). For many frames use :class:`Renderer`.
    """
    return Renderer(scene, device).render(time_s)
